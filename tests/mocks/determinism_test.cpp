// Every mock car under the virtual-time driver: the same seed and the same
// client bytes at the same times give the same bytes back and the same
// world, bit for bit; and the car really moved while doing so.

#include <gtest/gtest.h>

#include "link/transport.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"

namespace hil::mocks {
namespace {

using link::milliseconds;
using link::seconds;

struct Step {
  link::Time at;
  protocol::Bytes bytes;
};

// A client session that drives each car for a while.
std::vector<Step> session(CarKind kind) {
  namespace logi = protocol::logi;
  namespace wr8 = protocol::wr8;
  namespace arduino = protocol::arduino;
  namespace leka = protocol::leka;
  switch (kind) {
    case CarKind::logi:
      return {{milliseconds(100), logi::encode(logi::SetSpeed{80})},
              {milliseconds(150), logi::encode(logi::SetStation{2})},
              {milliseconds(200), logi::encode(logi::SetRun{true})}};
    case CarKind::wr8:
      return {{milliseconds(100), wr8::encode(wr8::Auth{wr8::default_profile().auth_text})},
              {milliseconds(300),
               wr8::encode(wr8::Task{7, wr8::TaskCode::drive, {wr8::Word::from_i32(100)}})}};
    case CarKind::arduino:
      return {{milliseconds(100), arduino::encode({1, arduino::SetSpeed{200}})},
              {milliseconds(300), arduino::encode({2, arduino::Move{60}})},
              {milliseconds(900), arduino::encode({3, arduino::SonarRead{}})},
              {milliseconds(1500), arduino::encode({4, arduino::StatusRequest{}})}};
    case CarKind::leka:
      return {{milliseconds(100),
               leka::encode(leka::CommandGroup{
                   {leka::EarAll{{255, 0, 0}},
                    leka::MotorDuo{leka::kSpinForward, 200, leka::kSpinForward, 120}}})},
              {milliseconds(2000), leka::encode(leka::CommandGroup{{leka::Info{}}})}};
  }
  return {};
}

struct SessionRun {
  protocol::Bytes received;
  std::uint64_t world_hash = 0;
  sim::Pose start;
  sim::Pose end;
};

SessionRun run_session(CarKind kind, std::uint64_t seed) {
  link::VirtualExecutor executor;
  link::TransportContext context{executor};
  CarOptions options;
  options.kind = kind;
  options.seed = seed;
  MockCar car(options);
  ServerOptions server_options;
  server_options.listen = link::MemEndpoint{"car"};
  server_options.seed = seed;
  MockServer server(context, car.firmware(), server_options);
  server.start();
  SessionRun run;
  run.start = car.vehicle().pose();
  link::BytePipePtr client;
  link::connect(context, link::MemEndpoint{"car"}, [&](std::error_code ec, link::BytePipePtr p) {
    ASSERT_FALSE(ec);
    client = p;
    client->start(
        {[&](protocol::ByteView b) { run.received.insert(run.received.end(), b.begin(), b.end()); },
         [](std::error_code) {}});
  });
  for (const auto& step : session(kind)) {
    executor.call_at(step.at, [&client, bytes = step.bytes] { client->write(bytes); });
  }
  executor.run_until(link::Time(seconds(5)));
  run.world_hash = car.world().state_hash();
  run.end = car.vehicle().pose();
  server.close();
  return run;
}

class EveryCar : public testing::TestWithParam<CarKind> {};

TEST_P(EveryCar, ReplaysBitForBitFromItsSeed) {
  const SessionRun a = run_session(GetParam(), 42);
  const SessionRun b = run_session(GetParam(), 42);
  EXPECT_FALSE(a.received.empty());
  EXPECT_EQ(a.received, b.received);
  EXPECT_EQ(a.world_hash, b.world_hash);
  // The commands drove the simulated chassis.
  EXPECT_GT(sim::length(a.end.position() - a.start.position()), 0.2)
      << "from (" << a.start.x_m << ", " << a.start.y_m << ") to (" << a.end.x_m << ", "
      << a.end.y_m << ")";
}

INSTANTIATE_TEST_SUITE_P(MockCars, EveryCar,
                         testing::Values(CarKind::logi, CarKind::wr8, CarKind::arduino,
                                         CarKind::leka),
                         [](const testing::TestParamInfo<CarKind>& param) {
                           return std::string(to_string(param.param));
                         });

TEST(MockCar, NamesAndDefaultsOfTheFourCars) {
  for (const auto kind : {CarKind::logi, CarKind::wr8, CarKind::arduino, CarKind::leka}) {
    EXPECT_EQ(parse_car_kind(to_string(kind)), kind);
    MockCar car(CarOptions{kind, sim::default_warehouse_arena(), 1, "c", {}, {}});
    EXPECT_EQ(car.firmware().protocol(), to_string(kind));
  }
  EXPECT_FALSE(parse_car_kind("tesla"));
  EXPECT_EQ(link::to_uri(default_endpoint(CarKind::logi, 2)), "tcp://127.0.0.1:9002");
  EXPECT_EQ(link::to_uri(default_endpoint(CarKind::wr8, 0)), "tcp://127.0.0.1:9100");
  EXPECT_EQ(link::to_uri(default_endpoint(CarKind::arduino, 1)),
            "pty:///tmp/hil-arduino1?baud=9600");
  EXPECT_EQ(car_seed(77, 0), 77u);
  EXPECT_NE(car_seed(77, 1), car_seed(77, 2));
}

}  // namespace
}  // namespace hil::mocks
