// The LOGI client core driven directly in virtual time: connection and
// reconnect timing, stream decoding, the dispatcher's timeouts and retries,
// the safety guard and the communication log.

#include "client/logi/core.hpp"

#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "protocol/logi/codec.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::logi {
namespace {

using link::milliseconds;
using link::seconds;
using proto::Direction;
using proto::Mode;

constexpr Time ms(std::int64_t n) {
  return milliseconds(n);
}

protocol::Bytes bytes_of(std::string_view text) {
  return {text.begin(), text.end()};
}

std::string stat_frame(Mode mode = Mode::automatic) {
  proto::Status s;
  s.speed_percent = 50;
  s.mode = mode;
  return proto::encode_text(s);
}

/// A core with a clock: runs its wakeups in order and records what it does.
class Harness {
 public:
  explicit Harness(ClientConfig config = {}) : core(std::move(config)) {}

  LogiClientCore core;
  Time now{0};
  std::vector<std::pair<Time, std::string>> sent;  // frames written, with their time
  std::vector<std::pair<Time, Event>> events;
  int opens = 0;
  std::vector<Time> open_times;
  int closes = 0;

  /// Runs every wakeup up to and including `t`, then sets the clock to `t`.
  void run_until(Time t) {
    for (auto next = core.next_wakeup(); next && *next <= t; next = core.next_wakeup()) {
      now = std::max(now, *next);
      core.on_timer(now);
      drain();
    }
    now = t;
  }
  /// Records what the core did, then hands `r` back.
  SubmitResult then_drain(SubmitResult r) {
    drain();
    return r;
  }
  void drain() {
    for (auto& a : core.take_actions()) {
      if (std::holds_alternative<OpenConnection>(a)) {
        ++opens;
        open_times.push_back(now);
      } else if (auto* s = std::get_if<SendBytes>(&a)) {
        sent.emplace_back(now, s->text);
      } else {
        ++closes;
      }
    }
    for (auto& e : core.take_events())
      events.emplace_back(now, std::move(e));
  }
  /// Runs until `t`; when the latest connection attempt by then started.
  std::optional<Time> last_open_by(Time t) {
    run_until(t);
    if (open_times.empty()) return std::nullopt;
    return open_times.back();
  }
  SubmitResult submit(const proto::Message& command) {
    return then_drain(core.submit(now, command));
  }
  SubmitResult press(Direction direction) { return then_drain(core.press(now, direction)); }
  SubmitResult release() { return then_drain(core.release(now)); }
  SubmitResult emergency_stop() { return then_drain(core.emergency_stop(now)); }
  void connect() {
    core.connect(now);
    drain();
  }
  void connected() {
    core.connect(now);
    core.on_connected(now);
    drain();
  }
  void closed() {
    core.on_closed(now);
    drain();
  }
  void connect_failed() {
    core.on_connect_failed(now);
    drain();
  }
  /// Connected, with mode and speed confirmed and answered.
  void ready(Mode mode = Mode::manual) {
    connected();
    core.submit(now, proto::SetSpeed{50});
    reply("FB:SP:1");
    core.submit(now, proto::SetMode{mode});
    reply("FB:MD:1");
    sent.clear();
    events.clear();
  }
  void feed(std::string_view text) {
    const auto b = bytes_of(text);
    core.on_bytes(now, b);
    drain();
  }
  void reply(std::string_view payload) { feed(proto::frame_text(payload)); }

  std::vector<std::string> frames() const {
    std::vector<std::string> out;
    for (auto& [t, f] : sent)
      out.push_back(f);
    return out;
  }
  template <class E>
  std::vector<std::pair<Time, E>> of() const {
    return test::timed_events_of<E>(events);
  }
  std::vector<CommandEvent> commands(CommandState state) const {
    std::vector<CommandEvent> out;
    for (auto& [t, e] : of<CommandEvent>()) {
      if (e.state == state) out.push_back(e);
    }
    return out;
  }
};

std::string f(std::string_view payload) {
  return proto::frame_text(payload);
}

// ---- network ----

TEST(LogiClientCore, ConnectAndDisconnectOnRequestReportTheirStates) {
  Harness h;
  h.connect();
  EXPECT_EQ(h.opens, 1);
  EXPECT_EQ(h.core.state(), ConnectionState::connecting);
  h.core.on_connected(h.now);
  h.drain();
  EXPECT_EQ(h.core.state(), ConnectionState::connected);
  h.core.disconnect(h.now);
  h.drain();
  EXPECT_EQ(h.closes, 1);
  EXPECT_EQ(h.core.state(), ConnectionState::disconnected);
  h.run_until(seconds(60));
  EXPECT_EQ(h.opens, 1) << "no reconnect after the operator disconnected";
  std::vector<ConnectionState> states;
  for (auto& [t, e] : h.of<ConnectionEvent>())
    states.push_back(e.state);
  EXPECT_EQ(states,
            (std::vector<ConnectionState>{ConnectionState::connecting, ConnectionState::connected,
                                          ConnectionState::disconnected}));
}

TEST(LogiClientCore, ReconnectsAfterADropAt1s2s3sThen3sForever) {
  Harness h;
  h.connected();
  h.now = seconds(10);
  h.closed();
  EXPECT_EQ(h.core.state(), ConnectionState::reconnecting);
  for (Time at : {seconds(11), seconds(13), seconds(16), seconds(19), seconds(22)}) {
    const int before = h.opens;
    h.run_until(at - std::chrono::nanoseconds(1));
    EXPECT_EQ(h.opens, before) << "too early before " << link::format_ms(at);
    h.run_until(at);
    ASSERT_EQ(h.opens, before + 1) << "attempt due at " << link::format_ms(at);
    EXPECT_EQ(h.open_times.back(), at);
    EXPECT_EQ(h.core.state(), ConnectionState::connecting);
    h.connect_failed();
  }
  // A connection over which the car spoke starts the series again at 1 s.
  h.run_until(seconds(25));
  h.core.on_connected(h.now);
  h.feed(stat_frame());
  h.now = seconds(30);
  h.closed();
  EXPECT_EQ(h.last_open_by(seconds(31)), seconds(31));
}

TEST(LogiClientCore, ACarThatHangsUpBeforeSayingAnythingDoesNotRestartTheSeries) {
  Harness h;
  h.connected();
  h.feed(stat_frame());
  h.closed();
  // Each attempt connects and is closed at once, with no frame from the car:
  // the delays still grow 1 s, 2 s, 3 s, 3 s.
  for (Time at : {seconds(1), seconds(3), seconds(6), seconds(9)}) {
    ASSERT_EQ(h.last_open_by(at), at);
    h.core.on_connected(h.now);
    h.closed();
  }
  EXPECT_EQ(h.last_open_by(seconds(12)), seconds(12));
}

TEST(LogiClientCore, AFailedFirstConnectIsRetriedAfter1s) {
  Harness h;
  h.connect();
  h.connect_failed();
  h.run_until(seconds(1));
  EXPECT_EQ(h.open_times, (std::vector<Time>{Time{0}, seconds(1)}));
}

TEST(LogiClientCore, CommandsAreRefusedWhileNotConnected) {
  Harness h;
  EXPECT_EQ(h.core.submit(h.now, proto::SetSpeed{50}).refusal, Refusal::not_connected);
  EXPECT_EQ(h.core.press(h.now, Direction::fwd).refusal, Refusal::not_connected);
  EXPECT_EQ(h.core.emergency_stop(h.now).refusal, Refusal::not_connected);
  h.drain();
  EXPECT_TRUE(h.sent.empty());
  EXPECT_FALSE(h.core.movement_enabled());
}

// ---- protocol ----

TEST(LogiClientCore, StickyAndSplitFramesAllComeOutTyped) {
  Harness h;
  h.connected();
  h.submit(proto::SetSpeed{30});
  // FB and STAT stuck together, then a STAT one byte at a time.
  h.feed(f("FB:SP:1") + stat_frame());
  for (char c : stat_frame(Mode::manual))
    h.feed(std::string(1, c));
  const auto fbs = h.of<FeedbackEvent>();
  ASSERT_EQ(fbs.size(), 1u);
  EXPECT_EQ(fbs[0].second.feedback, (proto::Feedback{proto::Command::sp, true}));
  EXPECT_EQ(fbs[0].second.request, 1u);
  const auto stats = h.of<StatusEvent>();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[1].second.status.mode, Mode::manual);
  EXPECT_EQ(h.core.known_mode(), Mode::manual);
}

TEST(LogiClientCore, AnInvalidFrameIsDroppedAndLoggedWithItsRawText) {
  Harness h;
  h.connected();
  h.submit(proto::SetSpeed{30});
  h.feed("LOGI:FB:SP:1:00#");  // wrong checksum
  EXPECT_TRUE(h.of<FeedbackEvent>().empty());
  ASSERT_EQ(h.of<ParseErrorEvent>().size(), 1u);
  EXPECT_EQ(h.of<ParseErrorEvent>()[0].second.error.kind, protocol::ErrorKind::bad_checksum);
  bool logged = false;
  for (const auto& e : h.core.log()->entries()) {
    if (e.kind == LogKind::parse_error && e.raw == "LOGI:FB:SP:1:00#") logged = true;
  }
  EXPECT_TRUE(logged);
  EXPECT_EQ(h.core.state(), ConnectionState::connected);
  h.reply("FB:SP:1");  // the next good frame still counts
  EXPECT_EQ(h.commands(CommandState::accepted).size(), 1u);
}

// ---- dispatcher ----

TEST(LogiClientCore, OneCommandInFlightTheNextWaitsForItsFeedback) {
  Harness h;
  h.connected();
  const auto sp = h.submit(proto::SetSpeed{50});
  const auto md = h.submit(proto::SetMode{Mode::manual});
  EXPECT_NE(sp.request, md.request);
  EXPECT_EQ(h.frames(), (std::vector<std::string>{"LOGI:SP:050:D7#"}));
  h.now = ms(120);
  h.reply("FB:SP:1");
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{ms(120), "LOGI:MD:MAN:0C#"}));
  h.reply("FB:MD:1");
  const auto accepted = h.commands(CommandState::accepted);
  ASSERT_EQ(accepted.size(), 2u);
  EXPECT_EQ(accepted[0].request, sp.request);
  EXPECT_EQ(accepted[1].request, md.request);
}

TEST(LogiClientCore, UnansweredSpIsSentThreeTimes800msApartThenUncertain) {
  Harness h;
  h.connected();
  const auto sp = h.submit(proto::SetSpeed{80});
  h.submit(proto::SetStation{2});
  h.run_until(ms(2399));
  EXPECT_TRUE(h.commands(CommandState::uncertain).empty());
  h.run_until(ms(2400));
  ASSERT_EQ(h.sent.size(), 4u);
  EXPECT_EQ(h.sent[0], (std::pair<Time, std::string>{ms(0), "LOGI:SP:080:DA#"}));
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{ms(800), "LOGI:SP:080:DA#"}));
  EXPECT_EQ(h.sent[2], (std::pair<Time, std::string>{ms(1600), "LOGI:SP:080:DA#"}));
  EXPECT_EQ(h.sent[3], (std::pair<Time, std::string>{ms(2400), "LOGI:GS:002:CB#"}));
  const auto unc = h.commands(CommandState::uncertain);
  ASSERT_EQ(unc.size(), 1u);
  EXPECT_EQ(unc[0].request, sp.request);
  EXPECT_EQ(unc[0].attempt, 3);
  EXPECT_FALSE(unc[0].resend_on_confirm);
}

TEST(LogiClientCore, MdAndMvStopAreRetriedToo) {
  for (proto::Message m : {proto::Message{proto::SetMode{Mode::automatic}},
                           proto::Message{proto::Move{Direction::stop}}}) {
    Harness h;
    h.connected();
    h.submit(m);
    h.run_until(ms(1600));
    h.reply(std::holds_alternative<proto::SetMode>(m) ? "FB:MD:1" : "FB:MV:1");
    EXPECT_EQ(h.sent.size(), 3u);
    ASSERT_EQ(h.commands(CommandState::accepted).size(), 1u);
    EXPECT_EQ(h.commands(CommandState::accepted)[0].attempt, 3);
  }
}

TEST(LogiClientCore, TimedOutRunAndGsAreResentOnlyWhenTheOperatorConfirms) {
  Harness h;
  h.ready(Mode::automatic);
  const auto gs = h.submit(proto::SetStation{2});
  h.run_until(ms(800));
  auto unc = h.commands(CommandState::uncertain);
  ASSERT_EQ(unc.size(), 1u);
  EXPECT_EQ(unc[0].request, gs.request);
  EXPECT_TRUE(unc[0].resend_on_confirm);
  h.run_until(seconds(10));
  EXPECT_EQ(h.sent.size(), 1u) << "no automatic retry";
  EXPECT_EQ(h.core.confirm_resend(h.now, 999).refusal, Refusal::unknown_request);
  const auto again = h.core.confirm_resend(h.now, gs.request);
  h.drain();
  EXPECT_EQ(again.request, gs.request);
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{seconds(10), "LOGI:GS:002:CB#"}));
  h.reply("FB:GS:1");
  ASSERT_EQ(h.commands(CommandState::accepted).size(), 1u);
  EXPECT_EQ(h.commands(CommandState::accepted)[0].request, gs.request);

  const auto run = h.submit(proto::SetRun{true});
  h.run_until(seconds(10) + ms(800));
  unc = h.commands(CommandState::uncertain);
  ASSERT_EQ(unc.size(), 2u);
  EXPECT_EQ(unc[1].request, run.request);
  EXPECT_TRUE(unc[1].resend_on_confirm);
  EXPECT_EQ(h.sent.size(), 3u);
}

TEST(LogiClientCore, AMoveOtherThanStopIsNotRetriedButFollowedByMvStopAtItsTimeout) {
  Harness h;
  h.ready();
  const auto mv = h.press(Direction::fwd);
  h.submit(proto::SetSpeed{30});  // queued behind the move
  h.run_until(ms(799));
  EXPECT_EQ(h.frames(), (std::vector<std::string>{"LOGI:MV:FWD:23#"}));
  h.run_until(ms(800));
  // The move is uncertain and not resent; MV:STOP goes out at once, ahead
  // of the queued SP, since the car may have taken the move.
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{ms(800), "LOGI:MV:STOP:88#"}));
  const auto unc = h.commands(CommandState::uncertain);
  ASSERT_EQ(unc.size(), 1u);
  EXPECT_EQ(unc[0].request, mv.request);
  EXPECT_FALSE(unc[0].resend_on_confirm);
  const auto sent = h.commands(CommandState::sent);
  ASSERT_EQ(sent.size(), 2u);
  EXPECT_NE(sent[1].request, mv.request) << "the stop is a request of its own";
  EXPECT_EQ(h.core.held(), Direction::fwd) << "the operator still holds the button";
  h.now = ms(850);
  h.reply("FB:MV:1");
  EXPECT_EQ(h.sent.back(), (std::pair<Time, std::string>{ms(850), "LOGI:SP:030:D5#"}));
  h.reply("FB:SP:1");
  h.run_until(seconds(5));
  EXPECT_EQ(h.sent.size(), 3u) << "nothing more: the move is never written again";
}

TEST(LogiClientCore, TheFailSafeStopIsRetriedLikeAnyMvStopAndARefusalSwitchesNoMode) {
  Harness h;
  h.ready();
  h.press(Direction::cw);
  h.run_until(ms(2400));
  EXPECT_EQ(h.frames(), (std::vector<std::string>{"LOGI:MV:CW:DC#", "LOGI:MV:STOP:88#",
                                                  "LOGI:MV:STOP:88#", "LOGI:MV:STOP:88#"}));
  EXPECT_EQ(h.sent[3].first, ms(2400));
  h.reply("FB:MV:0");
  EXPECT_TRUE(h.of<NoticeEvent>().empty()) << "no switch to MAN for a stop";
  ASSERT_EQ(h.commands(CommandState::rejected).size(), 1u);
  EXPECT_EQ(h.commands(CommandState::rejected)[0].attempt, 3);
  EXPECT_EQ(h.sent.size(), 4u);
}

TEST(LogiClientCore, TimedOutStopsRunsAndSettingsAreNotFollowedByMvStop) {
  Harness h;
  h.ready(Mode::automatic);
  h.submit(proto::SetStation{1});
  h.run_until(ms(800));
  h.submit(proto::SetRun{true});
  h.run_until(ms(1600));
  h.submit(proto::SetRun{false});
  h.run_until(ms(2400));
  EXPECT_EQ(h.frames(),
            (std::vector<std::string>{"LOGI:GS:001:CA#", "LOGI:ST:RUN:3B#", "LOGI:ST:STOP:8C#"}));
  EXPECT_EQ(h.commands(CommandState::uncertain).size(), 3u);
}

// ---- safety guard ----

TEST(LogiClientCore, ReleasingAHeldDirectionSendsStop) {
  Harness h;
  h.ready();
  h.press(Direction::ccw);
  h.reply("FB:MV:1");
  EXPECT_EQ(h.core.held(), Direction::ccw);
  h.now = ms(700);
  h.release();
  EXPECT_FALSE(h.core.held());
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{ms(700), "LOGI:MV:STOP:88#"}));
  EXPECT_EQ(h.core.release(h.now).refusal, Refusal::not_held);
}

TEST(LogiClientCore, StaleRisesOnlyMoreThan2sAfterTheLastStatAndAFreshStatClearsIt) {
  Harness h;
  h.connected();
  h.now = ms(1000);
  h.feed(stat_frame());
  EXPECT_EQ(h.core.next_wakeup(), ms(3000) + LogiClientCore::kTick);
  h.run_until(ms(3000));
  EXPECT_FALSE(h.core.stale()) << "exactly 2 s without a STAT is not more than 2 s";
  h.core.on_timer(ms(3000));  // a timer firing exactly at 2 s raises nothing either
  h.drain();
  EXPECT_FALSE(h.core.stale());
  h.run_until(ms(3000) + LogiClientCore::kTick);
  EXPECT_TRUE(h.core.stale());
  h.run_until(ms(3500));
  h.feed(stat_frame());
  EXPECT_FALSE(h.core.stale());
  EXPECT_EQ(test::stale_flags(h.of<StaleEvent>()),
            (std::vector<std::pair<Time, bool>>{{ms(3000) + LogiClientCore::kTick, true},
                                                {ms(3500), false}}));
}

TEST(LogiClientCore, StaleCountsFromTheConnectWhenNoStatCame) {
  Harness h;
  h.now = ms(250);
  h.connected();
  h.run_until(ms(2250));
  EXPECT_FALSE(h.core.stale());
  h.run_until(ms(2250) + LogiClientCore::kTick);
  EXPECT_TRUE(h.core.stale());
}

TEST(LogiClientCore, OnlyAStatClearsTheStaleWarningNotFeedback) {
  Harness h;
  h.ready();
  h.run_until(ms(2000) + LogiClientCore::kTick);
  ASSERT_TRUE(h.core.stale());
  h.now = ms(2100);
  h.submit(proto::SetSpeed{40});
  h.reply("FB:SP:1");  // a valid frame, but not telemetry
  EXPECT_TRUE(h.core.stale());
  h.run_until(ms(4200));
  EXPECT_TRUE(h.core.stale()) << "an FB neither clears the warning nor restarts its clock";
  EXPECT_EQ(h.of<StaleEvent>().size(), 1u);
  h.now = ms(4300);
  h.feed(stat_frame());
  EXPECT_FALSE(h.core.stale());
  // The clock restarts at that STAT: stale again only after 6300 ms.
  h.run_until(ms(6300));
  EXPECT_FALSE(h.core.stale());
  h.run_until(ms(6300) + LogiClientCore::kTick);
  EXPECT_TRUE(h.core.stale());
}

TEST(LogiClientCore, EmergencyStopInAutoWritesStopsAheadOfTheQueue) {
  Harness h;
  h.ready(Mode::automatic);
  h.feed(stat_frame(Mode::automatic));
  h.submit(proto::SetStation{1});  // in flight, unanswered
  h.submit(proto::SetSpeed{80});   // queued, kept
  h.submit(proto::SetRun{true});   // queued movement, cancelled
  h.now = ms(100);
  const auto stop = h.emergency_stop();
  ASSERT_TRUE(stop);
  ASSERT_EQ(h.sent.size(), 3u);
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{ms(100), "LOGI:MV:STOP:88#"}));
  EXPECT_EQ(h.sent[2], (std::pair<Time, std::string>{ms(100), "LOGI:ST:STOP:8C#"}));
  ASSERT_EQ(h.commands(CommandState::cancelled).size(), 1u);
  EXPECT_TRUE(
      std::holds_alternative<proto::SetRun>(h.commands(CommandState::cancelled)[0].command));
  // The car answers in order; the queued SP goes once everything is answered.
  h.reply("FB:GS:1");
  h.reply("FB:MV:0");  // MV in AUTO is refused: no switch to MAN for a stop
  EXPECT_TRUE(h.of<NoticeEvent>().empty());
  EXPECT_EQ(h.sent.size(), 3u);
  h.reply("FB:ST:1");
  ASSERT_EQ(h.sent.size(), 4u);
  EXPECT_EQ(h.sent[3].second, "LOGI:SP:080:DA#");
}

TEST(LogiClientCore, EmergencyStStopIsResentEvery800msUntilTheCarAnswers) {
  Harness h;
  h.ready(Mode::automatic);
  h.now = ms(100);
  const auto stop = h.emergency_stop();
  h.now = ms(105);
  h.reply("FB:MV:0");  // AUTO refuses MV:STOP; the ST:STOP stays unanswered
  h.run_until(ms(4100));
  std::vector<std::pair<Time, std::string>> st;
  for (const auto& [t, frame] : h.sent) {
    if (frame == "LOGI:ST:STOP:8C#") st.emplace_back(t, frame);
  }
  ASSERT_EQ(st.size(), 6u) << "sent at 100 ms and every 800 ms after, no limit";
  for (std::size_t i = 0; i < st.size(); ++i) {
    EXPECT_EQ(st[i].first, ms(100) + ms(800) * static_cast<int>(i));
  }
  EXPECT_TRUE(h.commands(CommandState::uncertain).empty()) << "an emergency stop is never given up";
  h.now = ms(4200);
  h.reply("FB:ST:1");
  const auto accepted = h.commands(CommandState::accepted);
  ASSERT_EQ(accepted.size(), 1u);
  EXPECT_EQ(accepted[0].request, stop.request + 1) << "the ST:STOP's own request";
  EXPECT_EQ(accepted[0].attempt, 6);
  h.run_until(seconds(10));
  EXPECT_EQ(h.sent.size(), 7u) << "answered: no more resends";
}

TEST(LogiClientCore, EmergencyStStopResendsEndWithARefusalTheLinkOrANewerEmergencyStop) {
  Harness h;
  h.ready(Mode::automatic);
  h.emergency_stop();
  h.run_until(ms(800));
  ASSERT_EQ(h.sent.size(), 4u) << "MV:STOP and ST:STOP, then both again at 800 ms";
  // A second emergency stop takes over: the first one's ST:STOP is cancelled.
  h.now = ms(1000);
  h.emergency_stop();
  auto cancelled = h.commands(CommandState::cancelled);
  ASSERT_EQ(cancelled.size(), 1u);
  EXPECT_EQ(cancelled[0].command, proto::Message{proto::SetRun{false}});
  h.reply("FB:MV:0");
  h.reply("FB:MV:0");
  h.reply("FB:ST:0");  // the car refuses the stop: answered, so no more resends
  ASSERT_EQ(h.commands(CommandState::rejected).size(), 3u);
  EXPECT_EQ(h.commands(CommandState::rejected)[2].command, proto::Message{proto::SetRun{false}});
  const std::size_t sent = h.sent.size();
  h.run_until(seconds(10));
  EXPECT_EQ(h.sent.size(), sent);

  Harness lost;
  lost.ready(Mode::automatic);
  lost.emergency_stop();
  lost.run_until(ms(1600));
  lost.closed();
  EXPECT_EQ(lost.commands(CommandState::cancelled).size(), 2u) << "MV:STOP and ST:STOP";
  EXPECT_EQ(lost.core.in_flight(), 0u);
}

TEST(LogiClientCore, EmergencyStopInManSendsOnlyMvStopAndReleasesTheHeldDirection) {
  Harness h;
  h.ready(Mode::manual);
  h.press(Direction::fwd);
  h.reply("FB:MV:1");
  h.emergency_stop();
  EXPECT_EQ(h.frames(), (std::vector<std::string>{"LOGI:MV:FWD:23#", "LOGI:MV:STOP:88#"}));
  EXPECT_FALSE(h.core.held());
}

TEST(LogiClientCore, FbMv0SwitchesToManAndRetriesTheMoveOnce) {
  Harness h;
  h.ready(Mode::manual);
  const auto mv = h.press(Direction::left);
  h.reply("FB:MV:0");
  ASSERT_EQ(h.of<NoticeEvent>().size(), 1u);
  EXPECT_EQ(h.of<NoticeEvent>()[0].second.text, "Not in manual mode, switching to MAN");
  h.reply("FB:MD:1");
  h.reply("FB:MV:0");
  EXPECT_EQ(h.frames(),
            (std::vector<std::string>{"LOGI:MV:LEFT:6D#", "LOGI:MD:MAN:0C#", "LOGI:MV:LEFT:6D#"}));
  EXPECT_EQ(h.of<NoticeEvent>().size(), 1u) << "only one switch per move";
  ASSERT_EQ(h.commands(CommandState::rejected).size(), 1u);
  EXPECT_EQ(h.commands(CommandState::rejected)[0].request, mv.request);
}

TEST(LogiClientCore, ADropEntersTheSafeStateAndMovementNeedsMdAndSpAgain) {
  Harness h;
  h.ready(Mode::manual);
  EXPECT_TRUE(h.core.movement_enabled());
  h.press(Direction::fwd);
  h.submit(proto::SetSpeed{60});
  h.closed();
  EXPECT_FALSE(h.core.held());
  EXPECT_EQ(h.core.queued(), 0u);
  EXPECT_EQ(h.core.in_flight(), 0u);
  EXPECT_EQ(h.commands(CommandState::cancelled).size(), 2u);
  EXPECT_FALSE(h.core.movement_enabled());
  ASSERT_FALSE(h.of<MovementEvent>().empty());
  EXPECT_FALSE(h.of<MovementEvent>().back().second.enabled);

  h.run_until(seconds(1));
  h.core.on_connected(h.now);
  h.drain();
  EXPECT_EQ(h.core.press(h.now, Direction::fwd).refusal, Refusal::mode_speed_unconfirmed);
  EXPECT_EQ(h.core.submit(h.now, proto::SetRun{true}).refusal, Refusal::mode_speed_unconfirmed);
  h.core.submit(h.now, proto::SetMode{Mode::manual});
  EXPECT_EQ(h.core.press(h.now, Direction::fwd).refusal, Refusal::mode_speed_unconfirmed);
  h.core.submit(h.now, proto::SetSpeed{40});
  EXPECT_TRUE(h.core.press(h.now, Direction::fwd));
  EXPECT_TRUE(h.core.movement_enabled());
  h.drain();
  EXPECT_TRUE(h.of<MovementEvent>().back().second.enabled);
}

TEST(LogiClientCore, KeepaliveRepeatsTheHeldMoveEvery300ms) {
  ClientConfig config;
  config.keepalive = true;
  Harness h(config);
  h.ready();
  h.press(Direction::rf);
  h.reply("FB:MV:1");
  h.run_until(ms(299));
  EXPECT_EQ(h.sent.size(), 1u);
  h.run_until(ms(300));
  h.reply("FB:MV:1");
  h.run_until(ms(600));
  h.reply("FB:MV:1");
  h.now = ms(700);
  h.release();
  h.reply("FB:MV:1");
  h.run_until(seconds(2));
  ASSERT_EQ(h.sent.size(), 4u);
  EXPECT_EQ(h.sent[1], (std::pair<Time, std::string>{ms(300), "LOGI:MV:RF:DA#"}));
  EXPECT_EQ(h.sent[2], (std::pair<Time, std::string>{ms(600), "LOGI:MV:RF:DA#"}));
  EXPECT_EQ(h.sent[3], (std::pair<Time, std::string>{ms(700), "LOGI:MV:STOP:88#"}));
}

TEST(LogiClientCore, WithoutKeepaliveAHeldMoveIsSentOnce) {
  Harness h;
  h.ready();
  h.press(Direction::rf);
  h.reply("FB:MV:1");
  h.run_until(seconds(3));
  EXPECT_EQ(h.sent.size(), 1u);
}

// ---- communication log ----

TEST(LogiCommLog, RecordsTxRxAndErrorsAndExportsThem) {
  Harness h;
  h.connected();
  h.submit(proto::SetSpeed{50});
  h.now = ms(5);
  h.feed(f("FB:SP:1") + "xx");
  std::vector<LogKind> kinds;
  for (const auto& e : h.core.log()->entries()) {
    if (e.kind != LogKind::note) kinds.push_back(e.kind);
  }
  EXPECT_EQ(kinds, (std::vector<LogKind>{LogKind::tx, LogKind::rx}))
      << "the trailing bytes stay in the decoder until a frame or the end";
  const auto& log = *h.core.log();
  const std::string txt = log.to_string(client::LogFormat::txt);
  EXPECT_NE(txt.find("TX   LOGI:SP:050:D7#  SetSpeed percent=50"), std::string::npos) << txt;
  EXPECT_NE(txt.find("RX   LOGI:FB:SP:1:"), std::string::npos) << txt;
  const std::string csv = log.to_string(client::LogFormat::csv);
  EXPECT_EQ(csv.rfind("time_ms,kind,raw,description\r\n", 0), 0u);
  EXPECT_NE(csv.find("5.000,RX,\"LOGI:FB:SP:1:"), std::string::npos) << csv;
  const std::string nd = log.to_string(client::LogFormat::ndjson);
  EXPECT_NE(nd.find(R"("kind":"TX")"), std::string::npos) << nd;
  EXPECT_NE(nd.find(R"("raw":"LOGI:SP:050:D7#")"), std::string::npos) << nd;
}

TEST(LogiCommLog, CsvQuotesFieldsAndJsonEscapesOddBytes) {
  CommLog log;
  log.add({ms(1), LogKind::parse_error, std::string("a\"b,\x01", 5), "garbage"});
  EXPECT_NE(log.to_string(client::LogFormat::csv).find("\"a\"\"b,\\x01\""), std::string::npos)
      << log.to_string(client::LogFormat::csv);
  EXPECT_NE(log.to_string(client::LogFormat::ndjson).find(R"("raw":"a\"b,\\x01")"),
            std::string::npos)
      << log.to_string(client::LogFormat::ndjson);
}

TEST(LogiCommLog, AReaderThreadSeesEveryEntryWhileTheWriterAppends) {
  CommLog log;
  constexpr int kEntries = 20'000;
  std::thread writer([&] {
    for (int i = 0; i < kEntries; ++i)
      log.add({ms(i), LogKind::rx, "LOGI:x", "x"});
  });
  std::uint64_t seen = 0;
  while (seen < kEntries)
    seen += log.since(seen).size();
  writer.join();
  EXPECT_EQ(seen, static_cast<std::uint64_t>(kEntries));
  EXPECT_EQ(log.total(), static_cast<std::uint64_t>(kEntries));
}

}  // namespace
}  // namespace hil::client::logi
