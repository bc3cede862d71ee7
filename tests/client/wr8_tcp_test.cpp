// The WR8 client session against the mock WR8 vehicle over real TCP
// (tcp://127.0.0.1:0) under the real-time driver; bounded waits only.

#include <gtest/gtest.h>

#include <asio/io_context.hpp>

#include <vector>

#include "client/wr8/session.hpp"
#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::client::wr8 {
namespace {

TEST(Wr8SessionTcp, LogsInReadsDataAndCompletesATurnOverRealTcp) {
  asio::io_context io;
  link::AsioExecutor executor(io);
  link::TransportContext context{executor, &io};
  sim::World world({sim::default_warehouse_arena()});
  sim::Vehicle& vehicle = world.add_vehicle(sim::wr8_vehicle());
  mocks::Wr8Firmware firmware(world, vehicle);
  mocks::ServerOptions options;
  options.listen = link::parse_endpoint("tcp://127.0.0.1:0");
  mocks::MockServer server(context, firmware, options);
  server.start();

  std::vector<Event> events;
  Wr8Session session(context, link::parse_endpoint(server.address()), {},
                     [&](Time, const Event& e) { events.push_back(e); });
  session.connect();
  ASSERT_TRUE(link::test::run_until(
      io, [&] { return session.core().state() == ConnectionState::connected; }));
  ASSERT_TRUE(link::test::run_until(io, [&] { return session.core().live().has_value(); }));
  EXPECT_EQ(session.core().live()->battery_percent, 100.0);

  const auto r = session.turn(10);
  ASSERT_TRUE(r);
  auto final_state = [&]() -> std::optional<RequestState> {
    for (const auto& e : events) {
      const auto* q = std::get_if<RequestEvent>(&e);
      if (q && q->coi == r.coi && q->state != RequestState::sent &&
          q->state != RequestState::started)
        return q->state;
    }
    return std::nullopt;
  };
  ASSERT_TRUE(link::test::run_until(io, [&] { return final_state().has_value(); }));
  EXPECT_EQ(final_state(), RequestState::completed);
  EXPECT_NEAR(firmware.state().commanded_wheel_angle_deg, 10.0, 1e-9);
  EXPECT_FALSE(session.core().log()->to_string(client::LogFormat::ndjson).empty());
}

}  // namespace
}  // namespace hil::client::wr8
