#include "client/common/connection.hpp"

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <utility>

namespace hil::client {

// In the order the scenario language lists them.
constexpr base::EnumNames<ConnectionState, 7> kConnectionStateNames =
    base::enum_names<ConnectionState>(
        {ConnectionState::connected, "connected"}, {ConnectionState::disconnected, "disconnected"},
        {ConnectionState::connecting, "connecting"},
        {ConnectionState::authenticating, "authenticating"},
        {ConnectionState::reconnecting, "reconnecting"}, {ConnectionState::degraded, "degraded"},
        {ConnectionState::down, "down"});

std::string_view to_string(ConnectionState s) {
  return kConnectionStateNames.name(s);
}

Backoff Backoff::ladder(std::vector<link::Duration> delays) {
  if (delays.empty()) throw std::invalid_argument("a reconnect ladder needs at least one delay");
  Backoff b;
  b.ladder_ = std::move(delays);
  return b;
}

Backoff Backoff::doubling(link::Duration first) {
  Backoff b;
  b.first_ = first;
  return b;
}

link::Duration Backoff::delay(int attempt) const {
  const int index = std::max(attempt, 1) - 1;
  if (ladder_.empty()) return first_ * (std::int64_t{1} << index);
  return ladder_[std::min(static_cast<std::size_t>(index), ladder_.size() - 1)];
}

link::Duration ReconnectSchedule::schedule(link::Time now) {
  const link::Duration d = next_delay();
  schedule_at(now + d);
  return d;
}

void ReconnectSchedule::schedule_at(link::Time at) {
  ++attempt_;
  due_ = at;
}

bool ReconnectSchedule::take_due(link::Time now) {
  if (!due_ || now < *due_) return false;
  due_.reset();
  return true;
}

bool ConnectionLifecycle::active() const {
  return state_ == ConnectionState::connecting || state_ == ConnectionState::authenticating ||
         state_ == ConnectionState::connected;
}

std::optional<ConnectionEvent> ConnectionLifecycle::set(ConnectionState s, int attempt) {
  if (s == state_) return std::nullopt;
  state_ = s;
  return ConnectionEvent{s, attempt};
}

bool ConnectionLifecycle::want() {
  wanted_ = true;
  if (active()) return false;
  reconnect_.cancel();
  return true;
}

bool ConnectionLifecycle::unwant() {
  wanted_ = false;
  reconnect_.reset();
  return active();
}

std::optional<ConnectionEvent> ConnectionLifecycle::retry_at(link::Time at) {
  if (!wanted_) return set(ConnectionState::disconnected);
  reconnect_.schedule_at(at);
  return set(ConnectionState::reconnecting, reconnect_.attempt());
}

std::optional<int> ConnectionLifecycle::take_due_attempt(link::Time now) {
  if (state_ != ConnectionState::reconnecting || !reconnect_.take_due(now)) return std::nullopt;
  return reconnect_.attempt();
}

}  // namespace hil::client
