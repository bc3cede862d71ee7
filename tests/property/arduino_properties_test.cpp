// Properties of the Arduino reference client (docs/clients/arduino.md) in
// virtual time: the core against a scripted robot whose every answer is
// chosen at random (exact times of every attempt), and the session against
// the mock robot on mem:// under a random fault schedule and a random
// operator session (the bench, arduino_rig.hpp), checked from its frame
// log, its events and the chassis (the checks, arduino_checks.cpp).
//
// Which property guards which rule:
//   - EachAttemptWaitsTwiceTheLast...: the core alone, to the nanosecond:
//     each attempt's timeout doubles, a NACK BAD_CS is resent at once
//     without counting as a retry, and only a reply with the request's SEQ
//     ends it;
//   - AnAnswerIsTakenOnlyForTheRequestWithItsSeq...: a reply answers only
//     the request sent with its SEQ, and the result says what the robot
//     said to that request;
//   - EveryRetryComesOnItsDoubledTimeout...: each retry on its doubled
//     timeout, each BAD_CS resend at once (at most three), a timeout at the
//     sum of the timeouts, and the result counting them as they went out;
//   - TheLinkMovesAlongItsStateMachine...: the link's edges and when each
//     is taken, the reconnect back-off, and nothing but the proving PING on
//     a port the client reopened;
//   - RequestsAreServedOneAtATime...: one request at a time, in the order
//     made, each ending exactly once;
//   - OnACleanLink...: with nothing lost, every request answered at its
//     first attempt and the link never leaving OPEN.
// Every session property also holds each frame to its time and each port
// the client reopened to its PING (check_attempt_times, which they share).
// ArduinoClientPropertiesOnTheSketch runs the session properties against
// hil's test sketch on the emulated ATmega328P as well, with fewer cases
// (kSketchCasesPercent); there each planted bug below was caught too,
// within 10 to 23 sessions from kPlantedSeed.
//
// They have teeth. ArduinoPlantedBugs (at the end) plants each bug of
// tests/property/arduino_planted_bug.hpp in the client as built and shows
// the property guarding its rule fail on it and pass without it:
//   - no_resend_on_bad_cs (a NACK BAD_CS ends the request at once):
//     EveryRetryComesOnItsDoubledTimeout...;
//   - any_seq_is_answer (a reply with another SEQ ends the request):
//     AnAnswerIsTakenOnlyForTheRequestWithItsSeq...;
//   - fixed_timeout (the timeout never doubles):
//     EveryRetryComesOnItsDoubledTimeout....
// Rules broken by hand in a copy of client/arduino/core.cpp (never kept in
// this tree) were caught as well: timeouts growing as base x (attempt + 1),
// a BAD_CS resend counted as a retry and an ACK taken whatever its SEQ by
// EachAttemptWaitsTwiceTheLast... and every session property; a reopened
// port counted OPEN without its PING by every session property but
// RequestsAreServedOneAtATime...; the reconnect delay kept at 0.5 s instead
// of doubling by TheLinkMovesAlongItsStateMachine....
// RC_PARAMS="seed=..." printed with a failure replays it.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/detail/Configuration.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "client/arduino/core.hpp"
#include "protocol/arduino/codec.hpp"
#include "tests/property/arduino_planted_bug.hpp"
#include "tests/property/arduino_rig.hpp"
#include "tests/property/planted_check.hpp"

namespace hil::client::arduino::prop {
namespace {

using link::milliseconds;
using link::seconds;

// ---------------------------------------------------------------------------
// The core against a scripted robot: one request, each frame it sends meets
// an answer drawn at random, delivered before that attempt's deadline.
// ---------------------------------------------------------------------------

enum class Answer : std::uint8_t {
  silent,      ///< nothing comes back
  corrupted,   ///< an ACK with a wrong checksum (a parse error)
  stale,       ///< an ACK or NACK BAD_CS with another SEQ
  bad_cs,      ///< NACK BAD_CS with the request's SEQ
  ack,         ///< ACK with the request's SEQ
  other_nack,  ///< NACK BAD_V with the request's SEQ
};

struct ScriptedAnswer {
  Answer answer = Answer::silent;
  int delay_permille = 0;  ///< of the attempt's timeout, 0..999: always before the deadline
};

rc::Gen<ScriptedAnswer> gen_answer() {
  return rc::gen::build<ScriptedAnswer>(
      rc::gen::set(&ScriptedAnswer::answer,
                   rc::gen::weightedElement<Answer>({{4, Answer::silent},
                                                     {2, Answer::corrupted},
                                                     {2, Answer::stale},
                                                     {3, Answer::bad_cs},
                                                     {2, Answer::ack},
                                                     {1, Answer::other_nack}})),
      rc::gen::set(&ScriptedAnswer::delay_permille, rc::gen::inRange(0, 1000)));
}

/// What the documented rules say happens to the request.
struct Expected {
  std::vector<Time> sends;
  std::vector<Duration> timeouts;  ///< the timeout running after each send
  ResultCode code = ResultCode::timeout;
  int attempts = 0;
  int bad_cs_resends = 0;
  Time end{0};
};

Expected expect(const ClientConfig& config, const std::vector<ScriptedAnswer>& answers) {
  Expected e;
  Time t{0};
  int attempt = 0;
  for (std::size_t k = 0;; ++k) {
    const Duration timeout = config.base_timeout * (std::int64_t{1} << attempt);
    e.sends.push_back(t);
    e.timeouts.push_back(timeout);
    const ScriptedAnswer a = k < answers.size() ? answers[k] : ScriptedAnswer{};
    const Time answered = t + timeout * a.delay_permille / 1000;
    auto end = [&](ResultCode code, Time at) {
      e.code = code;
      e.end = at;
      e.attempts = attempt + 1;
    };
    switch (a.answer) {
      case Answer::ack:
        end(ResultCode::ok, answered);
        return e;
      case Answer::other_nack:
        end(ResultCode::nack, answered);
        return e;
      case Answer::bad_cs:
        if (e.bad_cs_resends < config.max_bad_cs_resends) {
          ++e.bad_cs_resends;
          t = answered;  // resent at once; the same attempt's timeout starts again
          continue;
        }
        end(ResultCode::nack, answered);
        return e;
      case Answer::silent:
      case Answer::corrupted:
      case Answer::stale:
        if (attempt < config.max_retries) {
          t += timeout;
          ++attempt;
          continue;
        }
        end(ResultCode::timeout, t + timeout);
        return e;
    }
  }
}

protocol::Bytes answer_bytes(Answer a, std::uint8_t seq, bool stale_is_bad_cs) {
  switch (a) {
    case Answer::ack:
      return proto::encode({seq, proto::Ack{"77"}});
    case Answer::other_nack:
      return proto::encode({seq, proto::Nack{proto::NackCode::bad_v}});
    case Answer::bad_cs:
      return proto::encode({seq, proto::Nack{proto::NackCode::bad_cs}});
    case Answer::stale: {
      const auto other = static_cast<std::uint8_t>(seq + 1);
      return stale_is_bad_cs ? proto::encode({other, proto::Nack{proto::NackCode::bad_cs}})
                             : proto::encode({other, proto::Ack{"STALE"}});
    }
    case Answer::corrupted: {
      protocol::Bytes b = proto::encode({seq, proto::Ack{"77"}});
      auto& digit = b[b.size() - 2];  // the checksum's last hex digit
      digit = digit == '0' ? '1' : '0';
      return b;
    }
    case Answer::silent:
      break;
  }
  return {};
}

RC_GTEST_PROP(ArduinoClientProperties,
              EachAttemptWaitsTwiceTheLastAndBadCsIsResentAtOnceWithoutCountingAsARetry, ()) {
  ClientConfig config;
  config.base_timeout = milliseconds(*rc::gen::inRange(50, 2001));
  config.max_retries = *rc::gen::inRange(0, 5);
  config.max_bad_cs_resends = *rc::gen::inRange(0, 4);
  config.health_check_interval = Duration::zero();
  const auto answers = *rc::gen::container<std::vector<ScriptedAnswer>>(gen_answer());
  const bool stale_is_bad_cs = *rc::gen::arbitrary<bool>();
  const auto first_seq = *rc::gen::arbitrary<std::uint8_t>();
  const Expected want = expect(config, answers);

  ArduinoClientCore core(config);
  core.open(Time{0});
  core.on_connected(Time{0});
  // Earlier requests, answered at once, move the SEQ to anywhere on its wheel.
  for (int i = 0; i < first_seq; ++i) {
    core.ping(Time{0});
    for (auto& a : core.take_actions()) {
      if (auto* send = std::get_if<SendFrame>(&a))
        core.on_bytes(Time{0}, proto::encode({send->seq, proto::Ack{"OK"}}));
    }
  }
  (void)core.take_events();
  RC_ASSERT(core.next_seq() == first_seq);

  std::vector<Time> sends;
  std::optional<std::pair<Time, protocol::Bytes>> delivery;
  std::optional<Result> result;
  Time ended{0};
  auto absorb = [&](Time now) {
    for (auto& a : core.take_actions()) {
      const auto* send = std::get_if<SendFrame>(&a);
      if (send == nullptr) continue;
      RC_ASSERT(send->seq == first_seq);  // every attempt and resend keeps the SEQ
      RC_ASSERT(send->bytes == proto::encode({first_seq, proto::SetSpeed{77}}));
      const std::size_t k = sends.size();
      sends.push_back(now);
      if (k < answers.size() && k < want.timeouts.size() && answers[k].answer != Answer::silent) {
        delivery = {now + want.timeouts[k] * answers[k].delay_permille / 1000,
                    answer_bytes(answers[k].answer, first_seq, stale_is_bad_cs)};
      }
    }
    for (auto& e : core.take_events()) {
      if (auto* done = std::get_if<RequestDone>(&e)) {
        result = done->result;
        ended = now;
      }
    }
  };
  core.set_v(Time{0}, 77);
  absorb(Time{0});
  while (!result) {
    const auto wake = core.next_wakeup();
    RC_ASSERT(wake.has_value() || delivery.has_value());
    if (delivery && (!wake || delivery->first <= *wake)) {
      const auto [at, bytes] = *std::exchange(delivery, std::nullopt);
      core.on_bytes(at, bytes);
      absorb(at);
    } else {
      core.on_timer(*wake);
      absorb(*wake);
    }
  }
  RC_ASSERT(sends == want.sends);
  RC_ASSERT(result->code == want.code);
  RC_ASSERT(ended == want.end);
  RC_ASSERT(result->attempts == want.attempts);
  RC_ASSERT(result->bad_cs_resends == want.bad_cs_resends);
  RC_ASSERT(result->seq == std::optional<std::uint8_t>(first_seq));
  if (result->code == ResultCode::ok) RC_ASSERT(result->info == std::string("77"));
  if (want.code == ResultCode::nack) {
    const bool last_was_bad_cs = answers[want.sends.size() - 1].answer == Answer::bad_cs;
    RC_ASSERT(result->nack == std::optional(proto::Nack{last_was_bad_cs ? proto::NackCode::bad_cs
                                                                        : proto::NackCode::bad_v}));
  }
}

// ---------------------------------------------------------------------------
// The session against the mock robot under random faults.
// ---------------------------------------------------------------------------

// The rules each session property reads from a whole run (arduino_checks.cpp).

void check_answers(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
  check_results(rig, wire, check_attempt_times(rig, wire), ResultRules::answers);
}

void check_attempts(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
  check_results(rig, wire, check_attempt_times(rig, wire), ResultRules::attempts);
}

void check_serving_order(const ArduinoRig& rig, const std::vector<WireFrame>&) {
  check_order(rig);
}

RC_GTEST_PROP(ArduinoClientProperties,
              AnAnswerIsTakenOnlyForTheRequestWithItsSeqAndSaysWhatTheRobotSaid, ()) {
  after_a_random_session(check_answers);
}

RC_GTEST_PROP(ArduinoClientProperties,
              EveryRetryComesOnItsDoubledTimeoutEveryBadCsResendAtOnceAndATimeoutAtTheSum, ()) {
  after_a_random_session(check_attempts);
}

RC_GTEST_PROP(ArduinoClientProperties,
              TheLinkMovesAlongItsStateMachineOnTimeAndAReopenedPortGetsOnlyItsProvingPing, ()) {
  after_a_random_session(check_link_states);
}

RC_GTEST_PROP(ArduinoClientProperties, RequestsAreServedOneAtATimeInOrderAndEachEndsExactlyOnce,
              ()) {
  after_a_random_session(check_serving_order);
}

/// With nothing lost on the link, against `board`: every request is
/// answered at its first attempt and the link never leaves OPEN.
void on_a_clean_link(Board board) {
  ArduinoRig rig(link::FaultProfile{}, PlantedBug::none, board);
  const auto requests = *rc::gen::container<std::vector<proto::Body>>(gen_request());
  for (const auto& body : requests) {
    const RequestId id = rig.session->request(body);
    rig.bodies[id] = body;
    if (is_valid_request(body)) rig.queued.push_back(id);
    rig.car.executor.run_for(milliseconds(*rc::gen::inRange(0, 300)));
  }
  finish(rig, seconds(20));
  const auto wire = wire_of(rig);
  RC_LOG() << dump(rig, wire);
  const auto exchanges = check_attempt_times(rig, wire);
  check_results(rig, wire, exchanges, ResultRules::answers);
  check_results(rig, wire, exchanges, ResultRules::attempts);
  check_link_states(rig, wire);
  check_order(rig);
  RC_ASSERT(rig.done.size() == requests.size());
  for (const auto& d : rig.done) {
    RC_ASSERT(
        d.result.code ==
        (is_valid_request(rig.bodies.at(d.id)) ? ResultCode::ok : ResultCode::invalid_request));
    RC_ASSERT(d.result.attempts <= 1);
  }
  // OPENING and OPEN, nothing else: with nothing lost, nothing degrades.
  RC_ASSERT(rig.links.size() == 2u);
  RC_ASSERT(rig.session->state() == ConnectionState::connected);
}

RC_GTEST_PROP(ArduinoClientProperties, OnACleanLinkEveryRequestIsAnsweredOnceAndTheLinkStaysOpen,
              ()) {
  on_a_clean_link(Board::mock);
}

// ---- the same properties against hil's test sketch on the emulated board ----
// The sketch runs as built: the robot misbehaves only as the driver can make
// it (hanging up, resetting the connection), and the link's faults act.

/// The emulated board costs CPU: it runs about ten to twelve times faster
/// than real time, and a random session lasts tens of virtual seconds
/// (about 2 s of CPU each, measured), so each property runs this share of
/// the cases RC_PARAMS asks for (100 by default: 5 sessions, about 8 to 12
/// s a property; the sanitizer trees' 25: 1; the soak's 5,000: 250), at
/// least one.
constexpr int kSketchCasesPercent = 5;

/// Checks `property` (a callable that checks one random case) as
/// RC_GTEST_PROP does, with kSketchCasesPercent of the configured cases.
template <class Property>
void check_on_the_sketch(const std::string& name, Property property) {
  rc::detail::TestParams params = rc::detail::configuration().testParams;
  params.maxSuccess = std::max(1, params.maxSuccess * kSketchCasesPercent / 100);
  rc::detail::TestMetadata metadata;
  metadata.id = "ArduinoClientPropertiesOnTheSketch/" + name;
  metadata.description = name;
  const rc::detail::TestResult result =
      rc::detail::checkTestable(std::move(property), metadata, params);
  EXPECT_TRUE(result.is<rc::detail::SuccessResult>()) << name << ":\n"
                                                      << logi::prop::result_message(result);
}

TEST(ArduinoClientPropertiesOnTheSketch,
     AnAnswerIsTakenOnlyForTheRequestWithItsSeqAndSaysWhatTheRobotSaid) {
  check_on_the_sketch("AnAnswerIsTakenOnlyForTheRequestWithItsSeq", [] {
    after_a_random_session(check_answers, PlantedBug::none, Board::sketch);
  });
}

TEST(ArduinoClientPropertiesOnTheSketch,
     EveryRetryComesOnItsDoubledTimeoutEveryBadCsResendAtOnceAndATimeoutAtTheSum) {
  check_on_the_sketch("EveryRetryComesOnItsDoubledTimeout", [] {
    after_a_random_session(check_attempts, PlantedBug::none, Board::sketch);
  });
}

TEST(ArduinoClientPropertiesOnTheSketch,
     TheLinkMovesAlongItsStateMachineOnTimeAndAReopenedPortGetsOnlyItsProvingPing) {
  check_on_the_sketch("TheLinkMovesAlongItsStateMachine", [] {
    after_a_random_session(check_link_states, PlantedBug::none, Board::sketch);
  });
}

TEST(ArduinoClientPropertiesOnTheSketch, RequestsAreServedOneAtATimeInOrderAndEachEndsExactlyOnce) {
  check_on_the_sketch("RequestsAreServedOneAtATime", [] {
    after_a_random_session(check_serving_order, PlantedBug::none, Board::sketch);
  });
}

TEST(ArduinoClientPropertiesOnTheSketch,
     OnACleanLinkEveryRequestIsAnsweredOnceAndTheLinkStaysOpen) {
  check_on_the_sketch("OnACleanLink", [] { on_a_clean_link(Board::sketch); });
}

// ---- the properties have teeth ----
// Each bug of tests/property/arduino_planted_bug.hpp, planted in the client
// on its own, makes the property named for it fail within a fixed number of
// random sessions (from one fixed seed, tests/property/planted_check.hpp),
// and the same property passes on the same sessions without the bug.

struct PlantedCase {
  const char* name;
  PlantedBug bug;
  const char* property;
  SessionCheck check;
};

rc::detail::TestResult run_planted(const PlantedCase& c, PlantedBug bug, int sessions) {
  return logi::prop::run_planted(c.property, sessions,
                                 [&c, bug] { after_a_random_session(c.check, bug); });
}

void PrintTo(const PlantedCase& c, std::ostream* os) {
  *os << c.name;
}

class ArduinoPlantedBugs : public ::testing::TestWithParam<PlantedCase> {};

TEST_P(ArduinoPlantedBugs, IsCaughtByItsPropertyWhichPassesWithoutIt) {
  const PlantedCase& c = GetParam();
  logi::prop::expect_caught_and_clean(c.property, c.name, [&c](bool planted, int sessions) {
    return run_planted(c, planted ? c.bug : PlantedBug::none, sessions);
  });
}

INSTANTIATE_TEST_SUITE_P(
    Arduino, ArduinoPlantedBugs,
    ::testing::Values(
        PlantedCase{"NoResendOnBadCs", PlantedBug::no_resend_on_bad_cs,
                    "EveryRetryComesOnItsDoubledTimeoutEveryBadCsResendAtOnceAndATimeoutAtTheSum",
                    check_attempts},
        PlantedCase{"AnySeqIsAnswer", PlantedBug::any_seq_is_answer,
                    "AnAnswerIsTakenOnlyForTheRequestWithItsSeqAndSaysWhatTheRobotSaid",
                    check_answers},
        PlantedCase{"FixedTimeout", PlantedBug::fixed_timeout,
                    "EveryRetryComesOnItsDoubledTimeoutEveryBadCsResendAtOnceAndATimeoutAtTheSum",
                    check_attempts}),
    [](const ::testing::TestParamInfo<PlantedCase>& param) {
      return std::string(param.param.name);
    });

}  // namespace
}  // namespace hil::client::arduino::prop
