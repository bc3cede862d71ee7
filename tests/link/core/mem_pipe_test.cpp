#include <gtest/gtest.h>

#include <tuple>

#include "link/endpoint.hpp"
#include "link/mem_pipe.hpp"

namespace hil::link {
namespace {

struct PipeRecorder {
  std::string data;
  std::optional<std::error_code> closed;
  int ends = 0;             // on_end calls
  std::string data_at_end;  // what had arrived when on_end came
  bool closed_before_end = false;
  BytePipe::Handlers handlers(bool half_close = false) {
    BytePipe::Handlers h{[this](ByteView b) { data.append(b.begin(), b.end()); },
                         [this](std::error_code ec) {
                           closed = ec;
                           closed_before_end = ends == 0;
                         }};
    if (half_close) {
      h.on_end = [this] {
        ++ends;
        data_at_end = data;
      };
    }
    return h;
  }
};

// Two started ends of a mem:// line at `baud` (0: unpaced), each with its
// recorder; with `half_close` both take on_end.
struct PacedLine {
  explicit PacedLine(unsigned baud = 0, bool half_close = false) {
    std::tie(a, b) = make_mem_pipe(ex, "t", baud);
    a->start(ra.handlers(half_close));
    b->start(rb.handlers(half_close));
  }
  VirtualExecutor ex;
  BytePipePtr a, b;
  PipeRecorder ra, rb;
};

TEST(MemPipe, DeliversInOrderOnTheExecutor) {
  PacedLine line;
  auto& [ex, a, b, ra, rb] = line;
  a->write(protocol::to_bytes("hello "));
  a->write(protocol::to_bytes("world"));
  EXPECT_EQ(rb.data, "");  // nothing is delivered inside write()
  EXPECT_EQ(a->queued_bytes(), 11u);
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "hello world");
  EXPECT_EQ(a->queued_bytes(), 0u);
}

TEST(MemPipe, BytesBeforeStartAreKept) {
  VirtualExecutor ex;
  auto [a, b] = make_mem_pipe(ex, "t");
  PipeRecorder ra, rb;
  a->start(ra.handlers());
  a->write(protocol::to_bytes("early"));
  ex.run_until_idle();
  b->start(rb.handlers());
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "early");
}

TEST(MemPipe, GracefulCloseDeliversDataThenEndOfStream) {
  PacedLine line;
  auto& [ex, a, b, ra, rb] = line;
  a->write(protocol::to_bytes("last words"));
  a->close(CloseMode::graceful);
  a->write(protocol::to_bytes("ignored"));
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "last words");
  EXPECT_EQ(rb.closed, end_of_stream());
  ASSERT_TRUE(ra.closed.has_value());
  EXPECT_FALSE(a->is_open());
  EXPECT_FALSE(b->is_open());
}

TEST(MemPipe, ResetDropsDataInFlight) {
  PacedLine line;
  auto& [ex, a, b, ra, rb] = line;
  a->write(protocol::to_bytes("lost"));
  a->close(CloseMode::reset);
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "");
  EXPECT_EQ(rb.closed, std::make_error_code(std::errc::connection_reset));
}

// A paced line: 9600 baud, 8N1, so byte k of a burst is in once its last
// bit is, at (k + 1) * 1.0417 ms.
TEST(MemPipe, APacedLineDeliversEachByteOnceItsLastBitIsSent) {
  PacedLine line(9600);
  line.a->write(protocol::to_bytes("^01|PING| *31$"));  // 14 bytes: 14.58 ms on the line
  EXPECT_EQ(line.a->queued_bytes(), 14u);
  line.ex.run_until(Time(std::chrono::nanoseconds(14'583'333)));
  EXPECT_EQ(line.rb.data, "^01|PING| *31");  // the 14th byte's last bit is not out yet
  line.ex.run_until(Time(std::chrono::nanoseconds(14'583'334)));
  EXPECT_EQ(line.rb.data, "^01|PING| *31$");
  EXPECT_EQ(line.a->queued_bytes(), 0u);
}

TEST(MemPipe, APacedLinePacesEachDirectionOnItsOwn) {
  PacedLine line(9600);
  line.a->write(protocol::to_bytes("0123456789"));
  line.b->write(protocol::to_bytes("abcde"));
  line.ex.run_until(Time(milliseconds(6)));
  EXPECT_EQ(line.ra.data, "abcde");  // 5.21 ms
  EXPECT_EQ(line.rb.data, "01234");
  line.ex.run_until(Time(milliseconds(11)));
  EXPECT_EQ(line.rb.data, "0123456789");  // 10.42 ms
}

TEST(MemPipe, OnAPacedLineTheEndOfStreamFollowsTheBytesStillOnIt) {
  PacedLine line(9600);
  line.a->write(protocol::to_bytes("last"));
  line.a->close(CloseMode::graceful);
  line.ex.run_until(Time(milliseconds(4)));
  EXPECT_EQ(line.rb.data, "las");
  EXPECT_FALSE(line.rb.closed.has_value()) << "the close may not overtake the bytes";
  line.ex.run_until_idle();
  EXPECT_EQ(line.rb.data, "last");
  EXPECT_EQ(line.rb.closed, end_of_stream());
}

TEST(MemPipe, APacedLineDeliversWhatWasWrittenAfterItsWriterIsDropped) {
  VirtualExecutor ex;
  PipeRecorder rb;
  BytePipePtr b;
  {
    auto [a, server] = make_mem_pipe(ex, "t", 9600);
    b = server;
    b->start(rb.handlers());
    a->write(protocol::to_bytes("bye"));
    a->close(CloseMode::graceful);
  }
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "bye");
  EXPECT_EQ(rb.closed, end_of_stream());
}

TEST(MemPipe, AResetOnAPacedLineDropsWhatIsStillOnIt) {
  PacedLine line(9600);
  line.a->write(protocol::to_bytes("0123456789"));
  line.ex.run_until(Time(milliseconds(3)));
  line.a->close(CloseMode::reset);
  line.ex.run_until_idle();
  EXPECT_EQ(line.rb.data, "01");  // in by 2.08 ms; the rest was still on the line
  EXPECT_EQ(line.rb.closed, std::make_error_code(std::errc::connection_reset));
}

TEST(MemPipe, AHalfCloseEndsOneDirectionAndTheOtherKeepsFlowing) {
  PacedLine line(0, true);
  auto& [ex, a, b, ra, rb] = line;
  a->write(protocol::to_bytes("request"));
  a->shutdown_send();
  a->write(protocol::to_bytes("ignored"));
  EXPECT_TRUE(a->is_open()) << "a still reads";
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "request");
  EXPECT_EQ(rb.ends, 1);
  EXPECT_EQ(rb.data_at_end, "request") << "the end follows the bytes written before it";
  EXPECT_FALSE(rb.closed.has_value());
  EXPECT_FALSE(ra.closed.has_value());

  b->write(protocol::to_bytes("answer"));
  ex.run_until_idle();
  EXPECT_EQ(ra.data, "answer");
  EXPECT_TRUE(a->is_open());
  EXPECT_TRUE(b->is_open());

  b->shutdown_send();  // both directions have ended: both ends close
  ex.run_until_idle();
  EXPECT_EQ(ra.ends, 1);
  EXPECT_EQ(ra.closed, end_of_stream());
  EXPECT_FALSE(ra.closed_before_end);
  EXPECT_EQ(rb.closed, end_of_stream());
  EXPECT_FALSE(a->is_open());
  EXPECT_FALSE(b->is_open());
}

TEST(MemPipe, AHalfCloseToAnEndWithoutOnEndIsAClose) {
  VirtualExecutor ex;
  auto [a, b] = make_mem_pipe(ex, "t");
  PipeRecorder ra, rb;
  a->start(ra.handlers(true));
  b->start(rb.handlers(false));
  a->write(protocol::to_bytes("bye"));
  a->shutdown_send();
  EXPECT_FALSE(a->is_open()) << "closed instead, at once";
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "bye");
  EXPECT_EQ(rb.closed, end_of_stream());
  EXPECT_EQ(ra.closed, closed_here());
}

TEST(MemPipe, AnOutrightCloseIsNeverAHalfClose) {
  PacedLine line(0, true);
  auto& [ex, a, b, ra, rb] = line;
  a->close(CloseMode::graceful);
  ex.run_until_idle();
  EXPECT_EQ(rb.ends, 0);
  EXPECT_EQ(rb.closed, end_of_stream());
}

TEST(MemPipe, OnAPacedLineAHalfCloseFollowsTheBytesStillOnIt) {
  PacedLine line(9600, true);
  line.a->write(protocol::to_bytes("last"));  // 4.17 ms on the line
  line.a->shutdown_send();
  line.ex.run_until(Time(milliseconds(4)));
  EXPECT_EQ(line.rb.data, "las");
  EXPECT_EQ(line.rb.ends, 0) << "the end may not overtake the bytes";
  line.ex.run_until(Time(milliseconds(5)));
  EXPECT_EQ(line.rb.data, "last");
  EXPECT_EQ(line.rb.ends, 1);
  EXPECT_FALSE(line.rb.closed.has_value());
}

TEST(MemNetwork, AListenersBaudPacesEveryConnectionToIt) {
  VirtualExecutor ex;
  MemNetwork net(ex);
  auto listener = net.listen("car0", 9600);
  EXPECT_EQ(listener->address(), "mem://car0?baud=9600");
  BytePipePtr server, client;
  listener->start([&](BytePipePtr p) { server = std::move(p); });
  net.connect("car0", [&](std::error_code, BytePipePtr p) { client = std::move(p); });
  ex.run_until_idle();
  ASSERT_TRUE(server && client);
  PipeRecorder rs, rc;
  server->start(rs.handlers());
  client->start(rc.handlers());
  const Time start = ex.now();
  client->write(protocol::to_bytes("0123456789"));
  ex.run_until(start + milliseconds(10));
  EXPECT_EQ(rs.data, "012345678");
  ex.run_until(start + milliseconds(11));
  EXPECT_EQ(rs.data, "0123456789");
}

TEST(MemNetwork, ConnectsToAListener) {
  VirtualExecutor ex;
  MemNetwork net(ex);
  auto listener = net.listen("car0");
  EXPECT_EQ(listener->address(), "mem://car0");
  BytePipePtr server, client;
  listener->start([&](BytePipePtr p) { server = p; });
  net.connect("car0", [&](std::error_code ec, BytePipePtr p) {
    EXPECT_FALSE(ec);
    client = p;
  });
  ex.run_until_idle();
  ASSERT_TRUE(server && client);
  PipeRecorder rs, rc;
  server->start(rs.handlers());
  client->start(rc.handlers());
  client->write(protocol::to_bytes("LOGI:SP:050:D7#"));
  ex.run_until_idle();
  EXPECT_EQ(rs.data, "LOGI:SP:050:D7#");
}

TEST(MemNetwork, RefusesWhenNothingListens) {
  VirtualExecutor ex;
  MemNetwork net(ex);
  std::error_code result;
  net.connect("nobody", [&](std::error_code ec, BytePipePtr) { result = ec; });
  ex.run_until_idle();
  EXPECT_EQ(result, std::make_error_code(std::errc::connection_refused));
  auto l = net.listen("x");
  EXPECT_THROW(net.listen("x"), EndpointError);
  l->close();
  EXPECT_NO_THROW(net.listen("x"));
}

}  // namespace
}  // namespace hil::link
