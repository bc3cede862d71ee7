// The Arduino client core driven directly in virtual time: every timing rule
// (timeout doubling, BAD_CS resends, stale SEQs, health check, reconnect
// backoff, DOWN) checked at the exact nanosecond.

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <string>
#include <vector>

#include "client/arduino/core.hpp"
#include "protocol/arduino/codec.hpp"

namespace hil::client::arduino {
namespace {

namespace proto = protocol::arduino;
using link::milliseconds;
using link::seconds;

std::string text_of(const Bytes& b) {
  return std::string(b.begin(), b.end());
}

/// The client of the README's examples (profile `readme`), whose frames
/// these timing tests spell out; the sketch's frames, the default, are
/// checked in arduino_firmware_dialect_test.cpp.
ClientConfig readme_client() {
  ClientConfig c;
  c.dialect = proto::Dialect::readme;
  return c;
}

/// A core with a clock and everything it handed back, recorded in order.
struct Harness {
  explicit Harness(ClientConfig config = readme_client()) : core(config) {}

  void at(Time t) { now = t; }
  /// Runs the core's timer up to `t`, firing at every wakeup on the way.
  void run_until(Time t) {
    while (auto due = core.next_wakeup()) {
      if (*due > t) break;
      now = *due;
      core.on_timer(now);
      collect();
    }
    now = t;
  }
  void collect() {
    for (auto& a : core.take_actions()) {
      if (auto* s = std::get_if<SendFrame>(&a)) {
        sent.push_back({now, text_of(s->bytes), s->seq});
      } else if (std::holds_alternative<OpenPort>(a)) {
        opens.push_back(now);
      } else {
        closes.push_back(now);
      }
    }
    for (auto& e : core.take_events()) {
      if (auto* d = std::get_if<RequestDone>(&e)) done.push_back({now, d->id, d->result});
      if (auto* l = std::get_if<LinkChanged>(&e)) changes.push_back(*l);
    }
  }
  void open_now() {
    core.open(now);
    core.on_connected(now);
    collect();
  }
  void answer(std::uint8_t seq, proto::Body body) { feed(proto::encode_text({seq, body})); }
  void feed(const std::string& text) {
    core.on_bytes(now, protocol::to_bytes(text));
    collect();
  }
  template <class F>
  RequestId submit(F f) {
    const RequestId id = f(core, now);
    collect();
    return id;
  }

  struct Sent {
    Time at;
    std::string frame;
    std::uint8_t seq;
  };
  struct Done {
    Time at;
    RequestId id;
    Result result;
  };
  ArduinoClientCore core;
  Time now{0};
  std::vector<Sent> sent;
  std::vector<Time> opens, closes;
  std::vector<Done> done;
  std::vector<LinkChanged> changes;
};

ClientConfig no_health_check() {
  ClientConfig c = readme_client();
  c.health_check_interval = Duration::zero();
  return c;
}

TEST(ArduinoClientCore, FramesComeFromTheCodecAndTheSeqWrapsFromFFTo00) {
  Harness h(no_health_check());
  h.open_now();
  for (int i = 0; i < 257; ++i) {
    h.submit([](auto& c, Time t) { return c.ping(t); });
    ASSERT_EQ(h.sent.size(), static_cast<std::size_t>(i + 1));
    h.answer(h.sent.back().seq, proto::Ack{"OK"});
  }
  EXPECT_EQ(h.sent[0].frame, "^00|PING|*10$");
  EXPECT_EQ(h.sent[1].frame, "^01|PING|*11$");  // the protocol document's example
  EXPECT_EQ(h.sent[255].seq, 0xFF);
  EXPECT_EQ(h.sent[256].seq, 0x00);
  EXPECT_EQ(h.sent[256].frame, "^00|PING|*10$");
  ASSERT_EQ(h.done.size(), 257u);
  for (auto& d : h.done)
    EXPECT_EQ(d.result.code, ResultCode::ok);
}

TEST(ArduinoClientCore, AnAckReturnsItsPayloadAndTheTypedHelpersSendTheirCommands) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.set_v(t, 160); });
  h.answer(0x00, proto::Ack{"160"});
  h.submit([](auto& c, Time t) { return c.move_cm(t, 25); });
  h.answer(0x01, proto::Ack{"OK"});
  h.submit([](auto& c, Time t) { return c.rotate_deg(t, -90); });
  h.answer(0x02, proto::Ack{"OK"});
  h.submit([](auto& c, Time t) { return c.stop(t); });
  h.answer(0x03, proto::Ack{"OK"});
  h.submit([](auto& c, Time t) { return c.sonar(t); });
  h.answer(0x04, proto::Ack{"123"});
  h.submit([](auto& c, Time t) { return c.ir(t); });
  h.answer(0x05, proto::Ack{"L=0,0 R=0,0"});
  h.submit([](auto& c, Time t) { return c.status(t); });
  h.answer(0x06, proto::Ack{"IDLE PWM=160"});
  h.submit([](auto& c, Time t) { return c.help(t); });
  h.answer(0x07, proto::Ack{"PING"});
  const std::vector<proto::Body> bodies = {
      proto::SetSpeed{160}, proto::Move{25}, proto::Rotate{-90},     proto::Stop{},
      proto::SonarRead{},   proto::IrRead{}, proto::StatusRequest{}, proto::Help{}};
  ASSERT_EQ(h.sent.size(), bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    EXPECT_EQ(h.sent[i].frame, proto::encode_text({static_cast<std::uint8_t>(i), bodies[i]}));
  }
  EXPECT_EQ(h.sent[1].frame, "^01|M|25*4B$");
  ASSERT_EQ(h.done.size(), 8u);
  EXPECT_EQ(h.done[0].result.info, "160");
  EXPECT_EQ(h.done[4].result.info, "123");
  EXPECT_EQ(h.done[5].result.info, "L=0,0 R=0,0");
  for (auto& d : h.done) {
    EXPECT_EQ(d.result.code, ResultCode::ok);
    EXPECT_EQ(d.result.attempts, 1);
  }
}

TEST(ArduinoClientCore, RawTokensAreFramedAsTheRobotsCliTakesThem) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.raw(t, "V:160"); });
  h.answer(0x00, proto::Ack{"160"});
  h.submit([](auto& c, Time t) { return c.raw(t, "r:-90"); });
  h.answer(0x01, proto::Ack{"OK"});
  h.submit([](auto& c, Time t) { return c.raw(t, "PING"); });
  ASSERT_EQ(h.sent.size(), 3u);
  EXPECT_EQ(h.sent[0].frame, proto::encode_text({0x00, proto::SetSpeed{160}}));
  EXPECT_EQ(h.sent[1].frame, proto::encode_text({0x01, proto::Rotate{-90}}));
  EXPECT_EQ(h.sent[2].frame, proto::encode_text({0x02, proto::Ping{}}));
}

// As the robot's own CLI does: a token hil would not type is the board's
// to judge (the board answers NACK BAD_CMD or BAD_V, or takes "fast" as 0).
TEST(ArduinoClientCore, RawTokensHilDoesNotTypeGoToTheRobotAsGiven) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.raw(t, "JUMP"); });
  h.answer(0x00, proto::Nack{proto::NackCode::bad_cmd});
  h.submit([](auto& c, Time t) { return c.raw(t, "V:fast"); });
  h.answer(0x01, proto::Nack{proto::NackCode::bad_v});
  h.submit([](auto& c, Time t) { return c.raw(t, "history:2"); });
  ASSERT_EQ(h.sent.size(), 3u);
  EXPECT_EQ(h.sent[0].frame, "^00|JUMP|*02$");
  EXPECT_EQ(h.sent[1].frame, "^01|V|fast*57$");
  EXPECT_EQ(h.sent[2].frame, "^02|HISTORY|2*72$");
  ASSERT_EQ(h.done.size(), 2u);
  EXPECT_EQ(h.done[0].result.code, ResultCode::nack);
  EXPECT_EQ(h.done[1].result.code, ResultCode::nack);
}

TEST(ArduinoClientCore, RequestsTheProtocolCannotCarryEndAtOnceWithoutSendingAnything) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.set_v(t, 300); });
  h.submit([](auto& c, Time t) { return c.raw(t, ""); });
  h.submit([](auto& c, Time t) { return c.raw(t, "V:1|2"); });
  h.submit([](auto& c, Time t) { return c.raw(t, "^PING"); });
  h.submit([](auto& c, Time t) { return c.request(t, proto::Ack{"x"}); });
  EXPECT_TRUE(h.sent.empty());
  ASSERT_EQ(h.done.size(), 5u);
  for (auto& d : h.done)
    EXPECT_EQ(d.result.code, ResultCode::invalid_request) << d.result.detail;
  EXPECT_EQ(h.core.next_seq(), 0x00) << "a refused request must not use up a SEQ";
}

TEST(ArduinoClientCore, SilenceRetriesAfter600Then1200Then2400Then4800MsAndTimesOutAt9s) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  h.run_until(seconds(20));
  ASSERT_EQ(h.sent.size(), 4u);
  EXPECT_EQ(h.sent[0].at, milliseconds(0));
  EXPECT_EQ(h.sent[1].at, milliseconds(600));
  EXPECT_EQ(h.sent[2].at, milliseconds(1800));
  EXPECT_EQ(h.sent[3].at, milliseconds(4200));
  for (auto& s : h.sent)
    EXPECT_EQ(s.frame, "^00|PING|*10$") << "a retry keeps its SEQ";
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].at, milliseconds(9000));
  EXPECT_EQ(h.done[0].result.code, ResultCode::timeout);
  EXPECT_EQ(h.done[0].result.attempts, 4);
}

TEST(ArduinoClientCore, MaxRetriesSetsTheNumberOfDoublings) {
  ClientConfig config = no_health_check();
  config.max_retries = 1;
  config.base_timeout = milliseconds(100);
  Harness h(config);
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  h.run_until(seconds(5));
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1].at, milliseconds(100));
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].at, milliseconds(300));
}

TEST(ArduinoClientCore, ACorruptedAnswerIsAParseErrorAndTheRetryWaitsForTheAttemptsTimeout) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  h.at(milliseconds(20));
  h.feed("^00|ACK|OK*00$");  // checksum wrong
  h.run_until(milliseconds(599));
  EXPECT_EQ(h.sent.size(), 1u);
  h.run_until(milliseconds(620));
  h.feed("^00|ACK|OX*4C$");  // a changed byte
  h.run_until(milliseconds(1799));
  EXPECT_EQ(h.sent.size(), 2u);
  h.run_until(milliseconds(1810));
  h.answer(0x00, proto::Ack{"OK"});
  ASSERT_EQ(h.sent.size(), 3u);
  EXPECT_EQ(h.sent[1].at, milliseconds(600));
  EXPECT_EQ(h.sent[2].at, milliseconds(1800));
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].result.code, ResultCode::ok);
  EXPECT_EQ(h.done[0].result.attempts, 3);
  EXPECT_EQ(h.core.parse_errors(), 2u);
}

TEST(ArduinoClientCore, NackBadCsIsResentAtOnceWithTheSameSeqAndDoesNotCountAsARetry) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.move_cm(t, 25); });
  h.at(milliseconds(500));
  h.answer(0x00, proto::Nack{proto::NackCode::bad_cs});
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1].at, milliseconds(500));
  EXPECT_EQ(h.sent[1].frame, h.sent[0].frame);
  // The resend gets the attempt's full timeout again: 500 + 600 ms.
  h.run_until(milliseconds(1099));
  EXPECT_EQ(h.sent.size(), 2u);
  h.run_until(milliseconds(1100));
  ASSERT_EQ(h.sent.size(), 3u);
  EXPECT_EQ(h.sent[2].at, milliseconds(1100));
  h.answer(0x00, proto::Ack{"OK"});
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].result.code, ResultCode::ok);
  EXPECT_EQ(h.done[0].result.attempts, 2);
  EXPECT_EQ(h.done[0].result.bad_cs_resends, 1);
}

TEST(ArduinoClientCore, AFourthNackBadCsInARowIsReturnedAsTheError) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  for (int i = 0; i < 4; ++i)
    h.answer(0x00, proto::Nack{proto::NackCode::bad_cs});
  EXPECT_EQ(h.sent.size(), 4u);
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].result.code, ResultCode::nack);
  EXPECT_EQ(h.done[0].result.nack, (proto::Nack{proto::NackCode::bad_cs}));
  EXPECT_EQ(h.done[0].result.bad_cs_resends, 3);
}

TEST(ArduinoClientCore, OtherNacksAreReturnedWithTheirCodeAtOnce) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.move_cm(t, 25); });
  h.answer(0x00, proto::Nack{std::string("BUSY")});
  h.submit([](auto& c, Time t) { return c.set_v(t, 10); });
  h.answer(0x01, proto::Nack{proto::NackCode::bad_v});
  ASSERT_EQ(h.done.size(), 2u);
  EXPECT_EQ(h.done[0].result.code, ResultCode::nack);
  EXPECT_EQ(h.done[0].result.nack, (proto::Nack{std::string("BUSY")}));
  EXPECT_EQ(h.done[1].result.nack, (proto::Nack{proto::NackCode::bad_v}));
  EXPECT_EQ(h.sent.size(), 2u) << "no resend for a NACK other than BAD_CS";
  EXPECT_EQ(h.core.state(), ConnectionState::connected);
}

TEST(ArduinoClientCore, AnswersWithAnotherSeqAreIgnoredWithinTheAttempt) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.sonar(t); });
  h.at(milliseconds(100));
  h.answer(0x7F, proto::Ack{"999"});
  h.answer(0xFF, proto::Nack{proto::NackCode::bad_cs});
  EXPECT_TRUE(h.done.empty());
  EXPECT_EQ(h.sent.size(), 1u) << "a stale BAD_CS must not cause a resend";
  h.at(milliseconds(200));
  h.answer(0x00, proto::Ack{"40"});
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].result.info, "40");
  EXPECT_EQ(h.done[0].result.attempts, 1);
  EXPECT_EQ(h.core.stale_frames(), 2u);
}

TEST(ArduinoClientCore, OneRequestAtATimeInTheOrderTheyWereMade) {
  Harness h(no_health_check());
  h.open_now();
  const RequestId a = h.submit([](auto& c, Time t) { return c.ping(t); });
  const RequestId b = h.submit([](auto& c, Time t) { return c.sonar(t); });
  EXPECT_EQ(h.sent.size(), 1u);
  EXPECT_EQ(h.core.queued(), 1u);
  h.at(milliseconds(30));
  h.answer(0x00, proto::Ack{"OK"});
  ASSERT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(h.sent[1].at, milliseconds(30));
  EXPECT_EQ(h.sent[1].frame, "^01|B|*43$");
  h.answer(0x01, proto::Ack{"12"});
  ASSERT_EQ(h.done.size(), 2u);
  EXPECT_EQ(h.done[0].id, a);
  EXPECT_EQ(h.done[1].id, b);
}

TEST(ArduinoClientCore, NoAnswerToTheHealthCheckGoesDegradedThenReconnectingThenOpen) {
  Harness h;  // health check after 5 s without an exchange
  h.open_now();
  h.run_until(milliseconds(4999));
  EXPECT_TRUE(h.sent.empty());
  h.run_until(seconds(5));
  ASSERT_EQ(h.sent.size(), 1u);
  EXPECT_EQ(h.sent[0].frame, "^00|PING|*10$");
  h.run_until(milliseconds(13999));
  EXPECT_EQ(h.core.state(), ConnectionState::connected);
  h.run_until(seconds(14));  // 5 s + 9 s of attempts
  EXPECT_EQ(h.core.state(), ConnectionState::degraded);
  EXPECT_EQ(h.closes, (std::vector<Time>{seconds(14)}));
  h.run_until(milliseconds(14499));
  EXPECT_EQ(h.opens.size(), 1u);
  h.run_until(milliseconds(14500));
  EXPECT_EQ(h.core.state(), ConnectionState::reconnecting);
  ASSERT_EQ(h.opens.size(), 2u);
  EXPECT_EQ(h.opens[1], milliseconds(14500));
  h.at(milliseconds(14510));
  h.core.on_connected(h.now);
  h.collect();
  ASSERT_EQ(h.sent.size(), 5u);
  EXPECT_EQ(h.sent[4].frame, "^01|PING|*11$");
  h.answer(0x01, proto::Ack{"OK"});
  EXPECT_EQ(h.core.state(), ConnectionState::connected);
  ASSERT_EQ(h.changes.size(), 5u);
  const std::vector<std::pair<ConnectionState, Time>> expected = {
      {ConnectionState::connecting, seconds(0)},
      {ConnectionState::connected, seconds(0)},
      {ConnectionState::degraded, seconds(14)},
      {ConnectionState::reconnecting, milliseconds(14500)},
      {ConnectionState::connected, milliseconds(14510)}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(h.changes[i].to, expected[i].first) << i;
    EXPECT_EQ(h.changes[i].at, expected[i].second) << i;
  }
  // The health check comes again 5 s after the last exchange.
  h.run_until(milliseconds(19509));
  EXPECT_EQ(h.sent.size(), 5u);
  h.run_until(milliseconds(19510));
  EXPECT_EQ(h.sent.size(), 6u);
}

TEST(ArduinoClientCore, ReconnectAttemptsBackOffAndTheLinkIsDownAfterFourFailures) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  h.run_until(seconds(9));  // the ping times out: DEGRADED at 9 s
  const RequestId queued = h.submit([](auto& c, Time t) { return c.sonar(t); });
  std::vector<Time> attempts;
  for (int i = 0; i < 4; ++i) {
    const auto due = h.core.next_wakeup();
    ASSERT_TRUE(due.has_value());
    h.run_until(*due);
    attempts.push_back(h.now);
    h.core.on_connect_failed(h.now, "no such device");
    h.collect();
  }
  // 500 ms after the drop, then 1, 2 and 4 s after each failure.
  EXPECT_EQ(attempts, (std::vector<Time>{milliseconds(9500), milliseconds(10500),
                                         milliseconds(12500), milliseconds(16500)}));
  EXPECT_EQ(h.opens.size(), 5u);
  EXPECT_EQ(h.core.state(), ConnectionState::down);
  EXPECT_FALSE(h.core.next_wakeup().has_value());
  ASSERT_EQ(h.done.size(), 2u);
  EXPECT_EQ(h.done[1].id, queued);
  EXPECT_EQ(h.done[1].result.code, ResultCode::link_down);
  EXPECT_EQ(h.done[1].at, milliseconds(16500));
  h.submit([](auto& c, Time t) { return c.ping(t); });
  EXPECT_EQ(h.done.back().result.code, ResultCode::link_down) << "DOWN refuses at once";
}

TEST(ArduinoClientCore, AReconnectPingWithoutAnswerCountsAsAFailedAttempt) {
  Harness h(no_health_check());
  h.open_now();
  h.core.on_closed(h.now);  // the robot went away
  h.collect();
  EXPECT_EQ(h.core.state(), ConnectionState::degraded);
  h.run_until(milliseconds(500));
  h.core.on_connected(h.now);
  h.collect();
  // Reconnect PING: 0.6 + 1.2 + 2.4 s, then the next attempt 1 s later.
  h.run_until(milliseconds(4700));
  ASSERT_EQ(h.sent.size(), 3u);
  EXPECT_EQ(h.sent[1].at, milliseconds(1100));
  EXPECT_EQ(h.sent[2].at, milliseconds(2300));
  EXPECT_EQ(h.closes.back(), milliseconds(4700));
  EXPECT_EQ(h.core.state(), ConnectionState::reconnecting);
  EXPECT_EQ(h.core.next_wakeup(), milliseconds(5700));
}

TEST(ArduinoClientCore, ThePortClosingDuringARequestEndsItAsLinkDown) {
  Harness h(no_health_check());
  h.open_now();
  h.submit([](auto& c, Time t) { return c.move_cm(t, 10); });
  h.at(milliseconds(50));
  h.core.on_closed(h.now);
  h.collect();
  ASSERT_EQ(h.done.size(), 1u);
  EXPECT_EQ(h.done[0].result.code, ResultCode::link_down);
  EXPECT_EQ(h.core.state(), ConnectionState::degraded);
  EXPECT_EQ(h.core.next_wakeup(), milliseconds(550));
}

TEST(ArduinoClientCore, RequestsBeforeOpenOrAfterCloseEndAsLinkDown) {
  Harness h(no_health_check());
  h.submit([](auto& c, Time t) { return c.ping(t); });
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  h.submit([](auto& c, Time t) { return c.sonar(t); });
  h.core.close(h.now);
  h.collect();
  ASSERT_EQ(h.done.size(), 3u);
  for (auto& d : h.done)
    EXPECT_EQ(d.result.code, ResultCode::link_down);
  EXPECT_EQ(h.core.state(), ConnectionState::disconnected);
  EXPECT_EQ(h.closes.size(), 1u);
}

RC_GTEST_PROP(ArduinoClientCoreProperties, AnyChunkingOfNoiseStaleAndRightAnswersGivesTheSameResult,
              (std::uint8_t first_seq, std::uint8_t stale_offset)) {
  const auto info = *rc::gen::container<std::string>(
      rc::gen::suchThat(rc::gen::inRange<char>(0x20, 0x7F), proto::is_field_char));
  Harness h(no_health_check());
  h.open_now();
  // Use up SEQs so the request carries `first_seq`.
  for (int i = 0; i < first_seq; ++i) {
    h.submit([](auto& c, Time t) { return c.ping(t); });
    h.answer(h.sent.back().seq, proto::Ack{"OK"});
  }
  h.done.clear();
  h.submit([](auto& c, Time t) { return c.status(t); });
  RC_ASSERT(h.sent.back().seq == first_seq);
  const auto stale = static_cast<std::uint8_t>(first_seq + 1 + stale_offset % 255);
  const std::string stream = "\r\n" + proto::encode_text({stale, proto::Ack{"stale"}}) +
                             proto::encode_text({first_seq, proto::Ack{info}});
  const auto bytes = protocol::to_bytes(stream);
  std::size_t at = 0;
  while (at < bytes.size()) {
    const auto n = *rc::gen::inRange<std::size_t>(1, bytes.size() - at + 1);
    h.core.on_bytes(h.now, ByteView(bytes).subspan(at, n));
    h.collect();
    at += n;
  }
  RC_ASSERT(h.done.size() == 1u);
  RC_ASSERT(h.done[0].result.code == ResultCode::ok);
  RC_ASSERT(h.done[0].result.info == info);
  RC_ASSERT(h.done[0].result.attempts == 1);
  RC_ASSERT(h.core.stale_frames() == 1u);
}

RC_GTEST_PROP(ArduinoClientCoreProperties,
              TheAnswerAfterKLostAttemptsEndsTheRequestOnTheDoublingSchedule, ()) {
  const int lost = *rc::gen::inRange(0, 4);
  const auto base_ms = *rc::gen::inRange(1, 2000);
  ClientConfig config = no_health_check();
  config.base_timeout = milliseconds(base_ms);
  Harness h(config);
  h.open_now();
  h.submit([](auto& c, Time t) { return c.ping(t); });
  // Attempt k goes out at base * (2^k - 1).
  const Time sent_at = milliseconds(base_ms) * ((1 << lost) - 1);
  h.run_until(sent_at);
  RC_ASSERT(h.sent.size() == static_cast<std::size_t>(lost + 1));
  RC_ASSERT(h.sent.back().at == sent_at);
  h.answer(0x00, proto::Ack{"OK"});
  RC_ASSERT(h.done.size() == 1u);
  RC_ASSERT(h.done[0].result.attempts == lost + 1);
}

}  // namespace
}  // namespace hil::client::arduino
