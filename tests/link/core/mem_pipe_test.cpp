#include <gtest/gtest.h>

#include "link/endpoint.hpp"
#include "link/mem_pipe.hpp"

namespace hil::link {
namespace {

struct PipeRecorder {
  std::string data;
  std::optional<std::error_code> closed;
  BytePipe::Handlers handlers() {
    return {[this](ByteView b) { data.append(b.begin(), b.end()); },
            [this](std::error_code ec) { closed = ec; }};
  }
};

TEST(MemPipe, DeliversInOrderOnTheExecutor) {
  VirtualExecutor ex;
  auto [a, b] = make_mem_pipe(ex, "t");
  PipeRecorder ra, rb;
  a->start(ra.handlers());
  b->start(rb.handlers());
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
  VirtualExecutor ex;
  auto [a, b] = make_mem_pipe(ex, "t");
  PipeRecorder ra, rb;
  a->start(ra.handlers());
  b->start(rb.handlers());
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
  VirtualExecutor ex;
  auto [a, b] = make_mem_pipe(ex, "t");
  PipeRecorder ra, rb;
  a->start(ra.handlers());
  b->start(rb.handlers());
  a->write(protocol::to_bytes("lost"));
  a->close(CloseMode::reset);
  ex.run_until_idle();
  EXPECT_EQ(rb.data, "");
  EXPECT_EQ(rb.closed, std::make_error_code(std::errc::connection_reset));
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
