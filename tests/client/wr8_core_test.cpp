// The WR8 client core on its own, in exact virtual time: login and its
// timeout, the reconnect backoff, DATA into the live state and the stale
// flag, COI matching and wrap, answer and completion timeouts, the log.

#include "client/wr8/core.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/client/client_test_support.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;

protocol::Bytes packet(const proto::Message& m) {
  return proto::encode(m);
}

using test::events_of;
using test::has;

std::vector<protocol::Bytes> sent(const std::vector<Action>& actions) {
  return test::sent_bytes<SendBytes>(actions);
}

/// A core logged in at 0 ms, its actions and events so far taken.
Wr8ClientCore logged_in(ClientConfig config = {}) {
  Wr8ClientCore core(std::move(config));
  core.connect(Time{0});
  core.on_connected(Time{0});
  core.on_bytes(Time{0}, packet(proto::AuthReply{8, 1, proto::State::stop}));
  core.take_actions();
  core.take_events();
  return core;
}

void feed(Wr8ClientCore& core, Time now, const proto::Message& m) {
  core.on_bytes(now, packet(m));
}

TEST(Wr8ClientCore, ConnectSendsTheProfilesAuthStringAndLogsInOnAuthReply) {
  Wr8ClientCore core;
  core.connect(Time{0});
  EXPECT_TRUE(has(core.take_actions(), OpenConnection{}));
  EXPECT_EQ(core.state(), ConnectionState::connecting);
  core.on_connected(milliseconds(1));
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  const protocol::Bytes expected = {0x01, 'H', 'I', 'L', '-', 'W', 'R', '8', '-', '0', '1'};
  EXPECT_EQ(out[0], expected);
  EXPECT_EQ(core.state(), ConnectionState::authenticating);
  EXPECT_EQ(core.next_wakeup(), milliseconds(2001));  // the AUTH-REPLY deadline

  // Nothing may be sent before login.
  EXPECT_EQ(core.drive(milliseconds(2), 100).refusal, Refusal::not_connected);

  feed(core, milliseconds(5), proto::AuthReply{8, 1, proto::State::stop});
  EXPECT_EQ(core.state(), ConnectionState::connected);
  const auto logins = events_of<LoginEvent>(core.take_events());
  ASSERT_EQ(logins.size(), 1u);
  EXPECT_EQ(logins[0].reply.device_code, 8);
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
}

TEST(Wr8ClientCore, NoAuthReplyWithinTwoSecondsIsAFailedConnectionRetriedWithBackoff) {
  Wr8ClientCore core;
  test::connected_at_zero(core);

  core.on_timer(milliseconds(1999));
  EXPECT_EQ(core.state(), ConnectionState::authenticating);
  core.on_timer(seconds(2));
  auto actions = core.take_actions();
  EXPECT_TRUE(has(actions, CloseConnection{}));
  const auto failed = events_of<LoginFailedEvent>(core.take_events());
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0].reason, "AUTH-REPLY timeout");
  EXPECT_EQ(core.state(), ConnectionState::reconnecting);

  // Attempts 1 s, 2 s, 4 s, 8 s, 8 s after each failure.
  Time t = seconds(2);
  for (const auto delay : {seconds(1), seconds(2), seconds(4), seconds(8), seconds(8)}) {
    EXPECT_EQ(core.next_wakeup(), t + delay);
    core.on_timer(t + delay - milliseconds(1));
    EXPECT_FALSE(has(core.take_actions(), OpenConnection{}));
    t += delay;
    core.on_timer(t);
    EXPECT_TRUE(has(core.take_actions(), OpenConnection{}));
    core.on_connect_failed(t);
    EXPECT_EQ(core.state(), ConnectionState::reconnecting);
  }
}

TEST(Wr8ClientCore, ALoginResetsTheBackoff) {
  Wr8ClientCore core;
  core.connect(Time{0});
  core.on_connect_failed(Time{0});
  EXPECT_EQ(core.next_wakeup(), seconds(1));
  core.on_timer(seconds(1));
  core.on_connected(seconds(1));
  feed(core, seconds(1), proto::AuthReply{});
  core.on_closed(seconds(5));
  EXPECT_EQ(core.next_wakeup(), seconds(6));
}

TEST(Wr8ClientCore, DataFillsTheLiveStateAndStopsBeingFreshAfter500Ms) {
  auto core = logged_in();
  // The vehicle's DATA at rest at 100 ms (docs/mocks/wr8.md).
  const auto data = protocol::parse_hex(
      "06 02 64 00 00 00 11 00 00 00 00 00 01 00 00 00 00 02 00 00 00 00 03 64");
  ASSERT_TRUE(data);
  core.on_bytes(milliseconds(100), *data);
  ASSERT_TRUE(core.live());
  EXPECT_EQ(core.live()->state, proto::State::stop);
  EXPECT_EQ(core.live()->timestamp_ms, 100u);
  EXPECT_EQ(core.live()->odometry_cm, 0.0);
  EXPECT_EQ(core.live()->speed_mps, 0.0);
  EXPECT_EQ(core.live()->wheel_angle_deg, 0.0);
  EXPECT_EQ(core.live()->battery_percent, 100.0);

  feed(core, milliseconds(200),
       proto::Data{proto::State::run,
                   200,
                   {{proto::data_code::odometry, proto::Word::from_i32(-42)},
                    {proto::data_code::speed, proto::Word::from_f32(0.5f)},
                    {proto::data_code::wheel_angle, proto::Word::from_f32(-15.0f)},
                    {proto::data_code::battery, proto::Word::from_u32(97)}},
                   {}});
  EXPECT_EQ(core.live()->state, proto::State::run);
  EXPECT_EQ(core.live()->odometry_cm, -42.0);
  EXPECT_EQ(core.live()->speed_mps, 0.5);
  EXPECT_EQ(core.live()->wheel_angle_deg, -15.0);
  EXPECT_EQ(core.live()->battery_percent, 97.0);
  core.take_events();

  EXPECT_EQ(core.next_wakeup(), milliseconds(700));
  core.on_timer(milliseconds(699));
  EXPECT_FALSE(core.stale());
  core.on_timer(milliseconds(700));
  EXPECT_TRUE(core.stale());
  auto stale = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_TRUE(stale[0].stale);

  feed(core, milliseconds(900), proto::Data{proto::State::stop, 900, {}, {}});
  EXPECT_FALSE(core.stale());
  stale = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_FALSE(stale[0].stale);
}

TEST(Wr8ClientCore, TheStaleTimerStartsAgainWithTheFirstDataAfterALogin) {
  auto core = logged_in();
  feed(core, milliseconds(100), proto::Data{proto::State::stop, 100, {}, {}});
  core.on_closed(milliseconds(200));
  core.on_timer(milliseconds(1200));
  core.on_connected(milliseconds(1200));
  feed(core, milliseconds(1200), proto::AuthReply{});
  core.take_events();
  // DATA of the old connection does not make the new one stale at once.
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
  feed(core, milliseconds(1300), proto::Data{proto::State::stop, 1300, {}, {}});
  EXPECT_EQ(core.next_wakeup(), milliseconds(1800));
}

TEST(Wr8ClientCore, ADriveIsMatchedByCoiThroughStartedAndCompleted) {
  auto core = logged_in();
  const auto r = core.drive(milliseconds(10), 100);
  ASSERT_TRUE(r);
  EXPECT_EQ(r.coi, 0);
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], packet(proto::Task{0, proto::TaskCode::drive, {proto::Word::from_i32(100)}}));

  // An answer for another COI is not this drive's.
  feed(core, milliseconds(20), proto::Response{7, proto::ResponseCode::completed});
  EXPECT_EQ(events_of<IgnoredEvent>(core.take_events()).size(), 1u);
  EXPECT_EQ(core.open_requests(), 1u);

  feed(core, milliseconds(20), proto::Response{0, proto::ResponseCode::started});
  // Completion is now due within 30 s of the start, not the 500 ms answer timeout.
  EXPECT_EQ(core.next_wakeup(), milliseconds(20) + seconds(30));
  feed(core, milliseconds(3350), proto::Response{0, proto::ResponseCode::completed});
  const auto reqs = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(reqs.size(), 2u);
  EXPECT_EQ(reqs[0].state, RequestState::started);
  EXPECT_EQ(reqs[1].state, RequestState::completed);
  EXPECT_EQ(reqs[1].task, proto::TaskCode::drive);
  EXPECT_EQ(core.open_requests(), 0u);
}

TEST(Wr8ClientCore, AnUnansweredTaskTimesOutAt500MsAndItsLateAnswerIsIgnoredAndLogged) {
  auto core = logged_in();
  const auto r = core.turn(milliseconds(100), 15);
  ASSERT_TRUE(r);
  core.take_events();
  EXPECT_EQ(core.next_wakeup(), milliseconds(600));
  core.on_timer(milliseconds(599));
  EXPECT_EQ(core.open_requests(), 1u);
  core.on_timer(milliseconds(600));
  auto reqs = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(reqs.size(), 1u);
  EXPECT_EQ(reqs[0].coi, r.coi);
  EXPECT_EQ(reqs[0].state, RequestState::timed_out);

  feed(core, milliseconds(700), proto::Response{r.coi, proto::ResponseCode::completed});
  EXPECT_TRUE(events_of<RequestEvent>(core.take_events()).empty());
  const auto log = core.log()->entries();
  ASSERT_FALSE(log.empty());
  EXPECT_EQ(log.back().kind, LogKind::note);
  EXPECT_NE(log.back().description.find("ignored (late or unknown COI)"), std::string::npos);
}

TEST(Wr8ClientCore, AStartedTaskWithoutCompletionTimesOutAfterItsKindsLimit) {
  ClientConfig config;
  auto core = logged_in(config);
  const auto r = core.turn(Time{0}, 15);
  feed(core, milliseconds(50), proto::Response{r.coi, proto::ResponseCode::started});
  core.take_events();
  core.on_timer(milliseconds(3049));
  EXPECT_EQ(core.open_requests(), 1u);
  core.on_timer(milliseconds(3050));
  const auto reqs = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(reqs.size(), 1u);
  EXPECT_EQ(reqs[0].state, RequestState::timed_out);
}

TEST(Wr8ClientCore, CoiCountsUpAndWrapsFromFfTo00SkippingOpenOnes) {
  auto core = logged_in();
  const auto held = core.task(Time{0}, proto::TaskCode::blink);  // COI 0 stays open
  feed(core, Time{0}, proto::Response{held.coi, proto::ResponseCode::started});
  for (int i = 1; i < 256; ++i) {
    const auto r = core.task(Time{0}, proto::TaskCode::check);
    ASSERT_EQ(r.coi, i);
    feed(core, Time{0}, proto::Response{r.coi, proto::ResponseCode::completed});
  }
  EXPECT_EQ(core.task(Time{0}, proto::TaskCode::check).coi, 1);  // 0 is still the blink's
}

TEST(Wr8ClientCore, GetSettingsReturnsTheSettingsValues) {
  auto core = logged_in();
  const auto r = core.get_settings(Time{0});
  const std::vector<proto::Setting> values = {
      {proto::SettingCode::p, proto::Word::from_f32(1.5f)},
      {proto::SettingCode::i, proto::Word::from_f32(0.25f)},
      {proto::SettingCode::d, proto::Word::from_f32(0.05f)},
      {proto::SettingCode::servo_zero, proto::Word::from_i32(90)}};
  feed(core, milliseconds(1), proto::Settings{r.coi, values});
  feed(core, milliseconds(1), proto::Response{r.coi, proto::ResponseCode::completed});
  const auto events = core.take_events();
  const auto got = events_of<SettingsEvent>(events);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].settings, values);
  EXPECT_EQ(core.settings(), values);
  ASSERT_EQ(events_of<RequestEvent>(events).back().state, RequestState::completed);

  // A SETTINGS nobody asked for changes nothing.
  feed(core, milliseconds(2), proto::Settings{99, {}});
  EXPECT_EQ(events_of<IgnoredEvent>(core.take_events()).size(), 1u);
  EXPECT_EQ(core.settings(), values);
}

TEST(Wr8ClientCore, ALostConnectionCancelsOpenRequests) {
  auto core = logged_in();
  core.drive(Time{0}, 100);
  core.take_events();
  core.on_closed(milliseconds(10));
  const auto reqs = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(reqs.size(), 1u);
  EXPECT_EQ(reqs[0].state, RequestState::cancelled);
  EXPECT_EQ(core.state(), ConnectionState::reconnecting);
  EXPECT_EQ(core.next_wakeup(), milliseconds(1010));
}

TEST(Wr8ClientCore, TheLogExportsTxAndRxAsHexInTextCsvAndNdjson) {
  auto core = logged_in();
  ASSERT_TRUE(core.drive(milliseconds(10), 100));
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  const std::string task = protocol::to_hex(out[0]);
  const std::string text = core.log()->to_string(client::LogFormat::txt);
  EXPECT_NE(text.find("TX   " + task), std::string::npos) << text;
  EXPECT_NE(text.find("RX   02 08 01 02"), std::string::npos) << text;
  const std::string csv = core.log()->to_string(client::LogFormat::csv);
  EXPECT_EQ(csv.rfind("time_ms,kind,raw,description\r\n", 0), 0u);
  EXPECT_NE(csv.find("10.000,TX,\"" + task + "\""), std::string::npos) << csv;
  const std::string nd = core.log()->to_string(client::LogFormat::ndjson);
  EXPECT_NE(nd.find("\"kind\":\"RX\""), std::string::npos) << nd;
  EXPECT_NE(nd.find("\"raw\":\"02 08 01 02\""), std::string::npos) << nd;
}

TEST(Wr8ClientCore, TheLogNeverShowsTheAuthenticationString) {
  // The string in text and in hex ("HIL-WR8-01" is 48 49 4C 2D 57 52 38 2D 30 31),
  // in every export; what was sent on the wire is the whole string.
  ClientConfig config;
  const std::string secret = "SECRET-042";
  ASSERT_EQ(secret.size(), config.profile.auth_text.size());
  std::copy(secret.begin(), secret.end(), config.profile.auth_text.begin());
  auto core = logged_in(config);
  const std::string hex = "53 45 43 52 45 54 2D 30 34 32";
  for (const std::string& out : {core.log()->to_string(client::LogFormat::txt),
                                 core.log()->to_string(client::LogFormat::csv),
                                 core.log()->to_string(client::LogFormat::ndjson)}) {
    EXPECT_EQ(out.find(secret), std::string::npos) << out;
    EXPECT_EQ(out.find(hex), std::string::npos) << out;
  }
  const auto log = core.log()->entries();
  const auto auth =
      std::find_if(log.begin(), log.end(), [](const LogEntry& e) { return e.kind == LogKind::tx; });
  ASSERT_NE(auth, log.end());
  EXPECT_EQ(auth->raw, "01 ** ** ** ** ** ** ** ** ** **");
  EXPECT_EQ(auth->description, "Auth text=********** (profile string)");
}

}  // namespace
}  // namespace hil::client::wr8
