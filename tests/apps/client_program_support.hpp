#pragma once
// What the client programs' tests share: `hil mock` in the background with
// its TCP port or pty read from its output, a temporary folder per test,
// files read back, and a program run to its exit. Every wait is bounded.

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/hil_cli_support.hpp"

namespace hil::test {

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The records of a mock's NDJSON wire log (`hil mock --log`) that were
/// delivered to the car, in order of arrival.
inline std::vector<std::string> delivered_to_car(const std::string& wire_log_text) {
  std::vector<std::string> out;
  std::istringstream lines(wire_log_text);
  std::string line;
  while (std::getline(lines, line))
    if (contains(line, R"("event":"delivered")") && contains(line, R"("dir":"to_car")"))
      out.push_back(line);
  return out;
}

/// A TCP port nobody listens on: bound by the kernel's choice, then released.
inline std::string free_tcp_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ::close(fd);
  return std::to_string(ntohs(addr.sin_port));
}

/// A fresh folder for one test's files, removed with everything in it.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "hil-client-test") {
    static int counter = 0;
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            (prefix + "-" + std::to_string(::getpid()) + "-" +
             (test != nullptr ? std::string(test->name()) + "-" : std::string()) +
             std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// The path of `name` in the folder.
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// Writes `text` as `name` in the folder; its path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name, std::ios::binary) << text;
    return path_ / name;
  }

 private:
  std::filesystem::path path_;
};

/// `hil mock <car>` in the background, ready once it has named where it
/// listens: `mock_on_tcp` and `mock_on_pty` start one.
class MockCar {
 public:
  MockCar(std::vector<std::string> args, const std::string& ready_text)
      : process_(std::move(args)) {
    ready_line_ = process_.wait_for_line(ready_text, std::chrono::seconds(15));
  }
  ~MockCar() {
    if (!stopped_) process_.interrupt();
  }
  MockCar(const MockCar&) = delete;
  MockCar& operator=(const MockCar&) = delete;

  bool ready() const { return ready_line_.has_value(); }
  /// The TCP port of a mock started by mock_on_tcp (empty if it did not say).
  std::string port() const {
    std::smatch m;
    if (ready_line_ && std::regex_search(*ready_line_, m, std::regex(R"(tcp://[^ :]+:(\d+))")))
      return m[1];
    return {};
  }
  HilProcess& process() { return process_; }
  const std::string& output() const { return process_.output(); }
  /// Ctrl-C; the mock's exit status (0 when it stopped cleanly).
  std::optional<int> stop() {
    stopped_ = true;
    return process_.interrupt();
  }

 private:
  HilProcess process_;
  std::optional<std::string> ready_line_;
  bool stopped_ = false;
};

/// `hil mock <car> --port 0 <extra>`: a TCP port the kernel chose.
inline std::vector<std::string> mock_on_tcp_args(const std::string& car,
                                                 std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"mock", car, "--port", "0"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}
inline constexpr const char* kTcpReady = "connect to tcp://";

/// `hil mock <car> --pty <device> <extra>`: a pseudo-terminal at `device`.
inline std::vector<std::string> mock_on_pty_args(const std::string& car, const std::string& device,
                                                 std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"mock", car, "--pty", device};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}
inline constexpr const char* kPtyReady = "as a serial port at";

/// Runs `program` with `args` and no input to its exit (or `limit`; then
/// the exit code is -1).
inline CommandResult run_to_exit(const std::string& program, const std::vector<std::string>& args,
                                 std::chrono::milliseconds limit = std::chrono::seconds(20)) {
  HilProcess process(program, args);
  process.close_stdin();
  CommandResult result;
  result.exit_code = process.wait_exit(limit).value_or(-1);
  result.output = process.output();
  return result;
}

}  // namespace hil::test
