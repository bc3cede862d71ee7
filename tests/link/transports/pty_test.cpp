// The pty transport against a real pty, opened the way a client program
// opens a serial port.
#include "link/pty.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>

#include <asio/posix/stream_descriptor.hpp>
#include <asio/write.hpp>

#include "link/asio_executor.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace {

namespace fs = std::filesystem;

std::string unique_path(const std::string& what) {
  return "/tmp/hil-test-" + std::to_string(::getpid()) + "-" + what;
}

/// A client program's end: open(2) on the symlink, raw mode, async reads
/// recording when each byte arrived.
struct Client {
  Client(asio::io_context& io, AsioExecutor& ex, const std::string& path) : ex_(ex), port(io) {
    const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) throw std::system_error(errno, std::generic_category(), path);
    termios t{};
    ::tcgetattr(fd, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(fd, TCSANOW, &t);
    port.assign(fd);
    read();
  }

  void read() {
    // The port may be closed (the client destroyed) while a read waits;
    // the aborted handler must not touch it then.
    port.async_read_some(asio::buffer(buffer), [this, alive = std::weak_ptr<int>(alive_)](
                                                   std::error_code ec, std::size_t n) {
      if (alive.expired()) return;
      for (std::size_t i = 0; i < n; ++i) {
        data.push_back(buffer[i]);
        arrivals.push_back(ex_.now());
      }
      if (ec) {
        error = ec;
      } else {
        read();
      }
    });
  }

  void write(const std::string& text) {
    const auto n = ::write(port.native_handle(), text.data(), text.size());
    EXPECT_EQ(n, static_cast<ssize_t>(text.size()));
  }

  std::string text() const { return {data.begin(), data.end()}; }

  AsioExecutor& ex_;
  asio::posix::stream_descriptor port;
  std::array<std::uint8_t, 1024> buffer{};
  Bytes data;
  std::vector<Time> arrivals;
  std::optional<std::error_code> error;
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

/// The device side: a listener and the sessions it accepted.
struct Device {
  Device(asio::io_context& io, AsioExecutor& ex, const std::string& path, PtyOptions options = {})
      : ex_(ex), listener(io, ex, path, std::move(options)) {
    listener.start([this](BytePipePtr p) {
      sessions.push_back(p);
      closed.emplace_back();
      const std::size_t i = sessions.size() - 1;
      p->start({[this](ByteView b) {
                  data.insert(data.end(), b.begin(), b.end());
                  for (std::size_t k = 0; k < b.size(); ++k)
                    arrivals.push_back(ex_.now());
                },
                [this, i](std::error_code ec) { closed[i] = ec; }});
      if (on_session) on_session(*p);
    });
  }

  std::string text() const { return {data.begin(), data.end()}; }

  AsioExecutor& ex_;
  PtyListener listener;
  std::vector<BytePipePtr> sessions;
  std::vector<std::optional<std::error_code>> closed;
  std::function<void(BytePipe&)> on_session;
  Bytes data;
  std::vector<Time> arrivals;
};

struct PtyTest : ::testing::Test {
  ~PtyTest() override { fs::remove(path); }
  asio::io_context io;
  AsioExecutor ex{io};
  std::string path = unique_path(::testing::UnitTest::GetInstance()->current_test_info()->name());
};

TEST_F(PtyTest, SymlinkPointsAtTheSlaveAndIsRemovedOnClose) {
  auto device = std::make_unique<Device>(io, ex, path);
  ASSERT_TRUE(fs::is_symlink(path));
  EXPECT_EQ(fs::read_symlink(path).string(), device->listener.slave_path());
  EXPECT_EQ(device->listener.address(), "pty://" + path);
  device->listener.close();
  EXPECT_FALSE(fs::exists(fs::symlink_status(path)));
}

TEST_F(PtyTest, BytesFlowBothWaysThroughTheSymlink) {
  Device device(io, ex, path);
  device.on_session = [](BytePipe& p) { p.write(protocol::to_bytes("^0|READY|*00$\r\n")); };
  Client client(io, ex, path);
  client.write("^1|PING|*00$\n");
  ASSERT_TRUE(
      test::run_until(io, [&] { return device.data.size() == 13 && client.data.size() == 15; }));
  // Raw mode: no CR/LF translation, no echo.
  EXPECT_EQ(device.text(), "^1|PING|*00$\n");
  EXPECT_EQ(client.text(), "^0|READY|*00$\r\n");
  ASSERT_EQ(device.sessions.size(), 1u);
  EXPECT_NE(device.sessions[0]->describe().find(path), std::string::npos);
}

// Flow control for a relay: a paused session leaves what the client writes
// in the pty until it resumes, and then delivers all of it, in order.
TEST_F(PtyTest, APausedSessionLeavesTheClientsBytesUnreadUntilResumed) {
  Device device(io, ex, path);
  Client client(io, ex, path);
  client.write("first\n");
  ASSERT_TRUE(test::run_until(io, [&] { return device.text() == "first\n"; })) << device.text();
  ASSERT_EQ(device.sessions.size(), 1u);
  device.sessions[0]->pause_reading();
  // A read already waiting may still take one piece; after that, nothing.
  client.write("second\n");
  test::run_for(io, std::chrono::milliseconds(100));
  const std::size_t taken = device.data.size();
  client.write("third\n");
  test::run_for(io, std::chrono::milliseconds(300));
  EXPECT_EQ(device.data.size(), taken) << device.text();
  device.sessions[0]->resume_reading();
  ASSERT_TRUE(test::run_until(io, [&] { return device.text() == "first\nsecond\nthird\n"; }))
      << device.text();
}

// when_drained_to tells once the paced backlog has gone down to the level.
TEST_F(PtyTest, WhenDrainedToTellsOnceTheBacklogIsDown) {
  PtyOptions options;
  options.baud = 9600;  // about 1 ms a byte
  Device device(io, ex, path, options);
  Client client(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return device.sessions.size() == 1; }));
  BytePipe& session = *device.sessions[0];
  session.write(Bytes(300, 'x'));
  EXPECT_GT(session.queued_bytes(), 100u);
  int told = 0;
  std::size_t backlog_when_told = 0;
  const Time asked = ex.now();
  session.when_drained_to(100, [&] {
    ++told;
    backlog_when_told = session.queued_bytes();
  });
  ASSERT_TRUE(test::run_until(io, [&] { return told > 0; }));
  EXPECT_LE(backlog_when_told, 100u);
  // About 200 bytes at 1.04 ms each had to go first.
  EXPECT_GE(ex.now() - asked, milliseconds(150));
  ASSERT_TRUE(test::run_until(io, [&] { return client.data.size() == 300; }));
  EXPECT_EQ(told, 1);
  // Already down to the level: told at once (posted, not inside the call).
  session.when_drained_to(0, [&] { ++told; });
  EXPECT_EQ(told, 1);
  ASSERT_TRUE(test::run_until(io, [&] { return told == 2; }));
}

TEST_F(PtyTest, ClientOpenIsNoticedWithinAFewPollPeriods) {
  Device device(io, ex, path);
  Time accepted{-1};
  device.on_session = [&](BytePipe&) { accepted = ex.now(); };
  test::run_for(io, milliseconds(30));  // the listener is idle, polling
  const Time opened = ex.now();
  Client client(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return accepted >= Time{0}; }));
  std::printf("open noticed after %.1f ms (poll period 10 ms)\n", to_ms(accepted - opened));
  EXPECT_LE(accepted - opened, milliseconds(500));
  EXPECT_EQ(device.sessions.size(), 1u);
}

TEST_F(PtyTest, NinetySixByteFrameAt9600TakesAboutOneHundredMilliseconds) {
  PtyOptions options;
  options.baud = 9600;
  Device device(io, ex, path, options);
  Time written{-1};
  const std::string frame(96, 'x');
  device.on_session = [&](BytePipe& p) {
    written = ex.now();
    p.write(protocol::to_bytes(frame));
  };
  Client client(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return client.data.size() == 96; }));
  const auto last = to_ms(client.arrivals.back() - written);
  const auto spread = to_ms(client.arrivals.back() - client.arrivals.front());
  std::printf("96 bytes at 9600 baud: last byte after %.1f ms, first to last %.1f ms\n", last,
              spread);
  // Ideal: 100 ms and 99 ms. Bounds wide enough for a loaded machine.
  EXPECT_GE(last, 90.0);
  EXPECT_LE(last, 400.0);
  EXPECT_GE(spread, 40.0);
  // The bytes trickle in: many separate reads, not one lump.
  EXPECT_GE(std::set<Time>(client.arrivals.begin(), client.arrivals.end()).size(), 10u);
}

TEST_F(PtyTest, ClientBytesArePacedToTheDeviceToo) {
  PtyOptions options;
  options.baud = 9600;
  Device device(io, ex, path, options);
  Client client(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return !device.sessions.empty(); }));
  const Time written = ex.now();
  client.write(std::string(96, 'y'));
  ASSERT_TRUE(test::run_until(io, [&] { return device.data.size() == 96; }));
  const auto last = to_ms(device.arrivals.back() - written);
  std::printf("96 client bytes at 9600 baud reached the device after %.1f ms\n", last);
  EXPECT_GE(last, 90.0);
  EXPECT_LE(last, 400.0);
  EXPECT_GE(to_ms(device.arrivals.back() - device.arrivals.front()), 40.0);
}

TEST_F(PtyTest, ResetOnOpenLosesEarlyBytesAndKeepsLaterOnes) {
  PtyOptions options;
  options.reset_on_open = milliseconds(300);
  std::vector<std::string> log;
  options.log = [&](const std::string& line) { log.push_back(line); };
  Device device(io, ex, path, options);
  Client client(io, ex, path);
  client.write("EARLY");  // while the board boots
  ex.call_after(milliseconds(700), [&] { client.write("LATE"); });
  ASSERT_TRUE(test::run_until(io, [&] { return device.data.size() >= 4; }));
  EXPECT_EQ(device.text(), "LATE");
  EXPECT_EQ(device.listener.bytes_lost_to_reset(), 5u);
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.front().find("lost to reset_on_open"), std::string::npos);
}

TEST_F(PtyTest, ClientCloseEndsTheSessionAndANewOpenStartsAFreshOne) {
  Device device(io, ex, path);
  int opened = 0;
  device.on_session = [&](BytePipe& p) {
    ++opened;
    p.write(protocol::to_bytes("hello " + std::to_string(opened) + "\n"));
  };
  {
    Client first(io, ex, path);
    ASSERT_TRUE(test::run_until(io, [&] { return first.data.size() == 8; }));
    EXPECT_EQ(first.text(), "hello 1\n");
    first.write("bye");
    // The device keeps talking to a client that is about to go away.
    device.sessions[0]->write(Bytes(200, '!'));
    ASSERT_TRUE(test::run_until(io, [&] { return device.data.size() == 3; }));
  }
  ASSERT_TRUE(test::run_until(io, [&] { return device.closed[0].has_value(); }));
  EXPECT_EQ(*device.closed[0], end_of_stream());
  EXPECT_FALSE(device.sessions[0]->is_open());

  Client second(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return second.data.size() >= 8; }));
  test::run_for(io, milliseconds(30));
  // Nothing of the first session leaks into the second.
  EXPECT_EQ(second.text(), "hello 2\n");
  EXPECT_EQ(device.sessions.size(), 2u);
}

TEST_F(PtyTest, ADroppedSessionGivesThePortBackForTheNextClient) {
  PtyListener listener(io, ex, path);
  int accepted = 0;
  listener.start([&](BytePipePtr) { ++accepted; });  // dropped at once, never started
  {
    Client first(io, ex, path);
    ASSERT_TRUE(test::run_until(io, [&] { return accepted == 1; }));
  }
  // Long enough for the listener to see the port closed (one poll period);
  // a reopen faster than that looks like the same client.
  test::run_for(io, milliseconds(100));
  Client second(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return accepted == 2; }));
}

TEST_F(PtyTest, GracefulCloseFromTheDeviceFlushesPacedBytes) {
  PtyOptions options;
  options.baud = 19200;
  Device device(io, ex, path, options);
  device.on_session = [](BytePipe& p) {
    p.write(protocol::to_bytes("goodbye"));
    p.close();
  };
  Client client(io, ex, path);
  ASSERT_TRUE(
      test::run_until(io, [&] { return client.data.size() == 7 && device.closed[0].has_value(); }));
  EXPECT_EQ(client.text(), "goodbye");
  EXPECT_EQ(*device.closed[0], std::errc::operation_canceled);
}

TEST_F(PtyTest, ClosingTheListenerHangsUpTheClient) {
  Device device(io, ex, path);
  Client client(io, ex, path);
  ASSERT_TRUE(test::run_until(io, [&] { return !device.sessions.empty(); }));
  device.listener.close();
  ASSERT_TRUE(test::run_until(
      io, [&] { return client.error.has_value() && device.closed[0].has_value(); }));
  EXPECT_EQ(*device.closed[0], std::errc::operation_canceled);
  EXPECT_FALSE(fs::exists(fs::symlink_status(path)));
}

TEST_F(PtyTest, StaleSymlinkIsReplaced) {
  fs::create_symlink("/dev/pts/does-not-exist", path);
  Device device(io, ex, path);
  EXPECT_EQ(fs::read_symlink(path).string(), device.listener.slave_path());
}

TEST_F(PtyTest, RegularFileAtThePathIsNeverReplaced) {
  { std::ofstream(path) << "precious"; }
  try {
    PtyListener listener(io, ex, path);
    FAIL() << "the listener replaced a regular file";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::ifstream in(path);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");
}

TEST_F(PtyTest, ConnectOpensThePortLikeAClient) {
  Device device(io, ex, path);
  device.on_session = [](BytePipe& p) { p.write(protocol::to_bytes("OK\n")); };
  BytePipePtr pipe;
  Bytes got;
  std::optional<std::error_code> closed;
  pty_connect(io, ex, PtyEndpoint{path, 0, {}}, [&](std::error_code ec, BytePipePtr p) {
    ASSERT_FALSE(ec) << ec.message();
    pipe = p;
    p->start({[&](ByteView b) { got.insert(got.end(), b.begin(), b.end()); },
              [&](std::error_code e) { closed = e; }});
    p->write(protocol::to_bytes("AT\n"));
  });
  ASSERT_TRUE(test::run_until(io, [&] { return got.size() == 3 && device.data.size() == 3; }));
  EXPECT_EQ(std::string(got.begin(), got.end()), "OK\n");
  EXPECT_EQ(device.text(), "AT\n");
  pipe->close();
  ASSERT_TRUE(
      test::run_until(io, [&] { return closed.has_value() && device.closed[0].has_value(); }));
  EXPECT_EQ(*device.closed[0], end_of_stream());
}

TEST_F(PtyTest, ConnectToAMissingPathFails) {
  std::optional<std::error_code> result;
  pty_connect(io, ex, PtyEndpoint{path + "-missing", 0, {}},
              [&](std::error_code ec, BytePipePtr) { result = ec; });
  EXPECT_FALSE(result.has_value());  // never inside connect
  ASSERT_TRUE(test::run_until(io, [&] { return result.has_value(); }));
  EXPECT_EQ(*result, std::errc::no_such_file_or_directory);
}

}  // namespace
}  // namespace hil::link
