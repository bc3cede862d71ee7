// Properties of the WR8 reference client (docs/clients/wr8.md) against the
// mock WR8 vehicle on mem:// in virtual time, under a random fault schedule
// and a random operator session (connects, disconnects, tasks, settings,
// bursts that carry the COI counter across its wrap, the vehicle refusing,
// ignoring, muting DATA or hanging up), physics included. Each rule is
// checked on the whole run: the client's events, what the client wrote and
// what reached it on every connection (a tap on the mock server's links),
// and the simulated car.
//
// Each property was seen to fail with its rule broken on purpose in a copy
// of client/wr8/core.cpp (never in this tree), then the copy was thrown
// away; 300 sessions per property found each of these:
//   - a TASK allowed while authenticating, the next COI taken without
//     skipping open ones: every session property (the submit check), and
//     NothingButAuthGoesOutBeforeTheLoginOnEveryConnection for the first;
//   - a RESPONSE for no open COI credited to the oldest open request, the
//     answer timeout 1000 ms instead of 500:
//     EveryAnswerMatchesItsOpenRequestByCoiAcrossTheWrap...;
//   - the reconnect series not started again by a login:
//     ReconnectsBackOff1248SAndALoginWithoutReplyFailsAtExactly2S;
//   - the stale timer not restarted by each DATA:
//     DataIsTakenAsSentAndGoesStaleExactly500MsAfterTheLast and
//     OnACleanLinkEveryTaskEndsWithTheVehiclesAnswer.
// The bugs of tests/property/wr8_planted_bug.hpp are planted in the client
// as built (its core's protected rule functions) by Wr8PlantedBugs at the
// end of this file, which shows that the property named for each catches
// it from a fixed seed and passes on the same sessions without it.
// RC_PARAMS="seed=..." printed with a failure replays it.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <rapidcheck/state.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "client/wr8/session.hpp"
#include "link/executor.hpp"
#include "link/faults/profile.hpp"
#include "link/link.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8.hpp"
#include "protocol/wr8/codec.hpp"
#include "sim/presets.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/property/planted_check.hpp"
#include "tests/property/random_faults.hpp"
#include "tests/property/session_commands.hpp"
#include "tests/property/wr8_planted_bug.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;

/// One connection as the mock server's link saw it.
struct Connection {
  Time opened{0};
  std::optional<Time> closed;
  std::vector<std::pair<Time, proto::Message>> from_client;  ///< as written, before faults
  std::vector<std::pair<Time, proto::Message>> to_client;    ///< as delivered, after faults
  proto::Decoder client_bytes{{proto::Profile{}, proto::Sender::gui}};
  proto::Decoder car_bytes{{proto::Profile{}, proto::Sender::vehicle}};
  bool undecodable = false;
};

/// Taps every link of the mock server: what the client wrote, what reached it.
struct Tap : link::LinkObserver {
  explicit Tap(std::vector<Connection>& out) : out_(out) {}
  void on_open(Time at, const std::string&, const std::string&) override {
    out_.emplace_back();
    out_.back().opened = at;
  }
  void on_sent(Time at, link::Direction d, protocol::ByteView bytes) override {
    if (d == link::Direction::to_car)
      feed(at, out_.back().client_bytes, bytes, out_.back().from_client);
  }
  void on_delivered(Time at, link::Direction d, protocol::ByteView bytes) override {
    if (d == link::Direction::to_client)
      feed(at, out_.back().car_bytes, bytes, out_.back().to_client);
  }
  void on_close(Time at, const link::LinkClose&) override {
    if (!out_.back().closed) out_.back().closed = at;
  }

 private:
  void feed(Time at, proto::Decoder& decoder, protocol::ByteView bytes,
            std::vector<std::pair<Time, proto::Message>>& into) {
    items_.clear();
    decoder.feed(bytes, items_);
    for (auto& item : items_) {
      if (auto* f = std::get_if<protocol::Frame<proto::Message>>(&item)) {
        into.emplace_back(at, f->message);
      } else {
        out_.back().undecodable = true;
      }
    }
  }
  std::vector<Connection>& out_;
  std::vector<proto::Item> items_;
};

enum class OperatorAct : std::uint8_t { connect, disconnect };

struct Wr8Rig {
  /// The client is hil's, with `bug` planted in its core (none: as shipped).
  explicit Wr8Rig(link::FaultProfile faults, prop::PlantedBug bug = prop::PlantedBug::none) {
    mocks::ServerOptions options = test::on_mem("wr8");
    options.faults = std::move(faults);
    options.observers.push_back(std::make_shared<Tap>(connections));
    car.start_car(sim::wr8_vehicle(), std::move(options), mocks::Wr8Config{});
    session = std::make_unique<Wr8Session>(
        car.context, std::make_unique<prop::PlantedBugCore>(bug, ClientConfig{}),
        link::MemEndpoint{"wr8"}, [this](Time now, const Event& e) {
          events.emplace_back(now, e);
          if (const auto* r = std::get_if<RequestEvent>(&e)) {
            if (r->state == RequestState::sent) {
              open_cois.insert(r->coi);
            } else if (r->state != RequestState::started) {
              open_cois.erase(r->coi);
            }
            odometry_at[{r->coi, r->state, now}] = car.firmware->vehicle().odometry().distance_m;
          }
        });
  }

  Time now() const { return car.executor.now(); }
  const Wr8ClientCore& core() const { return session->core(); }

  template <class E>
  std::vector<std::pair<Time, E>> of() const {
    return test::timed_events_of<E>(events);
  }

  // The records come first: the car and the session report into them until
  // they are gone.
  std::vector<Connection> connections;
  std::vector<std::pair<Time, Event>> events;
  std::vector<std::pair<Time, OperatorAct>> acts;
  /// Each request: when it was submitted, its COI, what it asked.
  struct Submitted {
    Time at{0};
    std::uint8_t coi = 0;
    proto::Message message;
  };
  std::vector<Submitted> submitted;
  std::map<std::tuple<std::uint8_t, RequestState, Time>, double> odometry_at;
  std::uint8_t last_coi = 0xFF;      ///< so the first request takes COI 00
  std::set<std::uint8_t> open_cois;  ///< as the client's events tell
  test::VirtualCar<mocks::Wr8Firmware> car;
  std::unique_ptr<Wr8Session> session;
};

/// Whether a connection open at `t` saw a packet at `t` that `pred` accepts
/// (two connections share the instant one closes and the next opens).
template <class Pred>
bool seen_at(const Wr8Rig& rig, Time t, bool from_client, Pred pred) {
  for (const auto& c : rig.connections) {
    if (c.opened > t || (c.closed && *c.closed < t)) continue;
    const auto& packets = from_client ? c.from_client : c.to_client;
    for (const auto& [when, m] : packets) {
      if (when == t && pred(m)) return true;
    }
  }
  return false;
}

bool operator_acted_between(const Wr8Rig& rig, Time from, Time to) {
  return std::any_of(rig.acts.begin(), rig.acts.end(),
                     [&](const auto& a) { return a.first >= from && a.first <= to; });
}

/// Rule: on every connection the client's first packet is AUTH with the
/// profile's string, and it writes nothing else until that connection's
/// AUTH-REPLY has reached it (logins happen only on an AUTH-REPLY).
void check_login_first(const Wr8Rig& rig) {
  const auto logins = rig.of<LoginEvent>();
  for (const auto& c : rig.connections) {
    RC_ASSERT(!c.undecodable);
    if (c.from_client.empty()) continue;
    const auto* auth = std::get_if<proto::Auth>(&c.from_client.front().second);
    RC_ASSERT((auth != nullptr));
    RC_ASSERT(auth->text == rig.core().config().profile.auth_text);
    std::optional<Time> login;
    for (const auto& [t, l] : logins) {
      if (t >= c.opened && (!c.closed || t <= *c.closed)) {
        login = t;
        break;
      }
    }
    for (const auto& [t, m] : c.from_client) {
      if (std::holds_alternative<proto::Auth>(m)) continue;
      RC_ASSERT(login.has_value());
      RC_ASSERT(*login <= t);
    }
  }
  for (const auto& [t, l] : logins) {
    RC_ASSERT(seen_at(rig, t, false, [](const proto::Message& m) {
      return std::holds_alternative<proto::AuthReply>(m);
    }));
  }
}

/// Rule: a COI's life is sent, [started], then one end; a RESPONSE is
/// taken only for the open request with its COI, at the instant it
/// arrived, with its code; a late or unknown answer changes nothing; the
/// first answer is due 500 ms after the send, the end the task's
/// completion time after `started` (or after a get-settings' SETTINGS),
/// and a timeout comes at exactly that instant.
void check_coi_correlation(const Wr8Rig& rig) {
  const ClientConfig& config = rig.core().config();
  struct Open {
    RequestEvent sent;
    Time deadline{0};
    bool started = false;
  };
  std::map<std::uint8_t, Open> open;
  std::map<std::uint8_t, std::size_t> submitted_index;
  std::size_t next_submitted = 0;
  for (const auto& [t, e] : rig.events) {
    if (const auto* s = std::get_if<SettingsEvent>(&e)) {
      auto it = open.find(s->coi);
      RC_ASSERT(it != open.end());
      RC_ASSERT(it->second.sent.task == proto::TaskCode::get_settings);
      if (!it->second.started) {
        it->second.started = true;
        it->second.deadline =
            t + config.completion_timeout[static_cast<std::size_t>(proto::TaskCode::get_settings)];
      }
      continue;
    }
    const auto* r = std::get_if<RequestEvent>(&e);
    if (r == nullptr) continue;
    if (r->state == RequestState::sent) {
      RC_ASSERT(open.count(r->coi) == 0);
      // The request that was submitted, written in that instant under this COI.
      RC_ASSERT(next_submitted < rig.submitted.size());
      const auto& sub = rig.submitted[next_submitted++];
      RC_ASSERT(sub.at == t);
      RC_ASSERT(sub.coi == r->coi);
      RC_ASSERT(seen_at(rig, t, true, [&](const proto::Message& m) { return m == sub.message; }));
      open[r->coi] = Open{*r, t + config.answer_timeout, false};
      continue;
    }
    auto it = open.find(r->coi);
    RC_ASSERT(it != open.end());  // never an event for a COI that is not open
    Open& o = it->second;
    RC_ASSERT(r->kind == o.sent.kind);
    RC_ASSERT(r->task == o.sent.task);
    auto delivered = [&, t = t](proto::ResponseCode code) {
      return seen_at(rig, t, false, [&](const proto::Message& m) {
        return m == proto::Message{proto::Response{r->coi, code}};
      });
    };
    switch (r->state) {
      case RequestState::started:
        RC_ASSERT(!o.started);
        RC_ASSERT(t <= o.deadline);
        RC_ASSERT(delivered(proto::ResponseCode::started));
        o.started = true;
        o.deadline = t + (o.sent.kind == RequestKind::task
                              ? config.completion_timeout[static_cast<std::size_t>(o.sent.task)]
                              : config.answer_timeout);
        break;
      case RequestState::completed:
        RC_ASSERT(t <= o.deadline);
        RC_ASSERT(delivered(proto::ResponseCode::completed));
        open.erase(it);
        break;
      case RequestState::error:
        RC_ASSERT(t <= o.deadline);
        RC_ASSERT(delivered(proto::ResponseCode::error));
        open.erase(it);
        break;
      case RequestState::timed_out:
        RC_ASSERT(t == o.deadline);
        open.erase(it);
        break;
      case RequestState::cancelled:
        open.erase(it);
        break;
      case RequestState::sent:
        break;
    }
  }
  RC_ASSERT(next_submitted == rig.submitted.size());
}

/// Rule: a drop (or the operator's disconnect) cancels every open request
/// in that instant; nothing is cancelled otherwise.
void check_cancellations(const Wr8Rig& rig) {
  std::set<Time> lost;
  for (const auto& [t, c] : rig.of<ConnectionEvent>()) {
    if (c.state == ConnectionState::reconnecting || c.state == ConnectionState::disconnected)
      lost.insert(t);
  }
  for (const auto& [t, r] : rig.of<RequestEvent>()) {
    if (r.state == RequestState::cancelled) RC_ASSERT(lost.count(t) == 1);
  }
}

/// Rule: DATA is taken only on a logged-in connection, as the vehicle sent
/// it; without DATA for 500 ms the stale flag is raised at exactly that
/// moment, and the next DATA clears it.
void check_data_stream(const Wr8Rig& rig) {
  const ClientConfig& config = rig.core().config();
  std::optional<Time> last_data;  // since the last login
  bool stale = false;
  ConnectionState state = ConnectionState::disconnected;  // as the events so far tell
  for (const auto& [t, e] : rig.events) {
    if (const auto* c = std::get_if<ConnectionEvent>(&e)) state = c->state;
    if (std::holds_alternative<LoginEvent>(e)) last_data.reset();
    if (const auto* tel = std::get_if<TelemetryEvent>(&e)) {
      RC_ASSERT(state == ConnectionState::connected);
      RC_ASSERT(seen_at(rig, t, false, [&](const proto::Message& m) {
        const auto* d = std::get_if<proto::Data>(&m);
        return d != nullptr && d->timestamp_ms == tel->live.timestamp_ms &&
               d->state == tel->live.state;
      }));
      RC_ASSERT(tel->live.received == t);
      if (last_data && !stale && t - *last_data > config.stale_after) {
        // Still logged in throughout: the flag must have gone up in between.
        RC_ASSERT(false);
      }
      last_data = t;
    }
    if (const auto* s = std::get_if<StaleEvent>(&e)) {
      RC_ASSERT(s->stale != stale);
      if (s->stale) {
        RC_ASSERT(last_data.has_value());
        RC_ASSERT(t == *last_data + config.stale_after);
      } else {
        RC_ASSERT(last_data == std::optional<Time>(t));  // cleared by the DATA of that instant
      }
      stale = s->stale;
    }
  }
}

/// Rule: after a failed connection or a drop the next attempt comes 1, 2,
/// 4, then every 8 s after it, the series starting again with each login;
/// no AUTH-REPLY within 2 s of the connection opening fails it at exactly
/// 2 s; the operator's disconnect stops all of it.
void check_reconnects(const Wr8Rig& rig) {
  const ClientConfig& config = rig.core().config();
  const auto changes = rig.of<ConnectionEvent>();
  int failures = 0;
  std::optional<Time> authenticating_since;
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const auto& [t, c] = changes[i];
    if (c.state == ConnectionState::connected) failures = 0;
    if (c.state == ConnectionState::authenticating) authenticating_since = t;
    if (c.state == ConnectionState::reconnecting) {
      ++failures;
      RC_ASSERT(c.attempt == failures);
      if (i + 1 < changes.size() && changes[i + 1].second.state == ConnectionState::connecting) {
        const Time next = changes[i + 1].first;
        if (!operator_acted_between(rig, t, next)) {
          const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(failures - 1),
                                                      config.reconnect_delays.size() - 1);
          RC_ASSERT(next == t + config.reconnect_delays[k]);
          RC_ASSERT(changes[i + 1].second.attempt == failures);
        }
      }
    }
    if (c.state == ConnectionState::disconnected) failures = 0;
  }
  for (const auto& [t, f] : rig.of<LoginFailedEvent>()) {
    if (f.reason == "AUTH-REPLY timeout") {
      RC_ASSERT(authenticating_since.has_value());
      const auto since = [&, t = t] {
        std::optional<Time> s;
        for (const auto& [when, c] : changes) {
          if (when > t) break;
          if (c.state == ConnectionState::authenticating) s = when;
        }
        return s;
      }();
      RC_ASSERT(since.has_value());
      RC_ASSERT(t == *since + config.auth_timeout);
    }
  }
  // Between the operator's disconnect and the next connect nothing reconnects.
  for (std::size_t a = 0; a < rig.acts.size(); ++a) {
    if (rig.acts[a].second != OperatorAct::disconnect) continue;
    const Time from = rig.acts[a].first;
    const Time to = a + 1 < rig.acts.size() ? rig.acts[a + 1].first : rig.now() + seconds(1);
    for (const auto& [t, c] : changes) {
      if (t > from && t < to) RC_ASSERT(c.state != ConnectionState::connecting);
    }
  }
}

/// Physics: a drive reported completed has moved the car by at least its
/// distance between the send and the report.
void check_drives(const Wr8Rig& rig) {
  std::map<std::uint8_t, std::pair<double, double>> open;  // coi -> (odometry at send, target m)
  std::size_t next = 0;
  for (const auto& [t, r] : rig.of<RequestEvent>()) {
    if (r.state == RequestState::sent) {
      const auto& s = rig.submitted[next++];
      const auto* task = std::get_if<proto::Task>(&s.message);
      if (task != nullptr && task->task == proto::TaskCode::drive) {
        open[r.coi] = {rig.odometry_at.at({r.coi, r.state, t}), task->params[0].as_i32() / 100.0};
      }
      continue;
    }
    if (r.task != proto::TaskCode::drive || r.kind != RequestKind::task) continue;
    auto it = open.find(r.coi);
    if (it == open.end()) continue;
    if (r.state == RequestState::completed) {
      const double moved = rig.odometry_at.at({r.coi, r.state, t}) - it->second.first;
      RC_ASSERT(moved >= it->second.second - 1e-9);
    }
    if (r.state != RequestState::started) open.erase(it);
  }
}

/// The run as text, shown with a failing case.
std::string dump(const Wr8Rig& rig) {
  std::string out;
  auto ms = [](Time t) { return std::to_string(static_cast<double>(t.count()) / 1e6); };
  const proto::Profile profile;
  for (std::size_t i = 0; i < rig.connections.size(); ++i) {
    const auto& c = rig.connections[i];
    out += "connection " + std::to_string(i) + " opened " + ms(c.opened) +
           (c.closed ? " closed " + ms(*c.closed) : std::string()) + "\n";
    for (const auto& [t, m] : c.from_client)
      out += "  " + ms(t) + " client wrote " + proto::describe(m, profile) + "\n";
    for (const auto& [t, m] : c.to_client) {
      if (!std::holds_alternative<proto::Data>(m))
        out += "  " + ms(t) + " client got " + proto::describe(m, profile) + "\n";
    }
  }
  for (const auto& e : rig.core().log()->entries()) {
    if (e.kind != LogKind::rx || e.description.rfind("Data", 0) != 0)
      out += ms(e.at) + " " + std::string(to_string(e.kind)) + " " + e.description + "\n";
  }
  return out;
}

void check_all(const Wr8Rig& rig) {
  RC_LOG() << dump(rig);
  check_login_first(rig);
  check_coi_correlation(rig);
  check_cancellations(rig);
  check_data_stream(rig);
  check_reconnects(rig);
  check_drives(rig);
}

// ---- the stateful test ----

struct OperatorModel {
  bool want_connected = false;
};

using Wr8Command = rc::state::Command<OperatorModel, Wr8Rig>;

/// Submits through the session and checks what the core answered: refused
/// before login, else the next free COI after the last one used, or busy
/// when all 256 are open.
void submit(Wr8Rig& rig, const proto::Message& message) {
  const bool connected = rig.core().state() == ConnectionState::connected;
  const std::set<std::uint8_t> open_cois = rig.open_cois;
  const std::uint64_t log_before = rig.core().log()->total();
  SubmitResult result;
  if (const auto* task = std::get_if<proto::Task>(&message)) {
    result = rig.session->task(task->task, task->params);
  } else {
    result = rig.session->set_settings(std::get<proto::Settings>(message).params);
  }
  if (!connected) {
    RC_ASSERT(result.refusal == Refusal::not_connected);
    RC_ASSERT(rig.core().log()->total() == log_before);  // nothing written
    return;
  }
  if (open_cois.size() == 256) {
    RC_ASSERT(result.refusal == Refusal::busy);
    return;
  }
  RC_ASSERT(result.refusal == Refusal::none);
  auto expected = static_cast<std::uint8_t>(rig.last_coi + 1);
  while (open_cois.count(expected) != 0)
    expected = static_cast<std::uint8_t>(expected + 1);
  RC_ASSERT(result.coi == expected);
  rig.last_coi = result.coi;
  proto::Message sent = message;
  if (auto* t = std::get_if<proto::Task>(&sent)) t->coi = result.coi;
  if (auto* s = std::get_if<proto::Settings>(&sent)) s->coi = result.coi;
  rig.submitted.push_back({rig.now(), result.coi, sent});
}

rc::Gen<proto::Task> gen_task() {
  return rc::gen::oneOf(
      rc::gen::just(proto::Task{0, proto::TaskCode::check, {}}),
      rc::gen::map(rc::gen::inRange(1, 200),
                   [](int cm) {
                     return proto::Task{0, proto::TaskCode::drive, {proto::Word::from_i32(cm)}};
                   }),
      rc::gen::map(rc::gen::inRange(-25, 26),
                   [](int deg) {
                     return proto::Task{0, proto::TaskCode::turn, {proto::Word::from_i32(deg)}};
                   }),
      rc::gen::just(proto::Task{0, proto::TaskCode::blink, {}}),
      rc::gen::just(proto::Task{0, proto::TaskCode::get_settings, {}}));
}

struct SubmitTask : Wr8Command {
  proto::Task task = *gen_task();
  void apply(OperatorModel&) const override {}
  void run(const OperatorModel&, Wr8Rig& rig) const override { submit(rig, task); }
  void show(std::ostream& os) const override {
    os << "task " << proto::describe(proto::Message{task}, proto::Profile{});
  }
};

struct SubmitSettings : Wr8Command {
  void apply(OperatorModel&) const override {}
  void run(const OperatorModel&, Wr8Rig& rig) const override {
    // The settings in force: always acceptable to the vehicle.
    submit(rig, proto::Settings{0, rig.car.firmware->state().settings});
  }
  void show(std::ostream& os) const override { os << "settings (the ones in force)"; }
};

/// Many checks at once: carries the COI counter round its wrap.
struct Burst : Wr8Command {
  int count = *rc::gen::inRange(1, 300);
  void apply(OperatorModel&) const override {}
  void run(const OperatorModel&, Wr8Rig& rig) const override {
    for (int i = 0; i < count; ++i)
      submit(rig, proto::Task{0, proto::TaskCode::check, {}});
  }
  void show(std::ostream& os) const override { os << count << " checks at once"; }
};

using Advance = hil::test::AdvanceTime<Wr8Command, OperatorModel, Wr8Rig, 5000>;

std::size_t attempts(const Wr8Rig& rig) {
  std::size_t n = 0;
  for (const auto& [t, c] : rig.of<ConnectionEvent>())
    n += c.state == ConnectionState::connecting ? 1 : 0;
  return n;
}

struct Connect : Wr8Command {
  void checkPreconditions(const OperatorModel& m) const override { RC_PRE(!m.want_connected); }
  void apply(OperatorModel& m) const override { m.want_connected = true; }
  void run(const OperatorModel& model, Wr8Rig& rig) const override {
    const ConnectionState before = rig.core().state();
    const std::size_t attempts_before = attempts(rig);
    rig.acts.emplace_back(rig.now(), OperatorAct::connect);
    rig.session->connect();
    (void)model;
    // At once, from disconnected.
    RC_ASSERT(before == ConnectionState::disconnected);
    RC_ASSERT(attempts(rig) == attempts_before + 1);
  }
  void show(std::ostream& os) const override { os << "connect"; }
};

struct Disconnect : Wr8Command {
  void checkPreconditions(const OperatorModel& m) const override { RC_PRE(m.want_connected); }
  void apply(OperatorModel& m) const override { m.want_connected = false; }
  void run(const OperatorModel&, Wr8Rig& rig) const override {
    rig.acts.emplace_back(rig.now(), OperatorAct::disconnect);
    rig.session->disconnect();
    RC_ASSERT(rig.core().state() == ConnectionState::disconnected);
    RC_ASSERT(rig.core().open_requests() == 0u);
  }
  void show(std::ostream& os) const override { os << "disconnect"; }
};

struct CarMisbehaves : Wr8Command {
  int kind = *rc::gen::inRange(0, 5);
  int ms = *rc::gen::inRange(100, 6000);
  void apply(OperatorModel&) const override {}
  using Kind = hil::test::Misbehaviour;
  static constexpr Kind kKinds[] = {Kind::ignore_all, Kind::reject_next, Kind::mute_telemetry,
                                    Kind::hang_up, Kind::reset};
  void run(const OperatorModel&, Wr8Rig& rig) const override {
    rig.car.firmware->arm(hil::test::misbehaviour(kKinds[kind], milliseconds(ms)));
  }
  void show(std::ostream& os) const override {
    static const char* names[] = {"ignores everything for", "rejects the next command",
                                  "mutes DATA for", "hangs up", "resets the connection"};
    os << "vehicle " << names[kind];
    if (hil::test::lasts(kKinds[kind])) os << " " << ms << " ms";
  }
};

/// A random session: a random fault schedule, a connect, then random
/// tasks, settings, bursts of checks, waits, vehicle misbehaviour,
/// disconnects and connects (each submit checks the COI or the refusal at
/// once), then 40 s for every answer, timeout and reconnect to play out;
/// `check` reads the whole run.
void after_a_random_session(void (*check)(const Wr8Rig&),
                            prop::PlantedBug bug = prop::PlantedBug::none) {
  // Faults that keep the oracle sound. WR8 packets carry no checksum, so a
  // corrupted COI or code would be a different valid packet that no client
  // can tell from the real one: corruption and byte drops are left out.
  Wr8Rig rig(*hil::test::gen_faults_without_corruption(25, 400, 4000), bug);
  rig.acts.emplace_back(rig.now(), OperatorAct::connect);
  rig.session->connect();
  rc::state::check(
      OperatorModel{true}, rig,
      rc::state::gen::execOneOfWithArgs<SubmitTask, SubmitTask, SubmitTask, SubmitSettings, Burst,
                                        Advance, Advance, Advance, Connect, Connect, Connect,
                                        Disconnect, CarMisbehaves>());
  rig.car.executor.run_for(seconds(40));
  RC_LOG() << dump(rig);
  check(rig);
}

RC_GTEST_PROP(Wr8ClientProperties, NothingButAuthGoesOutBeforeTheLoginOnEveryConnection, ()) {
  after_a_random_session(check_login_first);
}

RC_GTEST_PROP(Wr8ClientProperties,
              EveryAnswerMatchesItsOpenRequestByCoiAcrossTheWrapAndEveryTimeoutComesOnTime, ()) {
  after_a_random_session(check_coi_correlation);
}

RC_GTEST_PROP(Wr8ClientProperties, ADropCancelsEveryOpenRequestInThatInstantAndNothingElseDoes,
              ()) {
  after_a_random_session(check_cancellations);
}

RC_GTEST_PROP(Wr8ClientProperties, DataIsTakenAsSentAndGoesStaleExactly500MsAfterTheLast, ()) {
  after_a_random_session(check_data_stream);
}

RC_GTEST_PROP(Wr8ClientProperties, ReconnectsBackOff1248SAndALoginWithoutReplyFailsAtExactly2S,
              ()) {
  after_a_random_session(check_reconnects);
}

RC_GTEST_PROP(Wr8ClientProperties, ADriveReportedCompletedHasMovedTheCarItsDistance, ()) {
  after_a_random_session(check_drives);
}

RC_GTEST_PROP(Wr8ClientProperties, OnACleanLinkEveryTaskEndsWithTheVehiclesAnswer, ()) {
  Wr8Rig rig(link::FaultProfile{});
  rig.acts.emplace_back(rig.now(), OperatorAct::connect);
  rig.session->connect();
  rig.car.executor.run_for(milliseconds(1));
  RC_ASSERT(rig.core().state() == ConnectionState::connected);
  const auto tasks = *rc::gen::container<std::vector<proto::Task>>(gen_task());
  for (const auto& task : tasks) {
    submit(rig, task);
    rig.car.executor.run_for(milliseconds(*rc::gen::inRange(0, 3000)));
  }
  rig.car.executor.run_for(seconds(40));
  check_all(rig);
  // Nothing lost: every request ended with the vehicle's answer (no
  // timeout, no cancel), no stale DATA, one login.
  std::size_t sent = 0;
  std::size_t answered = 0;
  for (const auto& [t, r] : rig.of<RequestEvent>()) {
    RC_ASSERT(r.state != RequestState::timed_out);
    RC_ASSERT(r.state != RequestState::cancelled);
    sent += r.state == RequestState::sent ? 1 : 0;
    answered += r.state == RequestState::completed || r.state == RequestState::error ? 1 : 0;
  }
  RC_ASSERT(sent == rig.submitted.size());
  RC_ASSERT(answered == sent);
  RC_ASSERT(rig.of<StaleEvent>().empty());
  RC_ASSERT(rig.of<LoginEvent>().size() == 1u);
  RC_ASSERT(rig.connections.size() == 1u);
}

// ---- the properties have teeth ----
// Each bug of tests/property/wr8_planted_bug.hpp, planted in the client on
// its own, makes the property named for it fail within a fixed number of
// random sessions (from one fixed seed, tests/property/planted_check.hpp),
// and the same property passes on the same sessions without the bug.

struct PlantedCase {
  const char* name;
  prop::PlantedBug bug;
  const char* property;
  void (*check)(const Wr8Rig&);
};

rc::detail::TestResult run_planted(const PlantedCase& c, prop::PlantedBug bug, int sessions) {
  return logi::prop::run_planted(c.property, sessions,
                                 [&c, bug] { after_a_random_session(c.check, bug); });
}

// The case's name in CTest's name for it, instead of its bytes.
void PrintTo(const PlantedCase& c, std::ostream* os) {
  *os << c.name;
}

class Wr8PlantedBugs : public ::testing::TestWithParam<PlantedCase> {};

TEST_P(Wr8PlantedBugs, IsCaughtByItsPropertyWhichPassesWithoutIt) {
  const PlantedCase& c = GetParam();
  logi::prop::expect_caught_and_clean(c.property, c.name, [&c](bool planted, int sessions) {
    return run_planted(c, planted ? c.bug : prop::PlantedBug::none, sessions);
  });
}

INSTANTIATE_TEST_SUITE_P(
    Wr8, Wr8PlantedBugs,
    ::testing::Values(
        PlantedCase{"TaskBeforeAuthReply", prop::PlantedBug::task_before_auth,
                    "NothingButAuthGoesOutBeforeTheLoginOnEveryConnection", check_login_first},
        PlantedCase{"NewestTaskAnswer", prop::PlantedBug::newest_task_answer,
                    "EveryAnswerMatchesItsOpenRequestByCoiAcrossTheWrapAndEveryTimeoutComesOnTime",
                    check_coi_correlation},
        // End to end: an answer given to the wrong request ends a drive short.
        PlantedCase{"NewestTaskAnswerEndsADriveShort", prop::PlantedBug::newest_task_answer,
                    "ADriveReportedCompletedHasMovedTheCarItsDistance", check_drives},
        PlantedCase{"NoBackoff", prop::PlantedBug::no_backoff,
                    "ReconnectsBackOff1248SAndALoginWithoutReplyFailsAtExactly2S",
                    check_reconnects}),
    [](const ::testing::TestParamInfo<PlantedCase>& param) {
      return std::string(param.param.name);
    });

}  // namespace
}  // namespace hil::client::wr8
