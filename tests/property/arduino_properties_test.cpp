// Properties of the Arduino reference client (docs/clients/arduino.md) in
// virtual time: the core against a scripted robot whose every answer is
// chosen at random (exact times of every attempt), and the session against
// the mock robot on mem:// under a random fault schedule and a random
// operator session, checked from its frame log, its events and the chassis.
//
// Each property was seen to fail with its rule broken on purpose in a copy
// of client/arduino/core.cpp (never in this tree), then the copy was
// thrown away; 300 sessions per property found each of these:
//   - timeouts growing base x (attempt + 1) instead of doubling, a BAD_CS
//     resend counted as a retry, an ACK taken whatever its SEQ:
//     EachAttemptWaitsTwiceTheLast..., and every session property (their
//     shared reading of the frames checks each retry's time);
//   - a reopened port counted OPEN without its PING: the session
//     properties but RequestsAreServedOneAtATime...;
//   - the reconnect delay kept at 0.5 s instead of doubling after each
//     failure: TheLinkMovesAlongItsStateMachine....
// RC_PARAMS="seed=..." printed with a failure replays it.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <rapidcheck/state.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "client/arduino/core.hpp"
#include "client/arduino/session.hpp"
#include "link/executor.hpp"
#include "link/faults/profile.hpp"
#include "link/transport.hpp"
#include "mocks/arduino.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/codec.hpp"
#include "sim/differential.hpp"
#include "sim/presets.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/property/random_faults.hpp"
#include "tests/property/session_commands.hpp"

namespace hil::client::arduino {
namespace {

namespace proto = protocol::arduino;
using hil::test::RandomFaults;
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

/// Faults that keep the oracle sound: whole frames dropped or duplicated,
/// one position corrupted (the XOR checksum always catches it), delays,
/// fragments, batches, harmless noise, stalls and link resets. Byte drops
/// and multi-position corruption are left out: they can turn a frame into
/// another valid one, which no client can tell.
rc::Gen<link::FaultProfile> gen_faults() {
  return rc::gen::exec([] {
    RandomFaults faults(30);
    faults.maybe(link::Drop{});
    if (RandomFaults::coin())
      faults.add_sometimes(
          link::Corrupt{.target = link::CorruptTarget::random, .field = "", .bits = 1});
    if (RandomFaults::coin())
      faults.add_sometimes(
          link::Corrupt{.target = link::CorruptTarget::checksum, .field = "", .bits = 1});
    faults.maybe(link::Duplicate{1});
    faults.maybe_delay(800);
    faults.maybe_fragment();
    if (RandomFaults::coin())
      faults.add_sometimes(link::Coalesce{2, milliseconds(*rc::gen::inRange(1, 200))});
    if (RandomFaults::coin()) faults.add_sometimes(link::Garbage{{1, 1}, {'\r', '\n', '~', '#'}});
    faults.add_stalls(6000);
    faults.add_breaks();
    return faults.take();
  });
}

rc::Gen<proto::Body> gen_request() {
  return rc::gen::oneOf(
      rc::gen::just<proto::Body>(proto::Ping{}), rc::gen::just<proto::Body>(proto::StatusRequest{}),
      rc::gen::map(rc::gen::inRange(0, 256),
                   [](int pwm) { return proto::Body{proto::SetSpeed{pwm}}; }),
      rc::gen::map(rc::gen::inRange(-40, 41), [](int cm) { return proto::Body{proto::Move{cm}}; }),
      rc::gen::map(rc::gen::inRange(-90, 91),
                   [](int deg) { return proto::Body{proto::Rotate{deg}}; }),
      rc::gen::just<proto::Body>(proto::Stop{}), rc::gen::just<proto::Body>(proto::SonarRead{}),
      rc::gen::just<proto::Body>(proto::IrRead{}),
      // What the protocol cannot carry: refused at once, no SEQ used.
      rc::gen::map(rc::gen::inRange(256, 1000),
                   [](int pwm) { return proto::Body{proto::SetSpeed{pwm}}; }));
}

bool is_valid_request(const proto::Body& body) {
  const auto* v = std::get_if<proto::SetSpeed>(&body);
  return v == nullptr || (v->pwm >= 0 && v->pwm <= 255);
}

/// The mock robot on mem://arduino, a session to it, and everything the
/// session reported, stamped with the virtual clock.
struct ArduinoRig {
  struct Done {
    Time at{0};
    RequestId id = 0;
    Result result;
    bool robot_moving = false;
    int left_pwm = 0;
    int right_pwm = 0;
  };

  /// Records when a link to the robot opened and closed, whoever closed it.
  struct Closes : link::LinkObserver {
    Closes(std::vector<Time>& closes, std::vector<Time>& opens) : out_(closes), opens_(opens) {}
    void on_open(Time at, const std::string&, const std::string&) override { opens_.push_back(at); }
    void on_close(Time at, const link::LinkClose&) override { out_.push_back(at); }
    std::vector<Time>& out_;
    std::vector<Time>& opens_;
  };

  explicit ArduinoRig(link::FaultProfile faults) {
    mocks::ServerOptions options = test::on_mem("arduino");
    options.faults = std::move(faults);
    options.observers.push_back(std::make_shared<Closes>(closes, car_opens));
    car.start_car(sim::arduino_robot(), std::move(options));
    session = std::make_unique<ArduinoSession>(car.context, link::MemEndpoint{"arduino"});
    // The log's clock is the virtual one in nanoseconds (not the microseconds
    // its name says): jittered delays fall between microseconds, and every
    // timing rule is checked to the nanosecond.
    session->set_wall_clock([this] { return car.executor.now().count(); });
    session->set_event_handler([this](const Event& e) {
      if (const auto* l = std::get_if<LinkChanged>(&e)) {
        links.push_back(*l);
        turned_away.push_back(car.server->turned_away());
      } else if (const auto* d = std::get_if<RequestDone>(&e)) {
        auto& chassis = dynamic_cast<sim::DifferentialChassis&>(car.firmware->vehicle().chassis());
        done.push_back({car.executor.now(), d->id, d->result, car.firmware->moving(),
                        chassis.left_pwm(), chassis.right_pwm()});
      }
    });
    session->open();
    car.executor.run_for(Duration::zero());
  }

  Time now() const { return car.executor.now(); }

  // The records come first: the car and the session report into them until
  // they are gone.
  std::vector<LinkChanged> links;
  std::vector<Done> done;
  std::map<RequestId, proto::Body> bodies;
  std::vector<RequestId> queued;  ///< requests that did not end at once, in order
  std::vector<Time> closes;       ///< when a link to the robot closed
  std::vector<Time> car_opens;    ///< when a link to the robot opened
  /// Connections the robot turned away (still busy with the last one), as
  /// counted at each link change.
  std::vector<std::uint64_t> turned_away;
  std::vector<Time> operator_opens{Time{0}};  ///< when the operator opened the port
  /// How many frames the session had logged when the operator opened the
  /// port, one per entry of operator_opens: orders that open against frames
  /// of the same instant.
  std::vector<std::size_t> logged_at_operator_open{0};
  test::VirtualCar<mocks::ArduinoFirmware> car;
  std::unique_ptr<ArduinoSession> session;
};

struct WireFrame {
  Time at{0};
  bool tx = false;
  std::string raw;
  std::optional<proto::Message> message;  ///< when it decodes
};

std::vector<WireFrame> wire_of(const ArduinoRig& rig) {
  std::vector<WireFrame> out;
  for (const auto& e : rig.session->log().entries()) {
    WireFrame f;
    f.at = Time{e.utc_us};
    f.tx = e.kind == LogKind::tx;
    f.raw = e.raw;
    const protocol::Bytes bytes(e.raw.begin(), e.raw.end());
    const auto item = proto::decode_frame(bytes, rig.session->core().config().dialect);
    if (const auto* frame = std::get_if<protocol::Frame<proto::Message>>(&item))
      f.message = frame->message;
    out.push_back(std::move(f));
  }
  return out;
}

bool is_bad_cs(const proto::Message& m) {
  const auto* n = std::get_if<proto::Nack>(&m.body);
  return n != nullptr &&
         n->error == std::variant<proto::NackCode, std::string>(proto::NackCode::bad_cs);
}

/// One request's frames on the wire: the consecutive TX frames with one SEQ.
struct Exchange {
  std::uint8_t seq = 0;
  std::size_t first = 0;  ///< index in the wire of its first TX
  std::vector<std::size_t> sends;
  int retries = 0;
  int resends = 0;
  bool reconnect_check = false;
};

/// Rule: every frame of a request after its first goes out either the
/// instant a NACK BAD_CS with its SEQ came in (a resend: same attempt) or
/// exactly base x 2^attempt after the one before it (a retry); never more
/// retries than allowed, never more than 3 resends.
std::vector<Exchange> check_attempt_times(const ArduinoRig& rig,
                                          const std::vector<WireFrame>& wire) {
  const ClientConfig& config = rig.session->core().config();
  std::vector<Exchange> out;
  std::optional<std::size_t> last_tx;
  std::deque<Time> unused_bad_cs;  // BAD_CS NACKs for the open exchange not yet resent for
  for (std::size_t i = 0; i < wire.size(); ++i) {
    const WireFrame& f = wire[i];
    if (!f.tx) {
      if (!out.empty() && f.message && is_bad_cs(*f.message) && f.message->seq == out.back().seq)
        unused_bad_cs.push_back(f.at);
      continue;
    }
    RC_ASSERT(f.message.has_value());  // the client only sends frames that decode
    const bool same =
        !out.empty() && last_tx && f.message->seq == out.back().seq && f.raw == wire[*last_tx].raw;
    if (!same) {
      Exchange x;
      x.seq = f.message->seq;
      x.first = i;
      x.sends.push_back(i);
      out.push_back(std::move(x));
      unused_bad_cs.clear();
      last_tx = i;
      continue;
    }
    Exchange& x = out.back();
    const Time previous = wire[*last_tx].at;
    if (!unused_bad_cs.empty() && x.resends < config.max_bad_cs_resends) {
      // A resend goes out in the same instant as the NACK that caused it.
      RC_ASSERT(f.at == unused_bad_cs.front());
      unused_bad_cs.pop_front();
      ++x.resends;
    } else {
      RC_ASSERT(f.at - previous == config.base_timeout * (std::int64_t{1} << x.retries));
      ++x.retries;
    }
    x.sends.push_back(i);
    last_tx = i;
  }
  // A port the client reopened by itself (not the operator's open) is
  // proved by a PING sent the instant it opens: that exchange is the
  // reconnect check, with its own retry count.
  for (Time opened : rig.car_opens) {
    if (std::count(rig.operator_opens.begin(), rig.operator_opens.end(), opened) != 0) continue;
    Exchange* first = nullptr;
    for (auto& x : out) {
      if (wire[x.first].at >= opened) {
        first = &x;
        break;
      }
    }
    RC_ASSERT((first != nullptr));
    RC_ASSERT(wire[first->first].at == opened);
    RC_ASSERT(std::holds_alternative<proto::Ping>(wire[first->first].message->body));
    first->reconnect_check = true;
  }
  // From DEGRADED until the link is OPEN again (or CLOSED, DOWN) only the
  // proving PINGs go out (the board has just reset; nothing queued may
  // reach it before it answered), also on a port the robot turned away.
  for (std::size_t i = 0; i < rig.links.size(); ++i) {
    if (rig.links[i].to != ConnectionState::degraded) continue;
    const Time from = rig.links[i].at;
    std::optional<Time> to;
    bool down = false;
    for (std::size_t j = i + 1; j < rig.links.size() && !to; ++j) {
      if (rig.links[j].to != ConnectionState::reconnecting &&
          rig.links[j].to != ConnectionState::degraded) {
        to = rig.links[j].at;
        down = rig.links[j].to == ConnectionState::down;
      }
    }
    // A frame logged after the operator opened the port in the instant the
    // link went DOWN belongs to the new port, not to the reconnect.
    auto after_operator_open = [&](std::size_t index, Time at) {
      for (std::size_t k = 0; k < rig.operator_opens.size(); ++k) {
        if (rig.operator_opens[k] == at && index >= rig.logged_at_operator_open[k]) return true;
      }
      return false;
    };
    for (auto& x : out) {
      const Time began = wire[x.first].at;
      // The last attempt may fail (and the link go DOWN) in the instant it began.
      if (began > from &&
          (!to || began < *to || (down && began == *to && !after_operator_open(x.first, began)))) {
        RC_ASSERT(std::holds_alternative<proto::Ping>(wire[x.first].message->body));
        x.reconnect_check = true;
      }
    }
  }
  for (const auto& x : out) {
    RC_ASSERT(x.retries <=
              (x.reconnect_check ? config.reconnect_ping_retries : config.max_retries));
    RC_ASSERT(x.resends <= config.max_bad_cs_resends);
  }
  return out;
}

/// Which rules of a request's result check_results() holds it to.
enum class ResultRules : std::uint8_t {
  /// An answer is taken only for the request with its SEQ, and carries what
  /// the robot said to that very request.
  answers,
  /// The result counts the request's retries and resends as they went out,
  /// and a timeout ends exactly base x 2^(last attempt) after its last frame.
  attempts,
};

void check_results(const ArduinoRig& rig, const std::vector<WireFrame>& wire,
                   const std::vector<Exchange>& exchanges, ResultRules rules) {
  const ClientConfig& config = rig.session->core().config();
  const proto::Dialect dialect = config.dialect;
  for (const auto& d : rig.done) {
    const proto::Body& body = rig.bodies.at(d.id);
    const Result& r = d.result;
    if (r.code == ResultCode::invalid_request) {
      RC_ASSERT(!is_valid_request(body));
      continue;
    }
    RC_ASSERT(is_valid_request(body));
    if (!r.seq) {  // never sent: the link was closed or DOWN
      RC_ASSERT(r.code == ResultCode::link_down);
      continue;
    }
    // The request's frames: the last exchange with its SEQ that began by then.
    const Exchange* x = nullptr;
    for (const auto& e : exchanges) {
      if (e.seq == *r.seq && wire[e.first].at <= d.at) x = &e;
    }
    RC_ASSERT((x != nullptr));
    RC_ASSERT(wire[x->first].raw == proto::encode_text({*r.seq, body}, dialect));
    if (rules == ResultRules::attempts) {
      RC_ASSERT(r.attempts == x->retries + 1);
      RC_ASSERT(r.bad_cs_resends == x->resends);
      const Time last_send = wire[x->sends.back()].at;
      if (r.code == ResultCode::timeout) {
        RC_ASSERT(r.attempts == config.max_retries + 1);
        RC_ASSERT(d.at ==
                  last_send + config.base_timeout * (std::int64_t{1} << config.max_retries));
      }
      if (r.code == ResultCode::nack &&
          r.nack == std::optional(proto::Nack{proto::NackCode::bad_cs}))
        RC_ASSERT(r.bad_cs_resends == config.max_bad_cs_resends);
      continue;
    }
    if (r.code == ResultCode::timeout || r.code == ResultCode::link_down) continue;
    // ok or nack: an answer with this SEQ and exactly this content came in at
    // that instant, after the request went out.
    RC_ASSERT((r.code == ResultCode::ok) != r.nack.has_value());
    const proto::Body said =
        r.code == ResultCode::ok ? proto::Body{proto::Ack{r.info}} : proto::Body{*r.nack};
    const WireFrame* answer = nullptr;
    for (std::size_t j = x->first + 1; j < wire.size() && answer == nullptr; ++j) {
      if (!wire[j].tx && wire[j].at == d.at && wire[j].message &&
          *wire[j].message == proto::Message{*r.seq, said})
        answer = &wire[j];
    }
    RC_ASSERT((answer != nullptr));
    if (r.code == ResultCode::ok) {
      // The README's board says the value it applied to V: the ACK belongs
      // to this V. The real sketch says OK, and PONG to PING.
      const bool readme = dialect == proto::Dialect::readme;
      if (const auto* v = std::get_if<proto::SetSpeed>(&body))
        RC_ASSERT(r.info == (readme ? std::to_string(v->pwm) : std::string("OK")));
      if (std::holds_alternative<proto::Ping>(body))
        RC_ASSERT(r.info == std::string(readme ? "OK" : "PONG"));
      // Physics: the robot stands with its motors off once S is acknowledged.
      if (std::holds_alternative<proto::Stop>(body)) {
        RC_ASSERT(!d.robot_moving);
        RC_ASSERT(d.left_pwm == 0);
        RC_ASSERT(d.right_pwm == 0);
      }
    } else {
      RC_ASSERT(r.code == ResultCode::nack);
    }
  }
}

/// Rule: the link moves only along the documented edges, and each timed
/// edge at its time: RECONNECTING 0.5 s after DEGRADED, the next reopen
/// 1, 2, 4 s after each failure, OPEN again only on an ACK to the PING sent
/// on the reopened port, nothing but that PING while reconnecting.
void check_link_states(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
  const ClientConfig& config = rig.session->core().config();
  static const std::set<std::pair<ConnectionState, ConnectionState>> edges = {
      {ConnectionState::disconnected, ConnectionState::connecting},
      {ConnectionState::connecting, ConnectionState::connected},
      {ConnectionState::connecting, ConnectionState::down},
      {ConnectionState::connected, ConnectionState::degraded},
      {ConnectionState::degraded, ConnectionState::reconnecting},
      {ConnectionState::reconnecting, ConnectionState::connected},
      {ConnectionState::reconnecting, ConnectionState::down},
      {ConnectionState::down, ConnectionState::connecting}};
  ConnectionState s = ConnectionState::disconnected;
  for (std::size_t i = 0; i < rig.links.size(); ++i) {
    const LinkChanged& l = rig.links[i];
    RC_ASSERT(l.from == s);
    RC_ASSERT(l.to == ConnectionState::disconnected || edges.count({l.from, l.to}) == 1);
    s = l.to;
    if (l.to == ConnectionState::reconnecting) {
      RC_ASSERT(i > 0);
      RC_ASSERT(rig.links[i - 1].to == ConnectionState::degraded);
      RC_ASSERT(l.at == rig.links[i - 1].at + config.reconnect_base_delay);
    }
    if (l.to == ConnectionState::connected && l.from == ConnectionState::reconnecting) {
      // The last frame in before it: the ACK to a PING sent while reconnecting.
      const WireFrame* ack = nullptr;
      for (const auto& f : wire) {
        if (f.at > l.at) break;
        if (!f.tx && f.message && std::holds_alternative<proto::Ack>(f.message->body)) ack = &f;
      }
      RC_ASSERT((ack != nullptr));
      RC_ASSERT(ack->at == l.at);
    }
  }
  const auto exchanges = check_attempt_times(rig, wire);
  // OPEN degrades only in the instant a request or the health check ran out
  // of attempts or the port closed under it; and every request that ran out
  // of attempts degrades it then.
  for (std::size_t i = 0; i < rig.links.size(); ++i) {
    const LinkChanged& l = rig.links[i];
    if (l.from != ConnectionState::connected || l.to != ConnectionState::degraded) continue;
    const bool request_timed_out = std::any_of(
        rig.done.begin(), rig.done.end(),
        [&](const auto& d) { return d.at == l.at && d.result.code == ResultCode::timeout; });
    const bool health_check_timed_out =
        std::any_of(exchanges.begin(), exchanges.end(), [&](const Exchange& x) {
          return !x.reconnect_check && x.retries == config.max_retries &&
                 std::holds_alternative<proto::Ping>(wire[x.first].message->body) &&
                 wire[x.sends.back()].at +
                         config.base_timeout * (std::int64_t{1} << config.max_retries) ==
                     l.at;
        });
    // Turned away: the count went up since the last change before this instant.
    std::uint64_t turned_away_before = 0;
    for (std::size_t j = 0; j < i && rig.links[j].at < l.at; ++j)
      turned_away_before = rig.turned_away[j];
    const bool port_closed = std::count(rig.closes.begin(), rig.closes.end(), l.at) != 0 ||
                             rig.turned_away[i] > turned_away_before;
    RC_ASSERT(request_timed_out || health_check_timed_out || port_closed);
  }
  for (const auto& d : rig.done) {
    if (d.result.code != ResultCode::timeout) continue;
    RC_ASSERT(std::any_of(rig.links.begin(), rig.links.end(), [&](const LinkChanged& l) {
      return l.at == d.at && l.to == ConnectionState::degraded;
    }));
  }
  // Reopen attempts: within one DEGRADED series the next attempt's PING goes
  // out 0.5 s x 2^failures after the previous attempt failed (timed exactly
  // when it failed by its full timeout, not by the port closing), and DOWN
  // comes with the max_reconnect_attempts-th failure.
  std::optional<std::size_t> series;
  int failures = 0;
  std::optional<Time> failed_at;
  std::map<std::size_t, int> failures_of_series;
  for (const auto& x : exchanges) {
    if (!x.reconnect_check) continue;
    const Time began = wire[x.first].at;
    std::optional<std::size_t> s_now;
    for (std::size_t i = 0; i < rig.links.size() && rig.links[i].at <= began; ++i) {
      if (rig.links[i].to == ConnectionState::degraded) s_now = i;
    }
    RC_ASSERT(s_now.has_value());
    if (s_now != series) {
      series = s_now;
      failures = 0;
      failed_at.reset();
    }
    if (failed_at) {
      RC_ASSERT(began == *failed_at + config.reconnect_base_delay * (std::int64_t{1} << failures));
    }
    const Time timeout_end =
        wire[x.sends.back()].at + config.base_timeout * (std::int64_t{1} << x.retries);
    bool opened = false;
    for (const auto& l : rig.links) {
      if (l.from == ConnectionState::reconnecting && l.to == ConnectionState::connected &&
          l.at >= began && l.at <= timeout_end)
        opened = true;
    }
    bool closed_early = false;
    for (Time t : rig.closes) {
      if (t >= began && t < timeout_end) closed_early = true;  // not its own close at the end
    }
    if (opened) {
      failures = 0;
      failed_at.reset();
    } else {
      ++failures;
      failed_at.reset();
      // Timed only when it ran its full course: a port closed under it (or
      // turned away as it opened) ends it sooner.
      if (!closed_early && x.retries == config.reconnect_ping_retries) failed_at = timeout_end;
    }
    failures_of_series[*series] = failures;
  }
  for (std::size_t i = 0; i < rig.links.size(); ++i) {
    const LinkChanged& l = rig.links[i];
    if (l.from != ConnectionState::reconnecting || l.to != ConnectionState::down) continue;
    std::optional<std::size_t> s_down;
    for (std::size_t j = 0; j < i; ++j) {
      if (rig.links[j].to == ConnectionState::degraded) s_down = j;
    }
    RC_ASSERT(s_down.has_value());
    RC_ASSERT(failures_of_series[*s_down] == config.max_reconnect_attempts);
  }
}

/// Rule: requests are served one at a time, in the order they were made;
/// each ends exactly once.
void check_order(const ArduinoRig& rig) {
  std::set<RequestId> seen;
  std::vector<RequestId> queued_done;
  const std::set<RequestId> queued(rig.queued.begin(), rig.queued.end());
  for (const auto& d : rig.done) {
    RC_ASSERT(seen.insert(d.id).second);
    if (queued.count(d.id) != 0) queued_done.push_back(d.id);
  }
  RC_ASSERT(queued_done == rig.queued);
}

/// The run as text, shown with a failing case.
std::string dump(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
  std::string out;
  auto ms = [](Time t) { return std::to_string(static_cast<double>(t.count()) / 1e6); };
  for (const auto& f : wire)
    out += ms(f.at) + (f.tx ? " TX " : " RX ") + f.raw + (f.message ? "" : " (does not decode)") +
           "\n";
  for (const auto& l : rig.links)
    out += ms(l.at) + " LINK " + std::string(link_name(l.to)) + " (" + l.reason + ")\n";
  for (const auto& d : rig.done) {
    out += ms(d.at) + " DONE #" + std::to_string(d.id) + " " +
           proto::describe({0, rig.bodies.at(d.id)}) + " -> " +
           std::string(to_string(d.result.code)) + " " + d.result.info +
           " seq=" + (d.result.seq ? std::to_string(*d.result.seq) : std::string("-")) + "\n";
  }
  for (Time t : rig.closes)
    out += ms(t) + " CAR LINK CLOSED\n";
  return out;
}

// ---- the stateful test: the operator, the robot's misbehaviour, time ----

struct OperatorModel {
  bool closed = false;  ///< the operator closed the port and has not opened it again
};

using ArduinoCommand = rc::state::Command<OperatorModel, ArduinoRig>;

struct Submit : ArduinoCommand {
  proto::Body body = *gen_request();
  void apply(OperatorModel&) const override {}
  void run(const OperatorModel& model, ArduinoRig& rig) const override {
    const std::size_t before = rig.done.size();
    const ConnectionState state = rig.session->state();
    const RequestId id = rig.session->request(body);
    rig.bodies[id] = body;
    const bool ended_at_once = rig.done.size() > before && rig.done.back().id == id;
    if (!is_valid_request(body)) {
      RC_ASSERT(ended_at_once);
      RC_ASSERT(rig.done.back().result.code == ResultCode::invalid_request);
    } else if (model.closed || state == ConnectionState::down) {
      // A closed or DOWN link takes no request; it says so at once.
      RC_ASSERT(ended_at_once);
      RC_ASSERT(rig.done.back().result.code == ResultCode::link_down);
    } else {
      RC_ASSERT(!ended_at_once);
      rig.queued.push_back(id);
    }
  }
  void show(std::ostream& os) const override { os << "request " << proto::describe({0, body}); }
};

using Advance = hil::test::AdvanceTime<ArduinoCommand, OperatorModel, ArduinoRig, 4000>;

struct CarMisbehaves : ArduinoCommand {
  int kind = *rc::gen::inRange(0, 4);
  int ms = *rc::gen::inRange(100, 30'000);
  void apply(OperatorModel&) const override {}
  using Kind = hil::test::Misbehaviour;
  static constexpr Kind kKinds[] = {Kind::ignore_all, Kind::reject_next, Kind::hang_up,
                                    Kind::reset};
  void run(const OperatorModel&, ArduinoRig& rig) const override {
    rig.car.firmware->arm(hil::test::misbehaviour(kKinds[kind], milliseconds(ms)));
  }
  void show(std::ostream& os) const override {
    static const char* names[] = {"ignores everything for", "rejects the next request", "hangs up",
                                  "resets the connection"};
    os << "robot " << names[kind];
    if (hil::test::lasts(kKinds[kind])) os << " " << ms << " ms";
  }
};

struct OperatorToggles : ArduinoCommand {
  bool close = *rc::gen::weightedElement<bool>({{1, true}, {2, false}});
  void apply(OperatorModel& model) const override { model.closed = close; }
  void run(const OperatorModel& model, ArduinoRig& rig) const override {
    const ConnectionState before = rig.session->state();
    if (close) {
      const std::size_t done_before = rig.done.size();
      const std::size_t waiting = [&] {
        std::set<RequestId> ended;
        for (const auto& d : rig.done)
          ended.insert(d.id);
        return static_cast<std::size_t>(std::count_if(
            rig.queued.begin(), rig.queued.end(), [&](RequestId id) { return !ended.count(id); }));
      }();
      rig.session->close();
      RC_ASSERT(rig.session->state() == ConnectionState::disconnected);
      // Everything still waiting ends link_down, at once.
      RC_ASSERT(rig.done.size() == done_before + waiting);
      for (std::size_t i = done_before; i < rig.done.size(); ++i)
        RC_ASSERT(rig.done[i].result.code == ResultCode::link_down);
    } else {
      rig.operator_opens.push_back(rig.now());
      rig.logged_at_operator_open.push_back(rig.session->log().entries().size());
      rig.session->open();
      rig.car.executor.run_for(Duration::zero());
      if (model.closed || before == ConnectionState::down) {
        // A mem:// port always opens; a robot still busy with the port the
        // operator closed in this very instant may hang up on it at once.
        const ConnectionState now = rig.session->state();
        RC_ASSERT(now == ConnectionState::connected || now == ConnectionState::degraded);
      }
    }
  }
  void show(std::ostream& os) const override { os << "operator " << (close ? "closes" : "opens"); }
};

/// A random session: a random fault schedule, then random operator
/// requests, waits, robot misbehaviour, closes and opens (each command
/// checks what the operator sees at once), then a minute for every retry,
/// reconnect and timeout to play out; `check` reads the whole run.
template <class Check>
void after_a_random_session(Check check) {
  ArduinoRig rig(*gen_faults());
  rc::state::check(OperatorModel{}, rig,
                   rc::state::gen::execOneOfWithArgs<Submit, Submit, Submit, Advance, Advance,
                                                     Advance, CarMisbehaves, OperatorToggles>());
  rig.car.executor.run_for(seconds(60));
  const auto wire = wire_of(rig);
  RC_LOG() << dump(rig, wire);
  check(rig, wire);
}

RC_GTEST_PROP(ArduinoClientProperties,
              AnAnswerIsTakenOnlyForTheRequestWithItsSeqAndSaysWhatTheRobotSaid, ()) {
  after_a_random_session([](const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
    check_results(rig, wire, check_attempt_times(rig, wire), ResultRules::answers);
  });
}

RC_GTEST_PROP(ArduinoClientProperties,
              EveryRetryComesOnItsDoubledTimeoutEveryBadCsResendAtOnceAndATimeoutAtTheSum, ()) {
  after_a_random_session([](const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
    check_results(rig, wire, check_attempt_times(rig, wire), ResultRules::attempts);
  });
}

RC_GTEST_PROP(ArduinoClientProperties,
              TheLinkMovesAlongItsStateMachineOnTimeAndAReopenedPortGetsOnlyItsProvingPing, ()) {
  after_a_random_session(check_link_states);
}

RC_GTEST_PROP(ArduinoClientProperties, RequestsAreServedOneAtATimeInOrderAndEachEndsExactlyOnce,
              ()) {
  after_a_random_session(
      [](const ArduinoRig& rig, const std::vector<WireFrame>&) { check_order(rig); });
}

RC_GTEST_PROP(ArduinoClientProperties, OnACleanLinkEveryRequestIsAnsweredOnceAndTheLinkStaysOpen,
              ()) {
  ArduinoRig rig(link::FaultProfile{});
  const auto requests = *rc::gen::container<std::vector<proto::Body>>(gen_request());
  for (const auto& body : requests) {
    const RequestId id = rig.session->request(body);
    rig.bodies[id] = body;
    if (is_valid_request(body)) rig.queued.push_back(id);
    rig.car.executor.run_for(milliseconds(*rc::gen::inRange(0, 300)));
  }
  rig.car.executor.run_for(seconds(20));
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

}  // namespace
}  // namespace hil::client::arduino
