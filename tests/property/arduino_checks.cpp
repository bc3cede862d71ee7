// The checks of the Arduino property bench (arduino_rig.hpp): each reads a
// whole run (the session's frame log, its events, the robot's links and
// chassis) and holds it to one rule of docs/clients/arduino.md, failing the
// case by RC_ASSERT.

#include <rapidcheck.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "tests/property/arduino_rig.hpp"

namespace hil::client::arduino::prop {
namespace {

bool is_bad_cs(const proto::Message& m) {
  const auto* n = std::get_if<proto::Nack>(&m.body);
  return n != nullptr &&
         n->error == std::variant<proto::NackCode, std::string>(proto::NackCode::bad_cs);
}

/// The wire's TX frames grouped into exchanges; each frame of one after its
/// first is held to its time, as a BAD_CS resend or as a retry.
std::vector<Exchange> read_exchanges(const ClientConfig& config,
                                     const std::vector<WireFrame>& wire) {
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
  return out;
}

/// A port the client reopened by itself (not the operator's open) is
/// proved by a PING sent the instant it opens: that exchange is the
/// reconnect check, with its own retry count.
void mark_reopened_ports(const ArduinoRig& rig, const std::vector<WireFrame>& wire,
                         std::vector<Exchange>& exchanges) {
  for (Time opened : rig.car_opens) {
    if (std::count(rig.operator_opens.begin(), rig.operator_opens.end(), opened) != 0) continue;
    Exchange* first = nullptr;
    for (auto& x : exchanges) {
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
}

/// From DEGRADED until the link is OPEN again (or CLOSED, DOWN) only the
/// proving PINGs go out (the board has just reset; nothing queued may
/// reach it before it answered), also on a port the robot turned away.
void mark_reconnecting(const ArduinoRig& rig, const std::vector<WireFrame>& wire,
                       std::vector<Exchange>& exchanges) {
  // A frame logged after the operator opened the port in the instant the
  // link went DOWN belongs to the new port, not to the reconnect.
  auto after_operator_open = [&](std::size_t index, Time at) {
    for (std::size_t k = 0; k < rig.operator_opens.size(); ++k) {
      if (rig.operator_opens[k] == at && index >= rig.logged_at_operator_open[k]) return true;
    }
    return false;
  };
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
    for (auto& x : exchanges) {
      const Time began = wire[x.first].at;
      // The last attempt may fail (and the link go DOWN) in the instant it began.
      if (began > from &&
          (!to || began < *to || (down && began == *to && !after_operator_open(x.first, began)))) {
        RC_ASSERT(std::holds_alternative<proto::Ping>(wire[x.first].message->body));
        x.reconnect_check = true;
      }
    }
  }
}

}  // namespace

std::vector<Exchange> check_attempt_times(const ArduinoRig& rig,
                                          const std::vector<WireFrame>& wire) {
  const ClientConfig& config = rig.session->core().config();
  std::vector<Exchange> out = read_exchanges(config, wire);
  mark_reopened_ports(rig, wire, out);
  mark_reconnecting(rig, wire, out);
  for (const auto& x : out) {
    RC_ASSERT(x.retries <=
              (x.reconnect_check ? config.reconnect_ping_retries : config.max_retries));
    RC_ASSERT(x.resends <= config.max_bad_cs_resends);
  }
  return out;
}

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

namespace {

/// The link takes only documented edges; RECONNECTING comes 0.5 s after
/// DEGRADED, and OPEN after RECONNECTING in the instant the ACK to its PING
/// came in.
void check_edges(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
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
}

/// OPEN degrades only in the instant a request or the health check ran out
/// of attempts or the port closed under it; and every request that ran out
/// of attempts degrades it then.
void check_degrades(const ArduinoRig& rig, const std::vector<WireFrame>& wire,
                    const std::vector<Exchange>& exchanges) {
  const ClientConfig& config = rig.session->core().config();
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
}

/// Reopen attempts: within one DEGRADED series the next attempt's PING goes
/// out 0.5 s x 2^failures after the previous attempt failed (timed exactly
/// when it failed by its full timeout, not by the port closing), and DOWN
/// comes with the max_reconnect_attempts-th failure.
void check_reopen_delays(const ArduinoRig& rig, const std::vector<WireFrame>& wire,
                         const std::vector<Exchange>& exchanges) {
  const ClientConfig& config = rig.session->core().config();
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

}  // namespace

void check_link_states(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
  check_edges(rig, wire);
  const auto exchanges = check_attempt_times(rig, wire);
  check_degrades(rig, wire, exchanges);
  check_reopen_delays(rig, wire, exchanges);
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

}  // namespace hil::client::arduino::prop
