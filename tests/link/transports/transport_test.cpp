#include "link/transport.hpp"

#include <gtest/gtest.h>

#include <asio/io_context.hpp>

#include "link/asio_executor.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace {

/// A listener on `uri` that keeps the connection it accepts and what
/// arrives on it.
struct Receiver {
  Receiver(TransportContext& context, const std::string& uri)
      : listener(listen(context, parse_endpoint(uri))) {
    listener->start([this](BytePipePtr p) {
      server = p;
      p->start({[this](ByteView b) { got.insert(got.end(), b.begin(), b.end()); }, {}});
    });
  }
  std::string text() const { return {got.begin(), got.end()}; }

  std::unique_ptr<Listener> listener;
  Bytes got;
  BytePipePtr server;
};

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
  Receiver car(context, "mem://car0");
  BytePipePtr client;
  connect(context, parse_endpoint("mem://car0"), [&](std::error_code ec, BytePipePtr p) {
    ASSERT_FALSE(ec);
    client = p;
    p->write(protocol::to_bytes("hi"));
  });
  ex.run_until_idle();
  EXPECT_EQ(car.text(), "hi");
}

TEST(Transport, TcpByUri) {
  asio::io_context io;
  AsioExecutor ex(io);
  TransportContext context{ex, &io};
  Receiver car(context, "tcp://127.0.0.1:0");
  BytePipePtr client;
  connect(context, parse_endpoint(car.listener->address()), [&](std::error_code ec, BytePipePtr p) {
    ASSERT_FALSE(ec) << ec.message();
    client = p;
    p->write(protocol::to_bytes("over tcp"));
  });
  ASSERT_TRUE(test::run_until(io, [&] { return car.got.size() == 8; }));
  EXPECT_EQ(car.text(), "over tcp");
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
