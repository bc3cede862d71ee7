#pragma once
// Helpers shared by the capture tests: scratch files and a pinned wall clock.

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

namespace hil::link::test {

/// The wall clock the capture tests give the wire log and the pcap writer
/// (2023-11-14 22:13:20 UTC, in microseconds).
inline constexpr std::int64_t kWallUs = 1'700'000'000'000'000;

/// A file path unique to this process and test, removed when it goes away.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& suffix) {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::string name =
        info ? std::string(info->test_suite_name()) + "." + info->name() : "rc";
    path_ = std::filesystem::temp_directory_path() /
            ("hil-capture-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
             name + suffix);
    std::filesystem::remove(path_);
  }
  ~ScratchFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string contents() const {
    std::ifstream in(path_, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  std::filesystem::path path_;
};

/// A wall clock that reads whatever the test set.
struct FakeWallClock {
  std::int64_t now_us = 1'700'000'000'000'000;
};

}  // namespace hil::link::test
