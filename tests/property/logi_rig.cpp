#include "tests/property/logi_rig.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <set>
#include <sstream>

#include "protocol/common/overloaded.hpp"
#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"

namespace hil::client::logi::prop {

namespace proto = protocol::logi;
using proto::Direction;
using proto::Mode;

const char* name_of(Prop p) {
  switch (p) {
    case Prop::backoff_delays:
      return "ReconnectDelaysAre1s2s3sThen3s";
    case Prop::single_outbound_queue:
      return "OneCommandAwaitsFeedbackAtATime";
    case Prop::feedback_timeout_800ms:
      return "FeedbackTimeoutIsExactly800ms";
    case Prop::retry_rules:
      return "OnlySpMdMvStopAreRetriedAtMostTwice";
    case Prop::stop_on_release:
      return "ReleaseSendsMvStop";
    case Prop::stale_after_2s:
      return "StaleJustAfter2sWithoutStatAndClearedOnlyByStat";
    case Prop::emergency_stop_order:
      return "EmergencyStopSendsMvStopFirstThenStStopInAuto";
    case Prop::estop_st_stop_resent:
      return "EmergencyStStopResentEvery800msUntilTheCarAnswers";
    case Prop::car_rests_after_estop:
      return "CarStopsOnceTheLinkLetsAnEmergencyStStopThrough";
    case Prop::move_timeout_stops:
      return "ATimedOutMoveIsFollowedByMvStopAtOnce";
    case Prop::mode_conflict:
      return "FbMv0GivesANoticeMdManAndOneRetry";
    case Prop::safe_state_and_reconfirm:
      return "SafeStateOnLossAndReconfirmAfterReconnect";
    case Prop::bad_checksum_dropped:
      return "BadChecksumFramesAreDroppedLoggedAndTheLinkKept";
    case Prop::stream_gives_every_frame:
      return "StickyAndSplitStreamsGiveEveryFrame";
    case Prop::chassis_rests_after_stop:
      return "ChassisRestsWithin2120msOfAStopThatGetsThrough";
    case Prop::connect_disconnect:
      return "ConnectAndDisconnectByHand";
    case Prop::status_and_feedback_parsed:
      return "StatusAndFeedbackParsedAndMatched";
    case Prop::buttons_send_exact_frames:
      return "EveryControlSendsItsExactFrame";
    case Prop::manual_directions:
      return "ManualControlDrivesEveryDirection";
    case Prop::auto_flow:
      return "AutoFlowStationRunStop";
    case Prop::reconnects_automatically:
      return "ReconnectsWithoutTheOperator";
    case Prop::log_has_tx_rx_errors:
      return "LogHoldsTxRxAndParseErrors";
    case Prop::telemetry_visible:
      return "TelemetryShownIsTheLastStat";
    case Prop::mode_and_direction_shown:
      return "ModeAndHeldDirectionShown";
    case Prop::emergency_stop_accessible:
      return "EmergencyStopAlwaysAccessible";
    case Prop::checksums_built_right:
      return "EveryFrameWrittenHasItsRightChecksum";
    case Prop::count_:
      break;
  }
  return "?";
}

Focus focus_for(Prop p) {
  switch (p) {
    case Prop::backoff_delays:
    case Prop::reconnects_automatically:
    case Prop::safe_state_and_reconfirm:
      return {.disconnect = 2, .drop_link = 5};
    case Prop::stale_after_2s:
    case Prop::telemetry_visible:
      return {.mute = 5, .faults = 4};
    case Prop::bad_checksum_dropped:
    case Prop::stream_gives_every_frame:
    case Prop::status_and_feedback_parsed:
    case Prop::log_has_tx_rx_errors:
      return {.faults = 8};
    case Prop::feedback_timeout_800ms:
    case Prop::retry_rules:
    case Prop::single_outbound_queue:
      return {.station = 4, .run = 4, .reject = 3, .ignore = 6, .faults = 4};
    case Prop::mode_conflict:
      return {.mode = 8, .reject = 4};
    case Prop::estop_st_stop_resent:
    case Prop::car_rests_after_estop:
      // Auto runs (a press would switch the car to MAN) stopped through a lossy link.
      return {.disconnect = 0,
              .speed = 6,
              .mode = 6,
              .press = 1,
              .release = 2,
              .station = 6,
              .run = 8,
              .stop = 1,
              .estop = 8,
              .drop_link = 0,
              .reject = 0,
              .ignore = 0,
              .mute = 0,
              .faults = 6};
    case Prop::move_timeout_stops:
      return {.disconnect = 0,
              .speed = 6,
              .mode = 6,
              .press = 12,
              .release = 4,
              .station = 0,
              .run = 0,
              .stop = 0,
              .estop = 1,
              .drop_link = 0,
              .ignore = 8,
              .faults = 6};
    case Prop::emergency_stop_order:
    case Prop::emergency_stop_accessible:
      return {.station = 5, .run = 5, .estop = 8};
    case Prop::chassis_rests_after_stop:
    case Prop::stop_on_release:
      return {.station = 4, .run = 4, .estop = 5, .faults = 4};
    case Prop::auto_flow:
      // A press switches the car to MAN, where RUN is refused.
      return {.press = 1, .station = 6, .run = 6, .stop = 4};
    default:
      return {};
  }
}

bool is_movement(const proto::Message& m) {
  if (const auto* mv = std::get_if<proto::Move>(&m)) return mv->direction != Direction::stop;
  if (const auto* st = std::get_if<proto::SetRun>(&m)) return st->run;
  return false;
}

namespace {

/// The signs of the forward, leftward and anticlockwise motion `d` asks for.
std::array<int, 3> motion_signs(Direction d) {
  const auto one_of = [d](std::initializer_list<Direction> ds) {
    return std::find(ds.begin(), ds.end(), d) != ds.end() ? 1 : 0;
  };
  return {one_of({Direction::fwd, Direction::lf, Direction::rf}) -
              one_of({Direction::bwd, Direction::lb, Direction::rb}),
          one_of({Direction::left, Direction::lf, Direction::lb}) -
              one_of({Direction::right, Direction::rf, Direction::rb}),
          one_of({Direction::ccw}) - one_of({Direction::cw})};
}

bool is_stop(const proto::Message& m) {
  if (const auto* mv = std::get_if<proto::Move>(&m)) return mv->direction == Direction::stop;
  if (const auto* st = std::get_if<proto::SetRun>(&m)) return !st->run;
  return false;
}

}  // namespace

std::string dir_word(Direction d) {
  return std::string(proto::to_string(d));
}

std::string ms(Duration d) {
  return link::format_ms(d);
}

std::string text_of(const protocol::Bytes& b) {
  return std::string(b.begin(), b.end());
}

// ---------------------------------------------------------------- the rig

class Rig::Observer final : public link::LinkObserver {
 public:
  explicit Observer(Rig* rig) : rig_(rig) {}
  Rig* rig_;
  proto::Decoder to_client_sent_;
  std::vector<proto::Item> items_;

  void on_open(Time at, const std::string&, const std::string&) override {
    if (!rig_) return;
    rig_->links.emplace_back();
    rig_->links.back().opened = at;
    to_client_sent_ = proto::Decoder{};
  }
  void on_sent(Time at, link::Direction d, protocol::ByteView bytes) override {
    LinkRecord* l = watched();
    if (l == nullptr) return;
    if (d == link::Direction::to_car) return append(l->to_car_sent, bytes);
    // The car's answers as it writes them: what the car did with a command.
    std::vector<proto::Feedback> feedback;
    for (const auto& m : messages_of(to_client_sent_, bytes)) {
      if (const auto* fb = std::get_if<proto::Feedback>(&m)) feedback.push_back(*fb);
    }
    std::map<proto::Command, int> per_code;
    for (const auto& fb : feedback)
      ++per_code[fb.command];
    for (const auto& fb : feedback) {
      // Two answers of one code in one write: which command each is for is
      // not known here, so neither is judged.
      if (!fb.accepted || per_code[fb.command] > 1) continue;
      rig_->on_car_accepted(at, fb);
    }
  }
  void on_delivered(Time at, link::Direction d, protocol::ByteView bytes) override {
    LinkRecord* l = watched();
    if (l == nullptr) return;
    if (d == link::Direction::to_client) return append(l->to_client_delivered, bytes);
    for (const auto& m : messages_of(l->to_car_decoder, bytes)) {
      CarFrame cf{at, rig_->links.size() - 1, m, rig_->firmware().state().mode};
      rig_->car_frames.push_back(cf);
    }
  }
  void on_fault(const link::FaultEvent& e) override {
    if (rig_) rig_->faults.push_back(e);
  }
  void on_close(Time at, const link::LinkClose& c) override {
    LinkRecord* l = watched();
    if (l == nullptr) return;
    l->closed = at;
    l->closed_by = c.by;
  }

 private:
  /// The connection being watched: the latest, while the rig is there.
  LinkRecord* watched() { return rig_ && !rig_->links.empty() ? &rig_->links.back() : nullptr; }
  static void append(protocol::Bytes& record, protocol::ByteView bytes) {
    record.insert(record.end(), bytes.begin(), bytes.end());
  }
  /// The messages of the frames `decoder` makes of `bytes`; what does not
  /// decode is passed over.
  std::vector<proto::Message> messages_of(proto::Decoder& decoder, protocol::ByteView bytes) {
    items_.clear();
    decoder.feed(bytes, items_);
    std::vector<proto::Message> out;
    for (const auto& item : items_) {
      if (const auto* f = std::get_if<protocol::Frame<proto::Message>>(&item))
        out.push_back(f->message);
    }
    return out;
  }
};

Rig::Rig(PlantedBug bug, std::uint64_t link_seed) {
  observer_ = std::make_shared<Observer>(this);
  mocks::ServerOptions options = test::on_mem("car");
  options.name = "logi";
  options.seed = link_seed;
  options.observers.push_back(observer_);
  car_.start_car(sim::logi_car(), std::move(options));
  session_ = std::make_unique<PlantedBugSession>(
      car_.context, link::MemEndpoint{"car"}, bug, ClientConfig{},
      [this](Time t, const Event& e) { on_event(t, e); });
}

Rig::~Rig() {
  observer_->rig_ = nullptr;
  session_.reset();
}

void Rig::fail(Prop p, std::string why) {
  auto& list = failures_[static_cast<int>(p)];
  if (list.size() < 5) list.push_back(ms(now()) + ": " + std::move(why));
}

void Rig::advance_to(Time until) {
  // One task at a time: a stop reaching the car adds a check 520 ms ahead,
  // and the clock must stop there even within one long wait.
  for (;;) {
    std::optional<Time> check_due;
    for (const auto* checks : {&chassis_checks_, &rest_checks_, &estop_samples_}) {
      if (!checks->empty() && (!check_due || checks->begin()->first < *check_due)) {
        check_due = checks->begin()->first;
      }
    }
    const Time target = check_due && *check_due < until ? *check_due : until;
    const auto next = car_.executor.next_due();
    if (next && *next <= target) {
      car_.executor.run_one();
      continue;
    }
    if (!check_due || *check_due > until) break;
    car_.executor.run_until(*check_due);
    if (!chassis_checks_.empty() && chassis_checks_.begin()->first == *check_due) {
      const std::size_t index = chassis_checks_.begin()->second;
      chassis_checks_.erase(chassis_checks_.begin());
      check_chassis(*check_due, index);
    } else if (!rest_checks_.empty() && rest_checks_.begin()->first == *check_due) {
      const std::size_t op = rest_checks_.begin()->second;
      rest_checks_.erase(rest_checks_.begin());
      check_rest(*check_due, op);
    } else {
      const std::size_t op = estop_samples_.begin()->second;
      estop_samples_.erase(estop_samples_.begin());
      sample_estop(*check_due, op);
    }
  }
  car_.executor.run_until(until);
}

bool Rig::at_rest() {
  car_.world->advance_to(now());
  return vehicle().chassis().wheel_twist() == sim::Twist{};
}

void Rig::check_chassis(Time due, std::size_t index) {
  // Voided by motion the car was told to make after the stop.
  for (std::size_t i = index + 1; i < car_frames.size() && car_frames[i].at <= due; ++i) {
    if (is_movement(car_frames[i].message)) return;
  }
  ++stop_claims;
  if (!at_rest()) {
    const auto t = vehicle().chassis().wheel_twist();
    fail(Prop::chassis_rests_after_stop,
         "still moving " + ms(kBrakeBound) + " after " +
             proto::describe(car_frames[index].message) + " reached the car at " +
             ms(car_frames[index].at) + " (vx " + std::to_string(t.vx_mps) + " vy " +
             std::to_string(t.vy_mps) + " wz " + std::to_string(t.wz_radps) + ")");
  }
}

void Rig::check_rest(Time due, std::size_t op_index) {
  const OpRecord& op = ops[op_index];
  const Time t = op.at;
  // The link must have stayed up: a car left alone keeps its motion.
  for (const auto& l : links) {
    if (l.closed && *l.closed >= t && *l.closed <= due) return;
  }
  // The attempts that count are the stops the car acts on in its mode: in
  // AUTO only ST:STOP (MV:STOP is refused there), in MAN both.
  const bool in_auto = op.car_mode == Mode::automatic;
  const auto acts_on = [&](const proto::Message& m) {
    return is_stop(m) && (!in_auto || std::holds_alternative<proto::SetRun>(m));
  };
  // No new motion asked for.
  std::size_t stops_sent = 0;
  for (std::size_t i = op.events_before; i < events.size(); ++i) {
    const auto& [at, e] = events[i];
    const auto* c = std::get_if<CommandEvent>(&e);
    if (c == nullptr || c->state != CommandState::sent) continue;
    if (is_movement(c->command)) return;
    if (acts_on(c->command) && at <= t + kLastStopAttempt) ++stops_sent;
  }
  // The fault schedule let none of those attempts through.
  std::size_t stops_destroyed = 0;
  for (const auto& f : faults) {
    if (f.direction != link::Direction::to_car || f.at < t || f.at > t + kLastStopAttempt) continue;
    if (f.kind != link::FaultKind::drop && f.kind != link::FaultKind::corrupt) continue;
    if (text_of(f.before).find(in_auto ? "ST:STOP" : "STOP") != std::string::npos) {
      ++stops_destroyed;
    }
  }
  if (stops_sent > 0 && stops_destroyed >= stops_sent) return;
  ++stop_claims;
  if (!at_rest()) {
    fail(Prop::chassis_rests_after_stop,
         std::string(op.kind == OpRecord::Kind::estop ? "emergency stop" : "release") + " at " +
             ms(t) + ": the chassis still moves " + ms(due - t) + " later (" +
             std::to_string(stops_sent) + " stop frames sent, " + std::to_string(stops_destroyed) +
             " destroyed by faults)");
  }
}

void Rig::sample_estop(Time due, std::size_t op_index) {
  const bool running = firmware().state().running;
  estop_samples.push_back({op_index, due, running, at_rest()});
  // The next attempt's instant, while the ST:STOP is still owed: not
  // answered or cancelled, no newer emergency stop, the same link up.
  const OpRecord& op = ops[op_index];
  const auto request = estop_st_stop(*this, op);
  for (std::size_t i = op_index + 1; i < ops.size(); ++i) {
    if (ops[i].kind == OpRecord::Kind::estop) return;
  }
  if (op.links_before == 0 || links.size() != op.links_before ||
      links[op.links_before - 1].closed) {
    return;
  }
  for (std::size_t i = op.events_before; i < events.size(); ++i) {
    const auto& e = events[i].second;
    if (const auto* f = std::get_if<FeedbackEvent>(&e); f && f->request == *request) return;
    const auto* c = std::get_if<CommandEvent>(&e);
    if (c && c->request == *request && c->state != CommandState::sent &&
        c->state != CommandState::uncertain) {
      return;
    }
  }
  estop_samples_.emplace(due + core().config().feedback_timeout, op_index);
}

void Rig::on_car_accepted(Time at, const proto::Feedback& fb) {
  // The command the car just answered: the last one of that code it received.
  const proto::Message* cmd = nullptr;
  std::size_t index = 0;
  for (std::size_t i = car_frames.size(); i-- > 0;) {
    if (proto::command_of(car_frames[i].message) == fb.command) {
      cmd = &car_frames[i].message;
      index = i;
      break;
    }
  }
  if (cmd == nullptr) return;
  // The car acted on a stop (its answer says so; a frame delivered to a car
  // that is hanging up may never be read): the chassis must rest 520 ms on.
  if (is_stop(*cmd)) chassis_checks_.emplace(at + kBrakeBound, index);
  const auto& s = firmware().state();
  CarAccepted rec{at, *cmd, true, {}};
  if (const auto* mv = std::get_if<proto::Move>(cmd)) {
    if (s.manual != mv->direction) rec.ok = false;
    if (mv->direction != Direction::stop && s.speed_percent > 0 && !s.obstacle) {
      const auto* m = vehicle().mecanum();
      const sim::Twist tw = m != nullptr ? m->target() : sim::Twist{};
      auto sign = [](double v) { return std::abs(v) < 1e-9 ? 0 : (v > 0 ? 1 : -1); };
      const auto [vx, vy, wz] = motion_signs(mv->direction);
      if (sign(tw.vx_mps) != vx || sign(tw.vy_mps) != vy || sign(tw.wz_radps) != wz) rec.ok = false;
    }
  } else if (const auto* st = std::get_if<proto::SetRun>(cmd)) {
    rec.ok = st->run ? s.running : (!s.running && s.manual == Direction::stop);
  } else if (const auto* gs = std::get_if<proto::SetStation>(cmd)) {
    rec.ok = s.station == gs->station;
  }
  car_accepted.push_back(std::move(rec));
}

void Rig::on_event(Time t, const Event& e) {
  events.emplace_back(t, e);
  if (const auto* c = std::get_if<ConnectionEvent>(&e)) {
    md_on_connection = false;
    sp_on_connection = false;
    shown_mode.reset();
    if (c->state != ConnectionState::connected) held.reset();
  } else if (const auto* s = std::get_if<StatusEvent>(&e)) {
    shown_mode = s->status.mode;
    last_status = s->status;
  } else if (const auto* c2 = std::get_if<CommandEvent>(&e)) {
    if (c2->state == CommandState::accepted) {
      if (const auto* md = std::get_if<proto::SetMode>(&c2->command)) shown_mode = md->mode;
    }
  }
}

OpRecord Rig::begin_op(OpRecord::Kind kind, int value) {
  // What the screen shows, checked before every operator action.
  if (core().last_status() != last_status) {
    fail(Prop::telemetry_visible, "the status shown is not the last STAT received");
  }
  if (core().known_mode() != shown_mode) {
    fail(Prop::mode_and_direction_shown, "the mode shown is not the last STAT's or accepted MD's");
  }
  if (core().held() != held) {
    fail(Prop::mode_and_direction_shown, "the direction shown is not the one the operator holds");
  }
  OpRecord r;
  r.kind = kind;
  r.at = now();
  r.value = value;
  r.state_before = core().state();
  r.line_idle = core().in_flight() == 0 && core().queued() == 0;
  r.known_mode_before = core().known_mode();
  r.car_running = firmware().state().running;
  r.car_mode = firmware().state().mode;
  r.events_before = events.size();
  r.links_before = links.size();
  return r;
}

void Rig::end_op(OpRecord r) {
  r.events_after = events.size();
  ops.push_back(std::move(r));
  settle();
  ops.back().state_after = core().state();
}

void Rig::op_connect() {
  auto r = begin_op(OpRecord::Kind::connect, 0);
  session_->connect();
  end_op(std::move(r));
}

void Rig::op_disconnect() {
  auto r = begin_op(OpRecord::Kind::disconnect, 0);
  session_->disconnect();
  held.reset();
  end_op(std::move(r));
}

void Rig::op_submit(OpRecord::Kind kind, const proto::Message& m, int value) {
  auto r = begin_op(kind, value);
  const bool connected = r.state_before == ConnectionState::connected;
  const Refusal expected = !connected ? Refusal::not_connected
                           : is_movement(m) && !(md_on_connection && sp_on_connection)
                               ? Refusal::mode_speed_unconfirmed
                               : Refusal::none;
  r.result = session_->call([&](LogiClientCore& c, Time t) { return c.submit(t, m); });
  if (r.result.refusal != expected) {
    fail(Prop::safe_state_and_reconfirm,
         proto::describe(m) + " answered '" + std::string(to_string(r.result.refusal)) +
             "', expected '" + std::string(to_string(expected)) + "'");
  }
  if (r.result) {
    if (std::holds_alternative<proto::SetMode>(m)) md_on_connection = true;
    if (std::holds_alternative<proto::SetSpeed>(m)) sp_on_connection = true;
  }
  end_op(std::move(r));
}

void Rig::op_press(Direction d) {
  auto r = begin_op(OpRecord::Kind::press, static_cast<int>(d));
  const bool connected = r.state_before == ConnectionState::connected;
  const Refusal expected = !connected ? Refusal::not_connected
                           : !(md_on_connection && sp_on_connection)
                               ? Refusal::mode_speed_unconfirmed
                               : Refusal::none;
  r.result = session_->call([&](LogiClientCore& c, Time t) { return c.press(t, d); });
  if (r.result.refusal != expected) {
    fail(Prop::safe_state_and_reconfirm, std::string("press ") + dir_word(d) + " answered '" +
                                             std::string(to_string(r.result.refusal)) +
                                             "', expected '" + std::string(to_string(expected)) +
                                             "'");
  }
  if (r.result) held = d;
  end_op(std::move(r));
}

void Rig::op_release() {
  auto r = begin_op(OpRecord::Kind::release, 0);
  const bool was_held = held.has_value();
  r.result = session_->call([](LogiClientCore& c, Time t) { return c.release(t); });
  held.reset();
  const Refusal expected = was_held ? Refusal::none : Refusal::not_held;
  if (r.result.refusal != expected && !(was_held && r.state_before != ConnectionState::connected)) {
    fail(Prop::stop_on_release, "release answered '" + std::string(to_string(r.result.refusal)) +
                                    "', expected '" + std::string(to_string(expected)) + "'");
  }
  const std::size_t index = ops.size();
  end_op(std::move(r));
  const auto& op = ops[index];
  if (op.result && op.line_idle && !op.car_running)
    rest_checks_.emplace(op.at + kStopToRest, index);
}

void Rig::op_estop() {
  auto r = begin_op(OpRecord::Kind::estop, 0);
  r.result = session_->call([](LogiClientCore& c, Time t) { return c.emergency_stop(t); });
  held.reset();
  const std::size_t index = ops.size();
  end_op(std::move(r));
  const auto& op = ops[index];
  if (op.state_before == ConnectionState::connected) {
    rest_checks_.emplace(op.at + kStopToRest, index);
    if (estop_st_stop(*this, op)) estop_samples_.emplace(op.at + kBrakeBound, index);
  }
}

void Rig::car_drop_link(bool reset) {
  firmware().arm(mocks::Behaviour{
      "drop", mocks::When{now(), {}, 1},
      mocks::CloseConnection{reset ? link::CloseMode::reset : link::CloseMode::graceful}});
  settle();
}

void Rig::car_arm(mocks::Behaviour b) {
  firmware().arm(std::move(b));
  settle();
}

void Rig::car_faults(link::FaultProfile profile) {
  server().set_faults(std::move(profile));
  settle();
}

std::string Rig::timeline() const {
  // Events and operator actions in order, for the person reading a failure.
  std::ostringstream os;
  std::size_t op = 0;
  auto show_op = [&](const OpRecord& r) {
    static const char* names[] = {"connect", "disconnect", "speed", "mode", "press",
                                  "release", "station",    "run",   "stop", "emergency-stop"};
    os << "  " << ms(r.at) << "  OPERATOR " << names[static_cast<int>(r.kind)] << " " << r.value
       << " -> "
       << (r.result ? "request " + std::to_string(r.result.request)
                    : std::string(to_string(r.result.refusal)))
       << "\n";
  };
  for (std::size_t i = 0; i < events.size(); ++i) {
    for (; op < ops.size() && ops[op].events_before <= i; ++op)
      show_op(ops[op]);
    const auto& [t, e] = events[i];
    os << "  " << ms(t) << "  ";
    std::visit(protocol::Overloaded{
                   [&](const ConnectionEvent& c) {
                     os << "connection " << to_string(c.state) << " attempt " << c.attempt;
                   },
                   [&](const StatusEvent& s) { os << "STAT " << proto::describe(s.status); },
                   [&](const FeedbackEvent& f) {
                     os << "FB " << proto::describe(f.feedback) << " -> request " << f.request;
                   },
                   [&](const CommandEvent& c) {
                     os << "request " << c.request << " " << proto::describe(c.command) << " "
                        << to_string(c.state) << " attempt " << c.attempt;
                   },
                   [&](const StaleEvent& s) { os << (s.stale ? "STALE" : "fresh"); },
                   [&](const NoticeEvent& n) { os << "notice: " << n.text; },
                   [&](const ParseErrorEvent& p) {
                     os << "parse error " << protocol::to_string(p.error.kind) << " '"
                        << text_of(p.error.raw) << "'";
                   },
                   [&](const MovementEvent& m) { os << "movement " << (m.enabled ? "on" : "off"); },
               },
               e);
    os << "\n";
  }
  for (; op < ops.size(); ++op)
    show_op(ops[op]);
  for (std::size_t k = 0; k < links.size(); ++k) {
    os << "  link " << k + 1 << ": opened " << ms(links[k].opened);
    if (links[k].closed)
      os << ", closed " << ms(*links[k].closed) << " by " << link::to_string(links[k].closed_by);
    os << "\n";
  }
  return os.str();
}

}  // namespace hil::client::logi::prop
