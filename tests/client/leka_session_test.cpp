// The Leka client session against the mock Leka robot on mem:// in virtual
// time: a multi-command group changes LEDs and motors, a paced burst loses
// nothing where an unpaced one overruns the serial buffer, info is parsed,
// and an ignored info times out.

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>

#include "client/leka/session.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/leka.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::leka {
namespace {

using link::milliseconds;

Time at_ms(int ms) {
  return Time(milliseconds(ms));
}

struct LekaSessionOnMem : ::testing::Test, test::VirtualCar<mocks::LekaFirmware> {
  void start(ClientConfig config = {}) {
    start_car(sim::leka_robot(), test::on_mem("leka"));
    session = std::make_unique<LekaSession>(context, link::MemEndpoint{"leka"}, config);
    session->set_wall_clock([this] { return executor.now().count() / 1000; });
    session->open();
    executor.run_for(Duration::zero());
    ASSERT_TRUE(session->is_open());
    ASSERT_EQ(executor.now(), at_ms(0));
  }

  /// Bytes of TX log entries, with the virtual millisecond they went out.
  std::vector<std::pair<std::int64_t, std::size_t>> tx_times() {
    std::vector<std::pair<std::int64_t, std::size_t>> out;
    for (const auto& e : session->log().entries())
      if (e.kind == LogKind::tx) out.push_back({e.utc_us / 1000, e.raw.size()});
    return out;
  }

  static GroupBuilder burst() {
    GroupBuilder b;
    for (int i = 0; i < 60; ++i)
      b.belt_single(i % 20, {static_cast<std::uint8_t>(i + 1), 0, 0});
    return b;
  }

  /// Asks for INFO now; its result goes to `info` and its time to `info_at`.
  void ask_info() {
    session->info([this](const InfoResult& r) {
      info = r;
      info_at = executor.now();
    });
  }

  std::unique_ptr<LekaSession> session;
  std::optional<InfoResult> info;
  std::optional<Time> info_at;
};

TEST_F(LekaSessionOnMem, AMultiCommandGroupChangesLedsAndMotorsAtTheNextPass) {
  start();
  executor.run_until(at_ms(3));
  GroupBuilder b;
  b.ear_all({255, 0, 0}).belt_all({0, 0, 255}).belt_single(4, {0, 255, 0}).motor_duo(0, 100, 1, 80);
  ASSERT_TRUE(session->send(b).ok());
  executor.run_until(at_ms(9));
  EXPECT_EQ(firmware->state().left.speed, 0) << "nothing runs before the 10 ms pass";
  executor.run_until(at_ms(10));
  const auto& s = firmware->state();
  EXPECT_EQ(s.ears[0], (proto::Rgb{255, 0, 0}));
  EXPECT_EQ(s.ears[1], (proto::Rgb{255, 0, 0}));
  EXPECT_EQ(s.belt[0], (proto::Rgb{0, 0, 255}));
  EXPECT_EQ(s.belt[4], (proto::Rgb{0, 255, 0}));
  EXPECT_EQ(s.left, (mocks::LekaMotor{0, 100}));
  EXPECT_EQ(s.right, (mocks::LekaMotor{1, 80}));
  EXPECT_EQ(s.counters.commands_run, 4u);
  ASSERT_EQ(tx_times().size(), 1u);
  EXPECT_EQ(tx_times()[0].first, 3);
}

TEST_F(LekaSessionOnMem, APaced300ByteBurstLosesNothing) {
  start();
  ASSERT_TRUE(session->send(burst()).ok());
  executor.run_until(at_ms(200));
  EXPECT_EQ(firmware->state().counters.bytes_lost, 0u);
  EXPECT_EQ(firmware->state().counters.commands_run, 60u);
  EXPECT_EQ(firmware->stats().bad_frames, 0u);
  const std::vector<std::pair<std::int64_t, std::size_t>> expected = {{0, 61},  {10, 61}, {20, 61},
                                                                      {30, 61}, {40, 61}, {50, 31}};
  EXPECT_EQ(tx_times(), expected);
  // The last command for LED 19 was the 60th: red 60.
  EXPECT_EQ(firmware->state().belt[19], (proto::Rgb{60, 0, 0}));
}

TEST_F(LekaSessionOnMem, TheSameBurstUnpacedOverrunsTheSerialBuffer) {
  start({.paced = false});
  ASSERT_TRUE(session->send(burst()).ok());
  executor.run_until(at_ms(200));
  EXPECT_GT(firmware->state().counters.bytes_lost, 0u);
  EXPECT_LT(firmware->state().counters.commands_run, 60u);
  ASSERT_EQ(tx_times().size(), 6u);
  EXPECT_EQ(tx_times().back().first, 0);
}

TEST_F(LekaSessionOnMem, InfoIsAnsweredAtTheNextPassAndParsed) {
  start();
  executor.run_until(at_ms(4));
  ask_info();
  executor.run_until(at_ms(300));
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->status, InfoStatus::ok);
  EXPECT_EQ(info_at, at_ms(10));
  EXPECT_EQ(info->reply->name, "leka");
  EXPECT_EQ(info->reply->firmware, "1.0.0");
  EXPECT_EQ(info->reply->buffer_bytes, 128);
  EXPECT_EQ(info->reply->state, "ok");
  const auto entries = session->log().entries();
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[1].kind, LogKind::rx);
  EXPECT_EQ(entries[1].note, "LEKA name=leka firmware=1.0.0 buffer=128 state=ok");
}

TEST_F(LekaSessionOnMem, AnIgnoredInfoTimesOut200msAfterItWentOut) {
  start();
  firmware->arm(mocks::Behaviour{"", mocks::When{}, mocks::Ignore{"info", 1, std::nullopt}});
  executor.run_until(at_ms(5));
  ask_info();
  executor.run_until(at_ms(204));
  EXPECT_FALSE(info.has_value());
  executor.run_until(at_ms(400));
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->status, InfoStatus::timeout);
  EXPECT_EQ(info_at, at_ms(205));
  EXPECT_EQ(firmware->state().counters.info_answers, 0u);
}

}  // namespace
}  // namespace hil::client::leka
