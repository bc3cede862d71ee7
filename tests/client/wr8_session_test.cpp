// The WR8 client session against the mock WR8 vehicle on mem:// in virtual
// time: login, a 100 cm drive, a turn, settings round trip, a rejected and
// an ignored task, a wrong AUTH string with its reconnect timeline, and
// DATA going stale while telemetry is muted.

#include "client/wr8/session.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <utility>
#include <vector>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;

std::pair<Time, RequestState> at(Time t, RequestState s) {
  return {t, s};
}

/// The mock vehicle on mem://car and a session pointed at it, in virtual time.
class VirtualBench : public test::SessionOnMem<Wr8Session, mocks::Wr8Firmware, Event> {
 public:
  explicit VirtualBench(mocks::Wr8Config car = {}, ClientConfig config = {})
      : SessionOnMem("wr8", sim::wr8_vehicle(), {}, std::move(config), car) {}

  /// The request events of one COI, with their times.
  std::vector<std::pair<Time, RequestState>> request(std::uint8_t coi) const {
    std::vector<std::pair<Time, RequestState>> out;
    for (const auto& [t, e] : of<RequestEvent>()) {
      if (e.coi == coi) out.emplace_back(t, e.state);
    }
    return out;
  }
  /// Runs until `t`; the request events of one COI by then.
  std::vector<std::pair<Time, RequestState>> request_by(std::uint8_t coi, Time t) {
    run_until(t);
    return request(coi);
  }
};

/// Logs in at 0 ms and runs to 1 ms.
void login(VirtualBench& bench) {
  bench.session().connect();
  bench.run_until(milliseconds(1));
  ASSERT_EQ(bench.session().core().state(), ConnectionState::connected);
}

TEST(Wr8Session, LogsInAndReceivesDataEvery100Ms) {
  VirtualBench bench;
  login(bench);
  const auto logins = bench.of<LoginEvent>();
  ASSERT_EQ(logins.size(), 1u);
  EXPECT_EQ(logins[0].second.reply.device_code, 8);
  EXPECT_EQ(logins[0].second.reply.device_id, 1);
  EXPECT_EQ(bench.firmware().state().session, mocks::Wr8Session::authenticated);

  bench.run_until(milliseconds(350));
  const auto data = bench.of<TelemetryEvent>();
  ASSERT_EQ(data.size(), 3u);
  EXPECT_EQ(data[0].first, milliseconds(100));
  EXPECT_EQ(data[2].first, milliseconds(300));
  EXPECT_EQ(data[2].second.live.timestamp_ms, 300u);
  EXPECT_EQ(data[2].second.live.battery_percent, 100.0);
  EXPECT_EQ(data[2].second.live.state, proto::State::stop);
}

TEST(Wr8Session, A100CmDriveStartsAtOnceAndCompletesAtTheDistance) {
  VirtualBench bench;
  login(bench);
  const auto r = bench.session().drive(100);
  ASSERT_TRUE(r);
  const auto states = bench.request_by(r.coi, seconds(5));
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[0], at(milliseconds(1), RequestState::sent));
  EXPECT_EQ(states[1], at(milliseconds(1), RequestState::started));
  EXPECT_EQ(states[2].second, RequestState::completed);
  // About 3.33 s for 100 cm from rest (docs/mocks/wr8.md), on the 10 ms control grid.
  EXPECT_GT(states[2].first, seconds(3));
  EXPECT_LT(states[2].first, milliseconds(3500));
  EXPECT_EQ(states[2].first.count() % milliseconds(10).count(), 0);
  const auto& live = bench.session().core().live();
  ASSERT_TRUE(live);
  EXPECT_GE(*live->odometry_cm, 100.0);
  EXPECT_EQ(live->state, proto::State::stop);
}

TEST(Wr8Session, ATurnTo15DegreesCompletesWhenTheWheelsGetThere) {
  VirtualBench bench;
  login(bench);
  bench.run_until(seconds(1));
  const auto r = bench.session().turn(15);
  const auto states = bench.request_by(r.coi, seconds(2));
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[1], at(seconds(1), RequestState::started));
  // The servo reaches 15 degrees at 1083.3 ms; the next control tick is 1090 ms.
  EXPECT_EQ(states[2], at(milliseconds(1090), RequestState::completed));
  EXPECT_NEAR(*bench.session().core().live()->wheel_angle_deg, 15.0, 0.01);
}

TEST(Wr8Session, SettingsSetThenReadBackGiveTheNewValues) {
  VirtualBench bench;
  login(bench);
  const std::vector<proto::Setting> wanted = {
      {proto::SettingCode::p, proto::Word::from_f32(2.0f)},
      {proto::SettingCode::servo_zero, proto::Word::from_i32(95)}};
  const auto set = bench.session().set_settings(wanted);
  ASSERT_TRUE(set);
  bench.run_until(milliseconds(10));
  ASSERT_EQ(bench.request(set.coi).back().second, RequestState::completed);
  EXPECT_EQ(bench.firmware().state().p, 2.0);

  const auto get = bench.session().get_settings();
  bench.run_until(milliseconds(20));
  EXPECT_EQ(bench.request(get.coi).back(), at(milliseconds(10), RequestState::completed));
  const auto got = bench.of<SettingsEvent>();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].second.coi, get.coi);
  const auto& s = bench.session().core().settings();
  ASSERT_EQ(s.size(), 4u);
  for (const auto& v : s) {
    if (v.code == proto::SettingCode::p) {
      EXPECT_EQ(v.value.as_f32(), 2.0f);
    }
    if (v.code == proto::SettingCode::i) {
      EXPECT_EQ(v.value.as_f32(), 0.25f);
    }
    if (v.code == proto::SettingCode::servo_zero) {
      EXPECT_EQ(v.value.as_i32(), 95);
    }
  }
}

TEST(Wr8Session, ATaskRejectedByTheVehicleEndsInError) {
  VirtualBench bench;
  login(bench);
  bench.firmware().arm(test::reject_next("TASK"));
  const auto r = bench.session().drive(100);
  const auto states = bench.request_by(r.coi, milliseconds(100));
  ASSERT_EQ(states.size(), 2u);
  EXPECT_EQ(states[1], at(milliseconds(1), RequestState::error));
  EXPECT_EQ(bench.firmware().state().drive, std::nullopt);
}

TEST(Wr8Session, AnIgnoredTaskTimesOutExactly500MsAfterItWasSent) {
  VirtualBench bench;
  login(bench);
  bench.firmware().arm({.name = "", .when = {}, .action = mocks::Ignore{"TASK", 1, {}}});
  bench.run_until(milliseconds(200));
  const auto r = bench.session().turn(10);
  const auto states = bench.request_by(r.coi, seconds(1));
  ASSERT_EQ(states.size(), 2u);
  EXPECT_EQ(states[1], at(milliseconds(700), RequestState::timed_out));
  // The next task is answered again, under the next COI.
  const auto next = bench.session().task(proto::TaskCode::check);
  EXPECT_EQ(next.coi, static_cast<std::uint8_t>(r.coi + 1));
  bench.run_until(milliseconds(1010));
  EXPECT_EQ(bench.request(next.coi).back(), at(seconds(1), RequestState::completed));
}

TEST(Wr8Session, AWrongAuthStringFailsTheConnectionAndRetriesOnTheBackoff) {
  ClientConfig config;
  config.profile.auth_text = {'W', 'R', 'O', 'N', 'G', '-', 'A', 'U', 'T', 'H'};
  VirtualBench bench({}, config);
  bench.session().connect();
  bench.run_until(seconds(20));
  EXPECT_TRUE(bench.of<LoginEvent>().empty());
  // The vehicle closes 1 s after a wrong string; each close is a failed
  // connection, and the next attempt comes 1 s, 2 s, 4 s, 8 s later.
  const auto failed = bench.of<LoginFailedEvent>();
  ASSERT_GE(failed.size(), 4u);
  EXPECT_EQ(failed[0].first, seconds(1));
  EXPECT_EQ(failed[0].second.reason, "closed before AUTH-REPLY");
  EXPECT_EQ(failed[1].first, seconds(3));   // retried at 2 s
  EXPECT_EQ(failed[2].first, seconds(6));   // retried at 5 s
  EXPECT_EQ(failed[3].first, seconds(11));  // retried at 10 s
  std::vector<Time> attempts;
  for (const auto& [t, e] : bench.of<ConnectionEvent>()) {
    if (e.state == ConnectionState::connecting && e.attempt > 0) attempts.push_back(t);
  }
  ASSERT_GE(attempts.size(), 4u);
  EXPECT_EQ(attempts[0], seconds(2));
  EXPECT_EQ(attempts[1], seconds(5));
  EXPECT_EQ(attempts[2], seconds(10));
  EXPECT_EQ(attempts[3], seconds(19));
  EXPECT_EQ(bench.firmware().state().auth_failures, 5u);  // at 0, 2, 5, 10 and 19 s
}

TEST(Wr8Session, DataGoesStale500MsAfterTheLastPacketWhileTelemetryIsMuted) {
  VirtualBench bench;
  login(bench);
  bench.run_until(milliseconds(250));
  bench.firmware().arm({.name = "", .when = {}, .action = mocks::MuteTelemetry{seconds(1)}});
  bench.run_until(seconds(2));
  // Last DATA at 200 ms; stale at 700 ms; DATA again on the grid at 1300 ms.
  EXPECT_EQ(
      test::stale_flags(bench.of<StaleEvent>()),
      (std::vector<std::pair<Time, bool>>{{milliseconds(700), true}, {milliseconds(1300), false}}));
}

}  // namespace
}  // namespace hil::client::wr8
