// The LOGI client session against the mock LOGI car over real TCP
// (tcp://127.0.0.1:0) under the real-time driver; bounded waits only.

#include <gtest/gtest.h>

#include <asio/io_context.hpp>

#include <vector>

#include "client/logi/session.hpp"
#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"
#include "mocks/logi.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::client::logi {
namespace {

using proto::Direction;
using proto::Mode;

TEST(LogiSessionTcp, DrivesTheMockCarOverRealTcpAndNoticesItsLoss) {
  asio::io_context io;
  link::AsioExecutor executor(io);
  link::TransportContext context{executor, &io};
  sim::World world({sim::default_warehouse_arena()});
  sim::Vehicle& vehicle = world.add_vehicle(sim::logi_car());
  mocks::LogiFirmware firmware(world, vehicle);
  mocks::ServerOptions options;
  options.listen = link::parse_endpoint("tcp://127.0.0.1:0");
  mocks::MockServer server(context, firmware, options);
  server.start();

  std::vector<Event> events;
  LogiSession session(context, link::parse_endpoint(server.address()), {},
                      [&](Time, const Event& e) { events.push_back(e); });
  session.connect();
  ASSERT_TRUE(link::test::run_until(
      io, [&] { return session.core().state() == ConnectionState::connected; }));

  auto accepted = [&](RequestId id) {
    for (const auto& e : events) {
      const auto* c = std::get_if<CommandEvent>(&e);
      if (c && c->request == id && c->state == CommandState::accepted) return true;
    }
    return false;
  };
  session.submit(proto::SetSpeed{40});
  const auto md = session.submit(proto::SetMode{Mode::manual});
  ASSERT_TRUE(link::test::run_until(io, [&] { return accepted(md.request); }));
  const auto mv = session.press(Direction::fwd);
  ASSERT_TRUE(mv);
  ASSERT_TRUE(link::test::run_until(io, [&] {
    const auto& s = session.core().last_status();
    return accepted(mv.request) && s && s->mode == Mode::manual && s->manual == Direction::fwd;
  }));
  session.release();
  ASSERT_TRUE(link::test::run_until(io, [&] {
    const auto& s = session.core().last_status();
    return s && s->manual == Direction::stop && session.core().in_flight() == 0;
  }));
  EXPECT_EQ(firmware.state().manual, Direction::stop);

  // The car goes away: the client enters the safe state and waits to reconnect.
  server.close();
  ASSERT_TRUE(link::test::run_until(io, [&] {
    return session.core().state() == ConnectionState::reconnecting ||
           session.core().state() == ConnectionState::connecting;
  }));
  EXPECT_FALSE(session.core().movement_enabled());
  EXPECT_EQ(session.press(Direction::fwd).refusal, Refusal::not_connected);

  session.disconnect();
  EXPECT_EQ(session.core().state(), ConnectionState::disconnected);
  const std::string log = session.log()->to_string(client::LogFormat::txt);
  EXPECT_NE(log.find("TX   LOGI:MV:FWD:23#"), std::string::npos) << log;
  EXPECT_NE(log.find("RX   LOGI:FB:MV:1:"), std::string::npos) << log;
}

}  // namespace
}  // namespace hil::client::logi
