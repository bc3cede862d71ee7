#include "link/transport.hpp"

#include <gtest/gtest.h>

#include <asio/io_context.hpp>

#include "link/asio_executor.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace {

TEST(Transport, RealTimeSchemesNeedTheRealTimeDriver) {
  VirtualExecutor ex;
  TransportContext context{ex};
  try {
    listen(context, parse_endpoint("tcp://127.0.0.1:0"));
    FAIL() << "tcp:// listened without an io_context";
  } catch (const EndpointError& e) {
    EXPECT_NE(std::string(e.what()).find("tcp:// needs the real-time driver"), std::string::npos);
  }
  EXPECT_THROW(connect(context, parse_endpoint("pty:///tmp/hil-nothing"),
                       [](std::error_code, BytePipePtr) {}),
               EndpointError);
}

TEST(Transport, MemWorksWithoutANetworkGiven) {
  VirtualExecutor ex;
  TransportContext context{ex};
  auto listener = listen(context, parse_endpoint("mem://car0"));
  Bytes got;
  BytePipePtr server;
  listener->start([&](BytePipePtr p) {
    server = p;
    p->start({[&got](ByteView b) { got.insert(got.end(), b.begin(), b.end()); }, {}});
  });
  BytePipePtr client;
  connect(context, parse_endpoint("mem://car0"), [&](std::error_code ec, BytePipePtr p) {
    ASSERT_FALSE(ec);
    client = p;
    p->write(protocol::to_bytes("hi"));
  });
  ex.run_until_idle();
  EXPECT_EQ(std::string(got.begin(), got.end()), "hi");
}

TEST(Transport, TcpByUri) {
  asio::io_context io;
  AsioExecutor ex(io);
  TransportContext context{ex, &io};
  auto listener = listen(context, parse_endpoint("tcp://127.0.0.1:0"));
  Bytes got;
  BytePipePtr server;
  listener->start([&](BytePipePtr p) {
    server = p;
    p->start({[&got](ByteView b) { got.insert(got.end(), b.begin(), b.end()); }, {}});
  });
  BytePipePtr client;
  connect(context, parse_endpoint(listener->address()), [&](std::error_code ec, BytePipePtr p) {
    ASSERT_FALSE(ec) << ec.message();
    client = p;
    p->write(protocol::to_bytes("over tcp"));
  });
  ASSERT_TRUE(test::run_until(io, [&] { return got.size() == 8; }));
  EXPECT_EQ(std::string(got.begin(), got.end()), "over tcp");
}

TEST(Transport, PtyByUriCarriesItsOptions) {
  asio::io_context io;
  AsioExecutor ex(io);
  TransportContext context{ex, &io};
  const std::string uri =
      "pty:///tmp/hil-test-" + std::to_string(::getpid()) + "-uri?baud=9600&reset_ms=50";
  auto listener = listen(context, parse_endpoint(uri));
  EXPECT_EQ(listener->address(), uri);
  listener->close();
}

}  // namespace
}  // namespace hil::link
