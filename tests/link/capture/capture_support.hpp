#pragma once
// Helpers shared by the capture tests: scratch files, a pinned wall clock
// and tshark, the real reader a pcap is checked against.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "tests/harness/scratch_dir.hpp"

namespace hil::link::test {

/// The wall clock the capture tests give the wire log and the pcap writer
/// (2023-11-14 22:13:20 UTC, in microseconds).
inline constexpr std::int64_t kWallUs = 1'700'000'000'000'000;

/// A file path unique to this process and test, in a scratch folder that
/// goes (with the file) when the object goes.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& suffix) : path_(dir_.path() / ("capture" + suffix)) {}

  const std::filesystem::path& path() const { return path_; }
  std::string contents() const {
    std::ifstream in(path_, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  ::hil::test::ScratchDir dir_{"hil-capture"};
  std::filesystem::path path_;
};

/// True when tshark is on the PATH.
inline bool tshark_installed() {
  return std::system("command -v tshark >/dev/null 2>&1") == 0;
}

/// What `tshark -n -r FILE ARGS` prints (stderr dropped); a test failure,
/// and nothing, when it cannot run or exits with an error.
inline std::optional<std::string> tshark_output(const std::filesystem::path& file,
                                                const std::string& args) {
  const std::string command = "tshark -n -r '" + file.string() + "' " + args + " 2>/dev/null";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) {
    ADD_FAILURE() << "cannot run " << command;
    return std::nullopt;
  }
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe))
    out.append(buf, n);
  const int status = ::pclose(pipe);
  if (status != 0) {
    ADD_FAILURE() << command << " exited with status " << status;
    return std::nullopt;
  }
  return out;
}

/// A wall clock that reads whatever the test set.
struct FakeWallClock {
  std::int64_t now_us = 1'700'000'000'000'000;
};

}  // namespace hil::link::test
