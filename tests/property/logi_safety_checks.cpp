// The LOGI checks of the safety guard (the car document's sections 5.5 and
// 9): the stop on release, the stale warning, the emergency stop (its order,
// its reach, its ST:STOP resent until the car answers and the car stopping
// once the link lets one through), the switch to MAN, the safe state on a
// lost link, and the MV:STOP after a move whose feedback never came. Each
// returns an empty string when its rule held; times are exact to the
// nanosecond.

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "protocol/logi/codec.hpp"
#include "tests/property/logi_rig.hpp"

namespace hil::client::logi::prop {

namespace proto = protocol::logi;
using proto::Direction;
using proto::Mode;

namespace {

constexpr Duration kTimeout = milliseconds(800);

bool is_move(const proto::Message& m) {
  const auto* mv = std::get_if<proto::Move>(&m);
  return mv != nullptr && mv->direction != Direction::stop;
}
bool is_mv_stop(const proto::Message& m) {
  return m == proto::Message{proto::Move{Direction::stop}};
}

/// When the ST:STOP `request` of an emergency stop stopped being owed: its
/// answer (an FB credited to it) or its cancellation; none while it is open.
std::optional<Time> ended(const Rig& rig, std::size_t from, RequestId request) {
  for (std::size_t i = from; i < rig.events.size(); ++i) {
    const auto& [t, e] = rig.events[i];
    if (const auto* f = std::get_if<FeedbackEvent>(&e); f && f->request == request) return t;
    const auto* c = std::get_if<CommandEvent>(&e);
    if (c && c->request == request && c->state == CommandState::cancelled) return t;
  }
  return std::nullopt;
}

std::string estop_at(const OpRecord& op) {
  return "emergency stop at " + ms(op.at);
}

}  // namespace

std::set<RequestId> estop_requests(const Rig& rig) {
  std::set<RequestId> ids;
  for (const auto& op : rig.ops) {
    if (op.kind != OpRecord::Kind::estop) continue;
    for (std::size_t i = op.events_before; i < op.events_after; ++i) {
      if (const auto* c = std::get_if<CommandEvent>(&rig.events[i].second)) {
        if (c->state == CommandState::sent) ids.insert(c->request);
      }
    }
  }
  return ids;
}

std::optional<RequestId> estop_st_stop(const Rig& rig, const OpRecord& op) {
  if (op.kind != OpRecord::Kind::estop) return std::nullopt;
  for (std::size_t i = op.events_before; i < op.events_after && i < rig.events.size(); ++i) {
    const auto* c = std::get_if<CommandEvent>(&rig.events[i].second);
    if (c && c->state == CommandState::sent && c->command == proto::Message{proto::SetRun{false}}) {
      return c->request;
    }
  }
  return std::nullopt;
}

std::set<RequestId> fail_safe_stops(const Rig& rig) {
  std::set<RequestId> operators = estop_requests(rig);
  for (const auto& op : rig.ops) {
    if (op.result) operators.insert(op.result.request);
  }
  std::set<RequestId> ids;
  for (const auto& [t, e] : rig.events) {
    const auto* c = std::get_if<CommandEvent>(&e);
    if (c && c->state == CommandState::sent && is_mv_stop(c->command) &&
        operators.count(c->request) == 0) {
      ids.insert(c->request);
    }
  }
  return ids;
}

bool destroyed_at(const Rig& rig, Time at, const std::string& text) {
  return std::any_of(rig.faults.begin(), rig.faults.end(), [&](const link::FaultEvent& f) {
    return f.at == at && f.direction == link::Direction::to_car &&
           (f.kind == link::FaultKind::drop || f.kind == link::FaultKind::corrupt) &&
           text_of(f.before).find(text) != std::string::npos;
  });
}

std::string check_stop_on_release(const Rig& rig) {
  const auto steps = by_request(rig);
  for (const auto& op : rig.ops) {
    if (op.kind != OpRecord::Kind::release || !op.result) continue;
    const auto it = steps.find(op.result.request);
    const std::string what = "release at " + ms(op.at);
    if (it == steps.end() || it->second.empty()) {
      if (op.line_idle) return what + " on an idle line: no MV:STOP was written";
      // On a busy line it waits its turn: no later operator request may go first.
      for (const auto& later : rig.ops) {
        if (!later.result || later.kind == OpRecord::Kind::estop ||
            later.result.request <= op.result.request) {
          continue;
        }
        const auto l = steps.find(later.result.request);
        if (l != steps.end() && !l->second.empty()) {
          return what + ": no MV:STOP written, yet request " +
                 std::to_string(later.result.request) + " queued after it was";
        }
      }
      continue;
    }
    const auto* first = std::get_if<CommandEvent>(it->second.front().e);
    if (first == nullptr) return what + ": odd first event";
    if (first->state == CommandState::cancelled) continue;  // the link went first
    if (first->state != CommandState::sent || first->command != proto::Message{proto::Move{}}) {
      return what + ": its request is " + proto::describe(first->command) + ", not MV:STOP";
    }
    if (op.line_idle && it->second.front().at != op.at) {
      return what + " on an idle line: MV:STOP written only at " + ms(it->second.front().at);
    }
  }
  return {};
}

std::string check_stale(const Rig& rig) {
  // "More than 2 s": raised at the first instant after, one tick (1 ns) on.
  const Duration after = seconds(2) + LogiClientCore::kTick;
  bool connected = false;
  bool stale = false;
  Time last{0};
  auto overdue = [&](Time upto) -> std::string {
    if (connected && !stale && last + after < upto) {
      return "no stale warning at " + ms(last + after) +
             ", 2 s and 1 ns after the last STAT (or connect) at " + ms(last);
    }
    return {};
  };
  for (std::size_t i = 0; i < rig.events.size(); ++i) {
    const auto& [t, e] = rig.events[i];
    if (auto why = overdue(t); !why.empty()) return why;
    if (const auto* c = std::get_if<ConnectionEvent>(&e)) {
      connected = c->state == ConnectionState::connected;
      if (connected) last = t;
    } else if (std::holds_alternative<StatusEvent>(e)) {
      last = t;
      if (stale) return "a STAT at " + ms(t) + " did not clear the stale warning";
    } else if (const auto* s = std::get_if<StaleEvent>(&e)) {
      if (s->stale) {
        if (!connected || stale)
          return "a stale warning at " + ms(t) + " while not connected or already stale";
        if (t != last + after) {
          return "stale warning at " + ms(t) + " (" + std::to_string((t - last).count()) +
                 " ns after the last STAT or connect at " + ms(last) + "), expected " +
                 std::to_string(after.count()) + " ns after it";
        }
        stale = true;
      } else {
        const bool stat_follows = i + 1 < rig.events.size() && rig.events[i + 1].first == t &&
                                  std::holds_alternative<StatusEvent>(rig.events[i + 1].second);
        if (!stale || !stat_follows) return "stale cleared at " + ms(t) + " without a fresh STAT";
        stale = false;
        last = t;  // the STAT that cleared it comes next
      }
    }
  }
  return overdue(rig.now());
}

std::string check_estop_order(const Rig& rig) {
  for (const auto& op : rig.ops) {
    if (op.kind != OpRecord::Kind::estop || op.state_before != ConnectionState::connected) continue;
    std::vector<proto::Message> sent;
    for (std::size_t i = op.events_before; i < op.events_after; ++i) {
      if (const auto* c = std::get_if<CommandEvent>(&rig.events[i].second)) {
        if (c->state == CommandState::sent) sent.push_back(c->command);
      }
    }
    const bool in_man = op.known_mode_before == Mode::manual;
    std::vector<proto::Message> want{proto::Move{}};
    if (!in_man) want.emplace_back(proto::SetRun{false});
    if (sent != want) {
      std::string got;
      for (const auto& m : sent)
        got += " " + proto::describe(m);
      return "emergency stop at " + ms(op.at) +
             (in_man ? " (car known in MAN)" : " (AUTO or unknown)") +
             " wrote:" + (got.empty() ? " nothing" : got) +
             (in_man ? "; expected MV:STOP only" : "; expected MV:STOP then ST:STOP");
    }
  }
  return {};
}

std::string check_mode_conflict(const Rig& rig) {
  // Stops the client wrote on its own never switch the car to MAN.
  auto estop = estop_requests(rig);
  estop.merge(fail_safe_stops(rig));
  std::map<RequestId, int> refusals;
  for (std::size_t i = 0; i < rig.events.size(); ++i) {
    const auto* f = std::get_if<FeedbackEvent>(&rig.events[i].second);
    if (f == nullptr || f->request == 0 || f->feedback.command != proto::Command::mv ||
        f->feedback.accepted) {
      continue;
    }
    const Time t = rig.events[i].first;
    const bool notice = i + 1 < rig.events.size() &&
                        std::holds_alternative<NoticeEvent>(rig.events[i + 1].second) &&
                        std::get<NoticeEvent>(rig.events[i + 1].second).text ==
                            "Not in manual mode, switching to MAN";
    const int n = ++refusals[f->request];
    if (estop.count(f->request) != 0 || n > 1) {
      if (notice)
        return "FB:MV:0 at " + ms(t) + " for a stop the client wrote on its own or a retried move" +
               " led to MD:MAN";
      continue;
    }
    if (!notice)
      return "FB:MV:0 at " + ms(t) + " without the notice 'Not in manual mode, switching to MAN'";
    // The next non-emergency sends: MD:MAN, then the move once more.
    std::vector<std::pair<RequestId, proto::Message>> next;
    for (std::size_t j = i + 1; j < rig.events.size() && next.size() < 2; ++j) {
      const auto& e = rig.events[j].second;
      if (const auto* k = std::get_if<ConnectionEvent>(&e)) {
        if (k->state != ConnectionState::connected) break;
      }
      const auto* c = std::get_if<CommandEvent>(&e);
      if (c != nullptr && c->request == f->request && c->state == CommandState::cancelled) {
        break;  // an emergency stop dropped the queued move: no retry is owed
      }
      if (c == nullptr || c->state != CommandState::sent || estop.count(c->request) != 0) continue;
      if (!next.empty() && next.back().first == c->request) continue;  // an MD retry
      next.emplace_back(c->request, c->command);
    }
    if (!next.empty() && next[0].second != proto::Message{proto::SetMode{Mode::manual}}) {
      return "after FB:MV:0 at " + ms(t) + " the client wrote " + proto::describe(next[0].second) +
             ", not MD:MAN";
    }
    if (next.size() == 2 && next[1].first != f->request) {
      return "after FB:MV:0 at " + ms(t) + " and MD:MAN the move was not retried next (" +
             proto::describe(next[1].second) + " came)";
    }
  }
  return {};
}

std::string check_safe_state(Rig& rig) {
  if (!rig.failures(Prop::safe_state_and_reconfirm).empty()) {
    return rig.failures(Prop::safe_state_and_reconfirm).front();
  }
  // Everything open is cancelled as the connection goes; nothing is written
  // on a new connection before the operator acts.
  std::set<RequestId> open;
  std::size_t op = 0;
  std::optional<Time> fresh_connection;
  bool movement_enabled = false;
  for (std::size_t i = 0; i < rig.events.size(); ++i) {
    for (; op < rig.ops.size() && rig.ops[op].events_before <= i; ++op) {
      fresh_connection.reset();
      if (rig.ops[op].result && rig.ops[op].kind != OpRecord::Kind::connect &&
          rig.ops[op].kind != OpRecord::Kind::disconnect) {
        open.insert(rig.ops[op].result.request);
      }
    }
    const auto& [t, e] = rig.events[i];
    if (const auto* c = std::get_if<CommandEvent>(&e)) {
      if (c->state == CommandState::sent) {
        if (fresh_connection) {
          return proto::describe(c->command) + " written at " + ms(t) +
                 " on a new connection before the operator did anything";
        }
        open.insert(c->request);
      } else if (c->state != CommandState::sent) {
        open.erase(c->request);
      }
    } else if (const auto* m = std::get_if<MovementEvent>(&e)) {
      movement_enabled = m->enabled;
    } else if (const auto* k = std::get_if<ConnectionEvent>(&e)) {
      if (k->state == ConnectionState::connected) {
        fresh_connection = t;
      } else {
        fresh_connection.reset();
        const bool disabled = i + 1 < rig.events.size() &&
                              std::holds_alternative<MovementEvent>(rig.events[i + 1].second) &&
                              !std::get<MovementEvent>(rig.events[i + 1].second).enabled;
        if (movement_enabled && !disabled) {
          return "movement controls still enabled as the link left at " + ms(t);
        }
        if (!open.empty()) {
          return "request " + std::to_string(*open.begin()) +
                 " neither ended nor cancelled when the link left at " + ms(t);
        }
      }
    }
  }
  return {};
}

std::string check_estop_accessible(const Rig& rig) {
  for (const auto& op : rig.ops) {
    if (op.kind != OpRecord::Kind::estop) continue;
    const bool connected = op.state_before == ConnectionState::connected;
    const Refusal want = connected ? Refusal::none : Refusal::not_connected;
    if (op.result.refusal != want) {
      return "emergency stop at " + ms(op.at) + " answered '" +
             std::string(to_string(op.result.refusal)) + "' while " +
             std::string(to_string(op.state_before));
    }
    if (!connected) continue;
    bool stop_now = false;
    for (std::size_t i = op.events_before; i < op.events_after; ++i) {
      const auto& [t, e] = rig.events[i];
      if (const auto* c = std::get_if<CommandEvent>(&e)) {
        if (c->state == CommandState::sent && c->command == proto::Message{proto::Move{}} &&
            t == op.at)
          stop_now = true;
      }
    }
    if (!stop_now) {
      return "emergency stop at " + ms(op.at) + (op.line_idle ? "" : " (line busy)") +
             " did not write MV:STOP at once";
    }
  }
  return {};
}

std::string check_estop_st_stop_resent(const Rig& rig) {
  for (const auto& op : rig.ops) {
    const auto request = estop_st_stop(rig, op);
    if (!request) continue;
    const std::string what =
        estop_at(op) + ": its ST:STOP (request " + std::to_string(*request) + ")";
    int sends = 0;
    bool open = true;
    for (std::size_t i = op.events_before; i < rig.events.size() && open; ++i) {
      const auto& [t, e] = rig.events[i];
      if (const auto* f = std::get_if<FeedbackEvent>(&e)) {
        if (f->request == *request) open = false;
        continue;
      }
      const auto* c = std::get_if<CommandEvent>(&e);
      if (c == nullptr || c->request != *request) continue;
      if (c->state == CommandState::uncertain) {
        return what + " was given up as uncertain at " + ms(t) + " after " +
               std::to_string(c->attempt) + " sends; it is owed until the car answers";
      }
      if (c->state != CommandState::sent) {
        open = false;
        continue;
      }
      const Time due = op.at + kTimeout * sends;
      ++sends;
      if (t != due || c->attempt != sends) {
        return what + ": send " + std::to_string(c->attempt) + " at " + ms(t) + ", expected send " +
               std::to_string(sends) + " at exactly " + ms(due);
      }
    }
    const Time next = op.at + kTimeout * sends;
    if (open && next < rig.now()) {
      return what + " was neither answered nor cancelled, yet not written again at " + ms(next);
    }
  }
  return {};
}

std::string check_car_rests_after_estop(const Rig& rig) {
  for (std::size_t k = 0; k < rig.ops.size(); ++k) {
    const OpRecord& op = rig.ops[k];
    const auto request = estop_st_stop(rig, op);
    if (!request || op.links_before == 0) continue;
    // The claim ends with the ST:STOP's answer or cancellation, a newer
    // emergency stop, the link closing or the session's end.
    Time end = ended(rig, op.events_before, *request).value_or(rig.now());
    for (std::size_t j = k + 1; j < rig.ops.size(); ++j) {
      if (rig.ops[j].kind != OpRecord::Kind::estop) continue;
      end = std::min(end, rig.ops[j].at);
      break;
    }
    const auto& link = rig.links[op.links_before - 1];
    if (link.closed) end = std::min(end, *link.closed);
    for (Time slot = op.at; slot < end; slot += kTimeout) {
      if (destroyed_at(rig, slot, "ST:STOP")) continue;
      // The first attempt slot the faults let through: an ST:STOP written
      // then reached the car, which stops and rests within kBrakeBound.
      const Time due = slot + kBrakeBound;
      if (due > rig.now() || (link.closed && *link.closed <= due)) break;
      const bool moved =
          std::any_of(rig.events.begin() + static_cast<std::ptrdiff_t>(op.events_before),
                      rig.events.end(), [&](const auto& te) {
                        const auto* c = std::get_if<CommandEvent>(&te.second);
                        return te.first <= due && c && c->state == CommandState::sent &&
                               is_movement(c->command);
                      });
      if (moved) break;  // motion asked for again: no claim
      const auto sample =
          std::find_if(rig.estop_samples.begin(), rig.estop_samples.end(),
                       [&](const EstopSample& s) { return s.op == k && s.at == due; });
      if (sample == rig.estop_samples.end()) {
        return estop_at(op) + ": the bench took no sample of the car at " + ms(due);
      }
      if (sample->running || !sample->at_rest) {
        return estop_at(op) + ": the faults let the ST:STOP slot at " + ms(slot) +
               " through, yet at " + ms(due) + " the car " +
               (sample->running ? "still runs its auto run" : "still moves");
      }
      break;
    }
  }
  return {};
}

std::string check_move_timeout_stops(const Rig& rig) {
  const auto estop = estop_requests(rig);
  std::set<RequestId> estop_waiting;  // emergency-stop requests awaiting feedback
  for (std::size_t i = 0; i < rig.events.size(); ++i) {
    const auto& [t, e] = rig.events[i];
    if (const auto* f = std::get_if<FeedbackEvent>(&e)) {
      estop_waiting.erase(f->request);
      continue;
    }
    const auto* c = std::get_if<CommandEvent>(&e);
    if (c == nullptr) continue;
    if (estop.count(c->request) != 0) {
      if (c->state == CommandState::sent) {
        estop_waiting.insert(c->request);
      } else {
        estop_waiting.erase(c->request);
      }
    }
    if (c->state != CommandState::uncertain || !is_move(c->command)) continue;
    const std::string what = proto::describe(c->command) + " (request " +
                             std::to_string(c->request) + ") uncertain at " + ms(t);
    const bool line_free = estop_waiting.empty();
    bool stopped = false;
    for (std::size_t j = i + 1; j < rig.events.size() && !stopped; ++j) {
      const auto& [tj, ej] = rig.events[j];
      if (const auto* k = std::get_if<ConnectionEvent>(&ej)) {
        if (k->state != ConnectionState::connected) break;  // the safe state takes over
      }
      const auto* n = std::get_if<CommandEvent>(&ej);
      if (n == nullptr || n->state != CommandState::sent) continue;
      if (n->request == c->request) return what + ": the move was written again at " + ms(tj);
      if (is_mv_stop(n->command)) {
        if (line_free && tj != t) {
          return what + ": MV:STOP written only at " + ms(tj) + " although nothing else waited";
        }
        stopped = true;
      } else if (estop.count(n->request) == 0) {
        return what + ": " + proto::describe(n->command) + " was written at " + ms(tj) +
               " before any MV:STOP";
      }
    }
    if (!stopped && line_free && t < rig.now()) {
      const bool lost = std::any_of(rig.events.begin() + static_cast<std::ptrdiff_t>(i),
                                    rig.events.end(), [](const auto& te) {
                                      const auto* k = std::get_if<ConnectionEvent>(&te.second);
                                      return k && k->state != ConnectionState::connected;
                                    });
      if (!lost) return what + ": no MV:STOP followed";
    }
  }
  return {};
}

}  // namespace hil::client::logi::prop
