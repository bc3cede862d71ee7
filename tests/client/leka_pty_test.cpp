// The Leka client session over a real pty at 115200 baud against the mock
// robot, under the real-time driver. Waits are bounded and generous.

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include <asio/io_context.hpp>

#include "client/leka/session.hpp"
#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "mocks/leka.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/serial_support.hpp"

namespace hil::client::leka {
namespace {

TEST(LekaSessionOverPty, APacedBurstAndAnInfoReachTheRobotWhole) {
  mocks::test::TempDir dir("hil-leka-client");
  const std::string uri = "pty://" + (dir.path / "leka0").string() + "?baud=115200";
  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  sim::World world(sim::WorldDef{});
  sim::Vehicle& vehicle = world.add_vehicle(sim::leka_robot());
  mocks::LekaFirmware firmware(world, vehicle);
  mocks::ServerOptions server_options;
  server_options.listen = link::parse_endpoint(uri);
  mocks::MockServer server(context, firmware, server_options);
  server.start();

  // A timeout that a loaded machine cannot miss.
  LekaSession session(context, link::parse_endpoint(uri), {.info_timeout = link::seconds(5)});
  session.open();
  ASSERT_TRUE(link::test::run_until(io, [&] { return session.is_open(); }))
      << "the port never opened";

  GroupBuilder b;
  for (int i = 0; i < 60; ++i)
    b.belt_single(i % 20, {static_cast<std::uint8_t>(i + 1), 0, 0});
  b.motor_all(1, 50);
  ASSERT_TRUE(session.send(b).ok());
  std::optional<InfoResult> result;
  session.info([&](const InfoResult& r) { result = r; });
  ASSERT_TRUE(link::test::run_until(io, [&] { return result.has_value(); }));
  EXPECT_EQ(result->status, InfoStatus::ok);
  ASSERT_TRUE(result->reply.has_value());
  EXPECT_EQ(result->reply->name, "leka");
  EXPECT_EQ(result->reply->buffer_bytes, 128);
  EXPECT_EQ(firmware.state().counters.commands_run, 62u);
  EXPECT_EQ(firmware.state().counters.bytes_lost, 0u);
  EXPECT_EQ(firmware.state().left, (mocks::LekaMotor{1, 50}));
  EXPECT_EQ(firmware.state().belt[19], (proto::Rgb{60, 0, 0}));
  session.close();
  EXPECT_FALSE(session.is_open());
}

}  // namespace
}  // namespace hil::client::leka
