// The logi-client terminal UI end to end: the program under a real
// pseudo-terminal (TERM=xterm, 100x32) driving `hil mock logi` over real
// TCP; keys typed as a person types them, the car's wire log checked.
// Bounded waits only.

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/client_program_support.hpp"

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

using hil::test::read_file;

/// logi-client on the slave side of a pty; the test holds the master.
class PtyProgram {
 public:
  PtyProgram(const std::vector<std::string>& args, const fs::path& cwd, int rows, int columns) {
    winsize size{};
    size.ws_row = static_cast<unsigned short>(rows);
    size.ws_col = static_cast<unsigned short>(columns);
    hil::test::ArgvList argv(LOGI_CLIENT_BINARY, args);
    pid_ = ::forkpty(&master_, nullptr, nullptr, &size);
    if (pid_ == 0) {
      if (::chdir(cwd.c_str()) != 0) ::_exit(126);
      ::setenv("TERM", "xterm", 1);
      ::setenv("LINES", std::to_string(rows).c_str(), 1);
      ::setenv("COLUMNS", std::to_string(columns).c_str(), 1);
      ::execv(LOGI_CLIENT_BINARY, argv.data());
      ::_exit(127);
    }
    if (master_ >= 0) ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  }
  ~PtyProgram() {
    if (pid_ > 0 && !exit_code_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (master_ >= 0) ::close(master_);
  }
  PtyProgram(const PtyProgram&) = delete;
  PtyProgram& operator=(const PtyProgram&) = delete;

  bool started() const { return pid_ > 0 && master_ >= 0; }

  void type(const std::string& keys) {
    ASSERT_EQ(::write(master_, keys.data(), keys.size()), static_cast<ssize_t>(keys.size()));
  }

  /// Reads the screen output for about `d` (the program must never block on a full pty).
  void pump(std::chrono::milliseconds d) {
    const auto deadline = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < deadline)
      read_some(deadline);
  }

  /// Reads until `done()` holds or `limit` passes.
  bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds limit = 15s) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (!done()) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      read_some(std::min(deadline, std::chrono::steady_clock::now() + 50ms));
    }
    return true;
  }

  /// Waits up to `limit` for the exit status.
  std::optional<int> wait_exit(std::chrono::milliseconds limit = 10s) {
    wait_until(
        [&] {
          int status = 0;
          if (::waitpid(pid_, &status, WNOHANG) == pid_)
            exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
          return exit_code_.has_value();
        },
        limit);
    return exit_code_;
  }

  const std::string& screen_output() const { return output_; }

 private:
  void read_some(std::chrono::steady_clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd p{master_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(std::max<long>(0, left.count()))) <= 0) return;
    char buf[4096];
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n > 0) output_.append(buf, static_cast<std::size_t>(n));
  }

  pid_t pid_ = -1;
  int master_ = -1;
  std::string output_;
  std::optional<int> exit_code_;
};

/// The client-to-car frames of the mock's NDJSON wire log, in order of arrival.
std::vector<std::string> frames_received(const std::string& wire_log) {
  std::vector<std::string> frames;
  const std::regex frame(R"(LOGI:(SP|MD|MV|GS|ST):[A-Z0-9]+:[0-9A-F]{2}#)");
  // What reached the car (after any faults; there are none here).
  for (const auto& line : hil::test::delivered_to_car(wire_log)) {
    for (auto it = std::sregex_iterator(line.begin(), line.end(), frame);
         it != std::sregex_iterator(); ++it)
      frames.push_back(it->str());
  }
  return frames;
}

TEST(LogiClientTui, DrivesTheMockCarFromARealTerminal) {
  const hil::test::TempDir temp("logi-tui");
  const fs::path& dir = temp.path();
  const fs::path wire = dir / "wire.ndjson";
  hil::test::MockCar mock(hil::test::mock_on_tcp_args("logi", {"--log", wire.string()}),
                          hil::test::kTcpReady);
  ASSERT_FALSE(mock.port().empty()) << mock.output();

  PtyProgram tui({"--port", mock.port()}, dir, 32, 100);
  ASSERT_TRUE(tui.started());
  ASSERT_TRUE(tui.wait_until([&] {
    return tui.screen_output().find("Connected") != std::string::npos;
  })) << tui.screen_output();

  auto car_got = [&](const std::string& frame, int times = 1) {
    return tui.wait_until([&] {
      int n = 0;
      for (const auto& f : frames_received(read_file(wire)))
        n += f == frame ? 1 : 0;
      return n >= times;
    });
  };

  tui.type("30\n");  // speed 30, sent
  ASSERT_TRUE(car_got("LOGI:SP:030:D5#")) << read_file(wire);
  tui.type("m");  // switch to MAN
  ASSERT_TRUE(car_got("LOGI:MD:MAN:0C#")) << read_file(wire);

  // Forward, held: the press, then the auto-repeats (first after 300 ms, then
  // every 40 ms), well inside the 700 ms and 200 ms windows.
  tui.type("w");
  tui.pump(300ms);
  for (int i = 0; i < 5; ++i) {
    tui.type("w");
    tui.pump(40ms);
  }
  // The key is let go: the release's MV:STOP follows without any key.
  ASSERT_TRUE(car_got("LOGI:MV:FWD:23#")) << read_file(wire);
  ASSERT_TRUE(car_got("LOGI:MV:STOP:88#")) << read_file(wire);

  tui.type(" ");  // the emergency stop
  ASSERT_TRUE(car_got("LOGI:MV:STOP:88#", 2)) << read_file(wire);

  tui.type("vt");  // save the log as text in the working directory
  ASSERT_TRUE(tui.wait_until([&] {
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".txt") return true;
    return false;
  })) << tui.screen_output();

  tui.type("\x03");  // Ctrl-C quits
  EXPECT_EQ(tui.wait_exit(), 0) << tui.screen_output();

  // In the order typed; the repeats of the held key sent no MV of their own
  // (one MV:FWD normally; a very slow machine may see a release between repeats).
  const auto frames = frames_received(read_file(wire));
  const std::vector<std::string> expected = {"LOGI:SP:030:D5#", "LOGI:MD:MAN:0C#",
                                             "LOGI:MV:FWD:23#", "LOGI:MV:STOP:88#",
                                             "LOGI:MV:STOP:88#"};
  std::size_t matched = 0;
  for (const auto& f : frames)
    if (matched < expected.size() && f == expected[matched]) ++matched;
  EXPECT_EQ(matched, expected.size()) << read_file(wire);
  EXPECT_LT(std::count(frames.begin(), frames.end(), "LOGI:MV:FWD:23#"), 6) << read_file(wire);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back(), "LOGI:MV:STOP:88#") << read_file(wire);

  std::string saved;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".txt") saved = read_file(entry.path());
  EXPECT_NE(saved.find("TX   LOGI:MV:FWD:23#"), std::string::npos) << saved;
  EXPECT_NE(saved.find("RX   LOGI:FB:MV:1"), std::string::npos) << saved;
  EXPECT_EQ(mock.stop(), 0);
}

TEST(LogiClientTui, RefusesToStartWithoutATerminal) {
  hil::test::HilProcess client(LOGI_CLIENT_BINARY, {"--port", "1"});
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(), 2) << client.output();
  EXPECT_NE(client.output().find("needs a terminal"), std::string::npos) << client.output();
}

}  // namespace
