#pragma once
// A scratch folder for a test's files.

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace hil::test {

/// A new, empty folder of its own under the temporary folder, named after
/// `prefix` and the running test, removed with everything in it when the
/// object goes.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix) : path_(new std::filesystem::path(made(prefix))) {}

  const std::filesystem::path& path() const { return *path_; }

 private:
  static std::filesystem::path made(const std::string& prefix) {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = prefix + "-" + (test != nullptr ? test->name() : "") + "-XXXXXX";
    for (char& c : name)
      if (c == '/') c = '_';  // a parameterised test's name is "Name/3"
    std::string pattern = (std::filesystem::temp_directory_path() / name).string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::system_error(errno, std::generic_category(), "mkdtemp " + pattern);
    return pattern;
  }
  struct RemoveAll {
    void operator()(const std::filesystem::path* path) const {
      std::error_code ignored;
      std::filesystem::remove_all(*path, ignored);
      delete path;
    }
  };
  std::unique_ptr<const std::filesystem::path, RemoveAll> path_;
};

}  // namespace hil::test
