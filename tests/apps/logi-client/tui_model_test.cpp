// The logi-client terminal UI's model against a mocked session, in virtual
// time with exact expectations: every control, hold/release detection, the
// emergency stop, the stale banner and the status panel.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "apps/logi-client/tui_model.hpp"

namespace hil::apps::logi_client {
namespace {

using link::milliseconds;
using logi::CommandState;
using logi::ConnectionState;
using logi::Refusal;
using logi::SubmitResult;
using proto::Direction;
using proto::Mode;
using ::testing::_;
using ::testing::HasSubstr;
using ::testing::InSequence;
using ::testing::NiceMock;
using ::testing::Return;

class MockSession : public SessionControl {
 public:
  MockSession() {
    ON_CALL(*this, submit(_)).WillByDefault(Return(SubmitResult{1, Refusal::none}));
    ON_CALL(*this, press(_)).WillByDefault(Return(SubmitResult{1, Refusal::none}));
    ON_CALL(*this, release()).WillByDefault(Return(SubmitResult{1, Refusal::none}));
    ON_CALL(*this, emergency_stop()).WillByDefault(Return(SubmitResult{1, Refusal::none}));
    ON_CALL(*this, confirm_resend(_)).WillByDefault(Return(SubmitResult{1, Refusal::none}));
    ON_CALL(*this, save_log(_)).WillByDefault(Return(std::string("log saved")));
  }
  MOCK_METHOD(void, connect, (const std::string& host, std::uint16_t port), (override));
  MOCK_METHOD(void, disconnect, (), (override));
  MOCK_METHOD(SubmitResult, submit, (const proto::Message& command), (override));
  MOCK_METHOD(SubmitResult, press, (Direction direction), (override));
  MOCK_METHOD(SubmitResult, release, (), (override));
  MOCK_METHOD(SubmitResult, emergency_stop, (), (override));
  MOCK_METHOD(SubmitResult, confirm_resend, (logi::RequestId request), (override));
  MOCK_METHOD(bool, busy, (), (const, override));
  MOCK_METHOD(std::string, save_log, (LogFormat format), (override));
};

Time ms(long n) {
  return milliseconds(n);
}

class TuiModelTest : public ::testing::Test {
 protected:
  TuiModelTest() : model(session, config()) {}
  static TuiModelConfig config() {
    TuiModelConfig c;
    c.connect_at_start = false;
    return c;
  }
  void connected(Time at = ms(0)) {
    model.on_event(at, logi::ConnectionEvent{ConnectionState::connected, 0});
  }
  /// The key held is released at `at` ms and not a millisecond before;
  /// with `held`, the model shows that direction held until then and
  /// nothing after.
  void expect_released_at(long at, std::optional<Direction> held = std::nullopt) {
    EXPECT_CALL(session, release()).Times(0);
    model.on_time(ms(at - 1));
    if (held) EXPECT_EQ(model.held(), *held);
    ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
    EXPECT_CALL(session, release()).Times(1);
    model.on_time(ms(at));
    if (held) EXPECT_FALSE(model.held());
  }
  void keys(Time at, const std::string& text) {
    for (const char c : text)
      model.on_key(at, c);
  }
  std::string screen(Time at = ms(0)) const {
    const Render r = model.render(at, 20);
    std::string s = r.header.text + "\n";
    if (r.stale) s += *r.stale + "\n";
    for (const auto* p : {&r.status, &r.controls, &r.log}) {
      s += "[" + p->title + "]\n";
      for (const auto& l : p->lines)
        s += l.text + "\n";
    }
    s += r.message.text + "\n";
    if (r.edit) s += *r.edit + "\n";
    return s;
  }

  NiceMock<MockSession> session;
  TuiModel model;
};

// ---- hold / release ----

TEST_F(TuiModelTest, AHeldKeyIsReleasedExactly200MsAfterItsLastRepeat) {
  connected();
  EXPECT_CALL(session, press(Direction::fwd)).Times(1);
  model.on_key(ms(0), 'w');
  // The terminal's auto-repeat: first repeat at 500 ms, then every 40 ms up to 1500 ms.
  for (long t = 500; t <= 1500; t += 40) {
    model.on_time(ms(t));
    model.on_key(ms(t), 'w');
  }
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  EXPECT_EQ(model.next_wakeup(), ms(1700));

  ASSERT_NO_FATAL_FAILURE(expect_released_at(1700, Direction::fwd));
  EXPECT_EQ(model.next_wakeup(), std::nullopt);
}

TEST_F(TuiModelTest, AShortAutoRepeatDelayIsFollowedJustAsWell) {
  connected();
  model.on_key(ms(0), 'd');
  // First repeat at 250 ms (the shortest usual delay), then every 30 ms up to 1000 ms.
  for (long t = 250; t <= 1000; t += 30)
    model.on_key(ms(t), 'd');
  EXPECT_EQ(model.next_wakeup(), ms(1200));
  ASSERT_NO_FATAL_FAILURE(expect_released_at(1200));
}

TEST_F(TuiModelTest, ASinglePressWithoutRepeatIsReleasedAtExactly700Ms) {
  connected();
  EXPECT_CALL(session, press(Direction::lf)).Times(1);
  model.on_key(ms(0), 'q');
  EXPECT_EQ(model.next_wakeup(), ms(700));
  ASSERT_NO_FATAL_FAILURE(expect_released_at(700, Direction::lf));
}

TEST_F(TuiModelTest, TheWindowsComeFromTheConfiguration) {
  TuiModelConfig c = config();
  c.first_repeat_window = ms(400);
  c.repeat_window = ms(100);
  NiceMock<MockSession> other;
  TuiModel m(other, c);
  m.on_event(ms(0), logi::ConnectionEvent{ConnectionState::connected, 0});
  m.on_key(ms(0), 'w');
  EXPECT_EQ(m.next_wakeup(), ms(400));
  m.on_key(ms(300), 'w');
  EXPECT_EQ(m.next_wakeup(), ms(400));
  EXPECT_CALL(other, release()).Times(1);
  m.on_time(ms(400));
}

TEST_F(TuiModelTest, AnotherDirectionSwitchesAtOnceWithoutAStopInBetween) {
  connected();
  {
    InSequence order;
    EXPECT_CALL(session, press(Direction::fwd));
    EXPECT_CALL(session, press(Direction::right));
    EXPECT_CALL(session, release());
  }
  model.on_key(ms(0), 'w');
  model.on_key(ms(520), 'w');
  model.on_key(ms(560), key::kRight);
  EXPECT_EQ(model.held(), Direction::right);
  // The new key starts with the long window again.
  EXPECT_EQ(model.next_wakeup(), ms(1260));
  model.on_time(ms(1260));
}

TEST_F(TuiModelTest, TheStopKeyReleasesAtOnceAndSendsMvStopWhenNothingIsHeld) {
  connected();
  EXPECT_CALL(session, press(Direction::cw));
  EXPECT_CALL(session, release()).Times(1);
  model.on_key(ms(0), ']');
  model.on_key(ms(100), 's');
  EXPECT_FALSE(model.held());
  EXPECT_EQ(model.next_wakeup(), std::nullopt);
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  EXPECT_CALL(session, submit(proto::Message{proto::Move{Direction::stop}}));
  model.on_key(ms(200), 's');
}

TEST_F(TuiModelTest, EveryDirectionKeySendsItsMove) {
  connected();
  const std::vector<std::pair<int, Direction>> keys = {
      {'w', Direction::fwd},        {'x', Direction::bwd},      {'a', Direction::left},
      {'d', Direction::right},      {'q', Direction::lf},       {'e', Direction::rf},
      {'z', Direction::lb},         {'c', Direction::rb},       {']', Direction::cw},
      {'[', Direction::ccw},        {key::kUp, Direction::fwd}, {key::kDown, Direction::bwd},
      {key::kLeft, Direction::left}};
  long t = 0;
  for (const auto& [code, direction] : keys) {
    EXPECT_CALL(session, press(direction)).Times(1);
    model.on_key(ms(t), code);
    model.on_key(ms(t + 1), 's');
    ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session)) << code;
    t += 10;
  }
}

TEST_F(TuiModelTest, LatchedModeHoldsUntilTheSameKeyOrStop) {
  connected();
  model.on_key(ms(0), 'l');
  EXPECT_TRUE(model.latched());
  EXPECT_CALL(session, press(Direction::bwd));
  model.on_key(ms(0), 'x');
  EXPECT_EQ(model.next_wakeup(), std::nullopt);
  EXPECT_CALL(session, release()).Times(0);
  model.on_time(ms(60'000));
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  EXPECT_CALL(session, release()).Times(1);
  model.on_key(ms(60'001), 'x');
  EXPECT_FALSE(model.held());
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));

  EXPECT_CALL(session, press(Direction::left));
  EXPECT_CALL(session, release()).Times(1);
  model.on_key(ms(70'000), 'a');
  model.on_key(ms(75'000), 's');
}

TEST_F(TuiModelTest, ARefusedPressHoldsNothingAndSaysWhy) {
  connected();
  ON_CALL(session, press(_))
      .WillByDefault(Return(SubmitResult{0, Refusal::mode_speed_unconfirmed}));
  EXPECT_CALL(session, release()).Times(0);
  model.on_key(ms(0), 'w');
  EXPECT_FALSE(model.held());
  EXPECT_EQ(model.next_wakeup(), std::nullopt);
  EXPECT_THAT(model.message(), HasSubstr("MV:FWD not sent"));
  EXPECT_THAT(model.message(), HasSubstr("needs MD (m) + SP (Enter)"));
}

// ---- emergency stop ----

TEST_F(TuiModelTest, SpaceAndEscapeAreEmergencyStopsEvenWhileEditingTheHost) {
  connected();
  EXPECT_CALL(session, emergency_stop()).Times(2);
  model.on_key(ms(0), 'h');
  keys(ms(0), "10.1");
  model.on_key(ms(10), ' ');
  EXPECT_EQ(model.host(), "127.0.0.1");  // the edit was abandoned
  EXPECT_EQ(model.render(ms(10), 5).edit, std::nullopt);
  model.on_key(ms(20), 'p');
  model.on_key(ms(30), key::kEscape);
  EXPECT_EQ(model.port(), 9000);
  EXPECT_THAT(model.message(), HasSubstr("EMERGENCY STOP"));
}

TEST_F(TuiModelTest, TheEmergencyStopReleasesAHeldDirection) {
  connected();
  EXPECT_CALL(session, emergency_stop()).Times(1);
  EXPECT_CALL(session, release()).Times(0);  // the emergency stop's MV:STOP covers it
  model.on_key(ms(0), 'w');
  model.on_key(ms(100), ' ');
  EXPECT_FALSE(model.held());
  model.on_time(ms(5000));
}

TEST_F(TuiModelTest, AnEmergencyStopWhileDisconnectedIsSentOnConnect) {
  EXPECT_CALL(session, emergency_stop()).Times(0);
  model.on_key(ms(0), ' ');
  EXPECT_TRUE(model.estop_pending());
  EXPECT_THAT(screen(), HasSubstr("EMERGENCY STOP pending"));
  model.on_event(ms(100), logi::ConnectionEvent{ConnectionState::connecting, 1});
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  EXPECT_CALL(session, emergency_stop()).Times(1);
  connected(ms(200));
  EXPECT_FALSE(model.estop_pending());
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  // Once sent, a later reconnect does not stop the car again.
  EXPECT_CALL(session, emergency_stop()).Times(0);
  model.on_event(ms(300), logi::ConnectionEvent{ConnectionState::reconnecting, 0});
  connected(ms(1300));
}

TEST_F(TuiModelTest, TheCarRefusingTheEmergencyMvStopInAutoLeavesTheStopMessage) {
  connected();
  model.on_key(ms(0), ' ');
  model.on_event(
      ms(5), logi::CommandEvent{1, proto::Move{Direction::stop}, CommandState::rejected, 1, false});
  EXPECT_THAT(model.message(), HasSubstr("EMERGENCY STOP sent"));
  // An ordinary rejected command is reported.
  model.on_event(ms(10),
                 logi::CommandEvent{2, proto::SetStation{2}, CommandState::rejected, 1, false});
  EXPECT_EQ(model.message(), "GS:002 rejected by the car");
}

TEST_F(TuiModelTest, TheControlsSayWhyMovementIsOff) {
  EXPECT_THAT(screen(), HasSubstr("Motion  off: not connected"));
  connected();
  EXPECT_THAT(screen(), HasSubstr("Motion  off: needs MD (m) + SP (Enter) on this connection"));
  model.on_event(ms(0), logi::MovementEvent{true, ""});
  EXPECT_THAT(screen(), HasSubstr("Motion  enabled"));
}

// ---- speed, mode, station, run ----

TEST_F(TuiModelTest, SpeedStepsBy10AndClampsAt0And100) {
  connected();
  EXPECT_EQ(model.speed_percent(), 50);
  keys(ms(0), "------");
  EXPECT_EQ(model.speed_percent(), 0);
  EXPECT_CALL(session, submit(proto::Message{proto::SetSpeed{0}}));
  model.on_key(ms(0), key::kEnter);
  keys(ms(0), "++++++++++++");
  EXPECT_EQ(model.speed_percent(), 100);
  EXPECT_CALL(session, submit(proto::Message{proto::SetSpeed{100}}));
  model.on_key(ms(0), key::kEnter);
}

TEST_F(TuiModelTest, ATypedSpeedIsSentAndClampedAt100) {
  connected();
  EXPECT_CALL(session, submit(proto::Message{proto::SetSpeed{35}}));
  keys(ms(0), "35\n");
  EXPECT_EQ(model.speed_percent(), 35);
  EXPECT_CALL(session, submit(proto::Message{proto::SetSpeed{100}}));
  keys(ms(0), "2500\n");  // at most three digits: 250, clamped
  EXPECT_EQ(model.speed_percent(), 100);
  EXPECT_CALL(session, submit(proto::Message{proto::SetSpeed{8}}));
  model.on_key(ms(0), '8');
  model.on_key(ms(0), '0');
  model.on_key(ms(0), key::kBackspace);
  model.on_key(ms(0), key::kEnter);
}

TEST_F(TuiModelTest, TheModeKeyTogglesManAndAuto) {
  connected();
  {
    InSequence order;
    EXPECT_CALL(session, submit(proto::Message{proto::SetMode{Mode::manual}}));
    EXPECT_CALL(session, submit(proto::Message{proto::SetMode{Mode::automatic}}));
    EXPECT_CALL(session, submit(proto::Message{proto::SetMode{Mode::manual}}));
  }
  model.on_key(ms(0), 'm');
  model.on_key(ms(10), 'm');
  // The car's own report decides what the toggle switches to.
  proto::Status s;
  s.mode = Mode::automatic;
  model.on_event(ms(20), logi::StatusEvent{s});
  model.on_key(ms(30), 'm');
}

TEST_F(TuiModelTest, TheModeShownIsTheLastMdSentWhoeverSentIt) {
  connected();
  const auto sent = [&](Time at, std::uint64_t request, Mode mode) {
    model.on_event(at,
                   logi::CommandEvent{request, proto::SetMode{mode}, CommandState::sent, 1, false});
  };
  // The client's own MD:MAN (after a refused move), then the operator's
  // MD:AUTO queued behind it: AUTO is what the car will be in.
  sent(ms(0), 1, Mode::manual);
  EXPECT_NE(screen().find("Mode    MAN"), std::string::npos) << screen();
  sent(ms(10), 2, Mode::automatic);
  EXPECT_NE(screen().find("Mode    AUTO"), std::string::npos) << screen();
}

TEST_F(TuiModelTest, StationRunAndStopKeysSendTheirCommands) {
  connected();
  {
    InSequence order;
    EXPECT_CALL(session, submit(proto::Message{proto::SetStation{1}}));
    EXPECT_CALL(session, submit(proto::Message{proto::SetStation{2}}));
    EXPECT_CALL(session, submit(proto::Message{proto::SetRun{true}}));
    EXPECT_CALL(session, submit(proto::Message{proto::SetRun{false}}));
  }
  keys(ms(0), "gtgrf");
  EXPECT_EQ(model.station(), 2);
}

TEST_F(TuiModelTest, HostAndPortAreEditedAndUsedByConnect) {
  EXPECT_CALL(session, connect("10.0.0.7", 9001));
  model.on_key(ms(0), 'h');
  for (int i = 0; i < 9; ++i)
    model.on_key(ms(0), key::kBackspace);
  keys(ms(0), "10.0.0.7\n");
  model.on_key(ms(0), 'p');
  for (int i = 0; i < 4; ++i)
    model.on_key(ms(0), key::kBackspace);
  keys(ms(0), "9001\n");
  EXPECT_EQ(model.host(), "10.0.0.7");
  EXPECT_EQ(model.port(), 9001);
  model.on_key(ms(0), 'o');
  EXPECT_THAT(screen(), HasSubstr("LOGI 10.0.0.7:9001"));
}

TEST_F(TuiModelTest, ABadPortIsRefusedAndTheOldOneKept) {
  model.on_key(ms(0), 'p');
  keys(ms(0), "\x7f\x7f\x7f\x7f");
  keys(ms(0), "0\n");
  EXPECT_EQ(model.port(), 9000);
  EXPECT_THAT(model.message(), HasSubstr("1..65535"));
}

TEST_F(TuiModelTest, TheConnectKeyConnectsWhenDisconnectedAndDisconnectsOtherwise) {
  TuiModelConfig c;
  NiceMock<MockSession> other;
  EXPECT_CALL(other, connect("127.0.0.1", 9000)).Times(1);
  TuiModel m(other, c);
  m.start(ms(0));  // connect_at_start
  m.on_event(ms(10), logi::ConnectionEvent{ConnectionState::connected, 0});
  EXPECT_CALL(other, disconnect()).Times(1);
  m.on_key(ms(20), 'o');
}

TEST_F(TuiModelTest, TheLogIsSavedInEachFormat) {
  {
    InSequence order;
    EXPECT_CALL(session, save_log(LogFormat::txt)).WillOnce(Return("saved a.txt"));
    EXPECT_CALL(session, save_log(LogFormat::csv)).WillOnce(Return("saved a.csv"));
    EXPECT_CALL(session, save_log(LogFormat::ndjson)).WillOnce(Return("saved a.ndjson"));
  }
  keys(ms(0), "vt");
  EXPECT_EQ(model.message(), "saved a.txt");
  keys(ms(0), "vcvn");
  EXPECT_EQ(model.message(), "saved a.ndjson");
  keys(ms(0), "vk");  // any other key cancels
  EXPECT_EQ(model.message(), "log not saved");
}

TEST_F(TuiModelTest, AnUncertainRunIsShownAndResentOnConfirm) {
  connected();
  model.on_event(ms(800), logi::CommandEvent{7, proto::SetRun{true}, CommandState::uncertain, 1,
                                             /*resend_on_confirm=*/true});
  EXPECT_THAT(screen(), HasSubstr("UNCERTAIN ST:RUN: y sends it again"));
  EXPECT_CALL(session, confirm_resend(7));
  model.on_key(ms(900), 'y');
  EXPECT_THAT(screen(), ::testing::Not(HasSubstr("UNCERTAIN")));
}

// ---- what the screen shows ----

TEST_F(TuiModelTest, TheStaleBannerComesWithTheStaleEventAndGoesWithAFreshStat) {
  connected();
  EXPECT_EQ(model.render(ms(0), 5).stale, std::nullopt);
  model.on_event(ms(2000), logi::StaleEvent{true});
  const auto banner = model.render(ms(2000), 5).stale;
  ASSERT_TRUE(banner);
  EXPECT_THAT(*banner, HasSubstr("STALE"));
  model.on_event(ms(2500), logi::StaleEvent{false});
  model.on_event(ms(2500), logi::StatusEvent{proto::Status{}});
  EXPECT_EQ(model.render(ms(2500), 5).stale, std::nullopt);
}

TEST_F(TuiModelTest, TheStatusPanelShowsEveryStatField) {
  connected();
  proto::Status s;
  s.speed_percent = 42;
  s.station = 2;
  s.running = true;
  s.mode = Mode::manual;
  s.manual = Direction::ccw;
  s.distance_cm = 137;
  s.track_mask = 0b0110;
  s.deviation = -3;
  s.obstacle = true;
  s.rpm = {11, -12, 13, -14};
  s.extra = {{"BAT", "87"}};
  model.on_event(ms(1000), logi::StatusEvent{s});
  const Render r = model.render(ms(1500), 5);
  std::string text;
  for (const auto& l : r.status.lines)
    text += l.text + "\n";
  for (const char* want : {"SP    42 %", "STA  002", "RUN  1 running", "MODE MAN", "MAN  CCW",
                           "DIS  137 cm", "TRK  0110", "DEV  -3", "OBS  1 BLOCKED",
                           "RPM  LR 11 LF -12 RF 13 RR -14", "BAT  87", "updated 0.5 s ago"})
    EXPECT_THAT(text, HasSubstr(want));
}

TEST_F(TuiModelTest, TheSwitchToManNoticeIsShown) {
  connected();
  model.on_event(ms(0), logi::NoticeEvent{"Not in manual mode, switching to MAN"});
  const Render r = model.render(ms(0), 5);
  EXPECT_EQ(r.message.text, "Not in manual mode, switching to MAN");
  EXPECT_EQ(r.message.style, Style::alert);
}

TEST_F(TuiModelTest, TheLogPanelShowsTheNewestLinesAndScrollsBack) {
  std::vector<logi::LogEntry> entries;
  for (int i = 0; i < 30; ++i)
    entries.push_back(
        {ms(i * 100), logi::LogKind::tx, "LOGI:SP:050:D7#", "SetSpeed #" + std::to_string(i)});
  model.on_log(entries);
  Render r = model.render(ms(0), 5);
  ASSERT_EQ(r.log.lines.size(), 5u);
  EXPECT_THAT(r.log.lines.front().text, HasSubstr("SetSpeed #25"));
  EXPECT_THAT(r.log.lines.back().text, HasSubstr("TX   LOGI:SP:050:D7#  SetSpeed #29"));
  model.on_key(ms(0), key::kPageUp);
  r = model.render(ms(0), 5);
  EXPECT_THAT(r.log.lines.back().text, HasSubstr("SetSpeed #19"));
  // New lines keep a scrolled-back view where it is.
  model.on_log({{ms(5000), logi::LogKind::rx, "LOGI:FB:SP:1:5A#", "Feedback"}});
  EXPECT_THAT(model.render(ms(0), 5).log.lines.back().text, HasSubstr("SetSpeed #19"));
  model.on_key(ms(0), key::kEnd);
  EXPECT_THAT(model.render(ms(0), 5).log.lines.back().text, HasSubstr("RX   LOGI:FB:SP:1:5A#"));
}

TEST_F(TuiModelTest, DisconnectingShowsItAndForgetsTheHeldDirection) {
  connected();
  model.on_key(ms(0), 'w');
  model.on_event(ms(100), logi::ConnectionEvent{ConnectionState::reconnecting, 0});
  EXPECT_FALSE(model.held());
  EXPECT_CALL(session, release()).Times(0);
  model.on_time(ms(700));
  EXPECT_THAT(screen(), HasSubstr("Connection lost, reconnecting"));
}

// ---- quitting ----

TEST_F(TuiModelTest, QuittingStopsTheCarAndClosesOnceTheStopIsAnswered) {
  connected();
  model.on_key(ms(0), 'w');
  ON_CALL(session, busy()).WillByDefault(Return(true));
  EXPECT_CALL(session, emergency_stop()).Times(1);
  EXPECT_CALL(session, disconnect()).Times(0);
  model.on_key(ms(100), key::kCtrlC);
  EXPECT_FALSE(model.done());
  model.on_event(ms(150), logi::CommandEvent{2, proto::Move{}, CommandState::sent, 1, false});
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  ON_CALL(session, busy()).WillByDefault(Return(false));
  EXPECT_CALL(session, disconnect()).Times(1);
  model.on_event(ms(170), logi::CommandEvent{2, proto::Move{}, CommandState::accepted, 1, false});
  EXPECT_TRUE(model.done());
}

TEST_F(TuiModelTest, QuittingClosesAfterTheGraceTimeWithoutAnAnswer) {
  connected();
  ON_CALL(session, busy()).WillByDefault(Return(true));
  EXPECT_CALL(session, emergency_stop()).Times(1);
  model.quit(ms(200));
  EXPECT_EQ(model.next_wakeup(), ms(1200));
  EXPECT_CALL(session, disconnect()).Times(0);
  model.on_time(ms(1199));
  ASSERT_TRUE(::testing::Mock::VerifyAndClearExpectations(&session));
  EXPECT_CALL(session, disconnect()).Times(1);
  model.on_time(ms(1200));
  EXPECT_TRUE(model.done());
}

TEST_F(TuiModelTest, QuittingWhileDisconnectedEndsAtOnce) {
  EXPECT_CALL(session, emergency_stop()).Times(0);
  EXPECT_CALL(session, disconnect()).Times(1);
  model.on_key(ms(0), key::kF10);
  EXPECT_TRUE(model.done());
}

}  // namespace
}  // namespace hil::apps::logi_client
