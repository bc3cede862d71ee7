#pragma once
// What the client programs' tests share: `hil mock` in the background with
// its TCP port or pty read from its output, a temporary folder per test,
// files read back, a program run to its exit or waited on line by line,
// and the fixture that holds a client's mock car and folder. Every wait is
// bounded.

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
#include <stdexcept>
#include <string>
#include <vector>

#include "link/endpoint.hpp"
#include "tests/apps/hil_cli_support.hpp"
#include "tests/harness/scratch_dir.hpp"
#include "tests/support/text.hpp"

namespace hil::test {

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

/// What a client takes `--port <path>` for: the serial device at `path`
/// at `baud`.
inline link::Endpoint serial_endpoint(std::string path, unsigned baud) {
  return link::PtyEndpoint{std::move(path), baud, link::Duration{0}};
}

/// A loopback TCP port that refuses every connection for as long as this
/// object lives: a socket bound to it that never listens. Holding the port
/// keeps tests that run beside this one (a fleet of mocks on free ports)
/// from taking it, so "nothing listens there" stays true.
class ClosedPort {
 public:
  ClosedPort() : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
      throw std::runtime_error("cannot bind a loopback port");
    socklen_t len = sizeof addr;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = std::to_string(ntohs(addr.sin_port));
  }
  ~ClosedPort() { ::close(fd_); }
  ClosedPort(const ClosedPort&) = delete;
  ClosedPort& operator=(const ClosedPort&) = delete;

  const std::string& port() const { return port_; }

 private:
  int fd_;
  std::string port_;
};

/// A fresh folder for one test's files, removed with everything in it.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "hil-client-test") : dir_(prefix) {}

  const std::filesystem::path& path() const { return dir_.path(); }
  /// The path of `name` in the folder.
  std::string file(const std::string& name) const { return (path() / name).string(); }
  /// Writes `text` as `name` in the folder; its path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path() / name, std::ios::binary) << text;
    return path() / name;
  }

 private:
  ScratchDir dir_;
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
  const std::string& output() { return process_.output(); }
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

/// Waits up to `limit` for `process` to exit: a fatal failure when it is
/// still running then, a failure when its status is not `expected`.
inline void expect_exit_status(HilProcess& process, int expected,
                               std::chrono::milliseconds limit = std::chrono::seconds(20)) {
  const auto status = process.wait_exit(limit);
  ASSERT_TRUE(status) << process.output();
  EXPECT_EQ(*status, expected) << process.output();
}

/// Waits for a line containing each of `texts` in turn, each after the one
/// before; a failure for each that does not come within `limit`.
inline void expect_lines(HilProcess& process, const std::vector<std::string>& texts,
                         std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  for (const auto& text : texts)
    EXPECT_TRUE(process.wait_for_line(text, limit)) << text << "\n" << process.output();
}

/// As expect_lines, but a fatal failure at the first line that does not come.
inline void assert_lines(HilProcess& process, const std::vector<std::string>& texts,
                         std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  for (const auto& text : texts)
    ASSERT_TRUE(process.wait_for_line(text, limit)) << text << "\n" << process.output();
}

/// A client program's tests against one mock car: a scratch folder and,
/// once a test starts it, `hil mock`, which must stop cleanly at the end.
class ClientProgramTest : public ::testing::Test {
 protected:
  /// `program`: the client's path; `port`: what --port is given until a
  /// mock on TCP names its own.
  ClientProgramTest(std::string program, const std::string& temp_prefix, std::string port = {},
                    std::chrono::milliseconds limit = std::chrono::seconds(30))
      : program_(std::move(program)), limit_(limit), temp(temp_prefix), port(std::move(port)) {}

  void TearDown() override {
    if (mock) {
      EXPECT_EQ(mock->stop(), 0) << mock->output();
    }
  }

  /// Starts `hil mock` with `args`, ready once it prints `ready_text`; a
  /// mock on TCP gives its port to the client.
  void start_mock(std::vector<std::string> args, const std::string& ready_text = kTcpReady) {
    mock.emplace(std::move(args), ready_text);
    ASSERT_TRUE(mock->ready()) << mock->output();
    if (ready_text != kTcpReady) return;
    port = mock->port();
    ASSERT_FALSE(port.empty()) << mock->output();
  }

  /// `--port PORT`, then `args`.
  std::vector<std::string> on_port(std::vector<std::string> args) const {
    args.insert(args.begin(), {"--port", port});
    return args;
  }

  /// The client with `--port PORT` and `args`, run to its exit.
  CommandResult client(std::vector<std::string> args) { return client(std::move(args), limit_); }
  CommandResult client(std::vector<std::string> args, std::chrono::milliseconds limit) {
    return run_to_exit(program_, on_port(std::move(args)), limit);
  }

  std::filesystem::path write(const std::string& name, const std::string& text) {
    return temp.write(name, text);
  }

  /// Runs the client with `args`, then `--script` and the path of `name`
  /// holding `text`: it refuses the script with exit 2, naming its path and
  /// then `says`. The client's output.
  std::string expect_script_refused(const std::string& name, const std::string& text,
                                    const std::string& says, std::vector<std::string> args = {}) {
    const auto script = write(name, text);
    args.insert(args.end(), {"--script", script.string()});
    const auto r = client(std::move(args));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(contains(r.output, script.string() + says)) << r.output;
    return r.output;
  }

 private:
  std::string program_;
  std::chrono::milliseconds limit_;

 protected:
  TempDir temp;
  std::filesystem::path dir = temp.path();
  std::string port;
  std::optional<MockCar> mock;
};

}  // namespace hil::test
