// The Leka client session over a real pty at 115200 baud against the mock
// robot, under the real-time driver. Waits are bounded and generous.

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include <asio/io_context.hpp>

#include "client/leka/session.hpp"
#include "link/endpoint.hpp"
#include "mocks/leka.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/real_time_car.hpp"

namespace hil::client::leka {
namespace {

TEST(LekaSessionOverPty, APacedBurstAndAnInfoReachTheRobotWhole) {
  mocks::test::PtyCar<mocks::LekaFirmware> car("leka0", "?baud=115200", sim::leka_robot());
  asio::io_context& io = car.io;
  const auto& firmware = car.firmware;

  // A timeout that a loaded machine cannot miss.
  LekaSession session(car.context, link::parse_endpoint(car.uri),
                      {.info_timeout = link::seconds(5)});
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
