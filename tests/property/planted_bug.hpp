#pragma once
// Known bugs planted in the LOGI client on purpose, so the property tests
// can show that they catch each one: a LogiClientCore that breaks one of the
// protocol's rules (its protected rule functions, overridden here), and a
// session over it.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "client/common/connecting_session.hpp"
#include "client/logi/core.hpp"

namespace hil::client::logi::prop {

enum class PlantedBug : std::uint8_t {
  none,
  no_backoff,                  ///< reconnect at once after every loss
  retry_run,                   ///< ST:RUN is resent after a timeout like SP
  no_stop_on_release,          ///< release() sends no MV:STOP
  read_is_frame,               ///< each read is decoded alone: a partial frame is dropped
  stale_at_5s,                 ///< the stale warning waits 5 s instead of stale_after
  no_sp_retry,                 ///< SP is never resent after a timeout
  st_stop_first,               ///< the emergency stop writes ST:STOP before MV:STOP
  st_stop_once,                ///< the emergency stop's ST:STOP is not resent until answered
  no_stop_after_move_timeout,  ///< a timed-out MV:<dir> is not followed by MV:STOP
  stale_at_2s,                 ///< the stale warning rises at exactly 2 s, not after
  any_frame_clears_stale,      ///< any valid frame (an FB too) counts as fresh telemetry
};

/// A planted bug and the name HIL_LOGI_PLANTED_BUG gives it.
struct PlantedBugName {
  PlantedBug bug;
  std::string_view name;
};

/// Every planted bug with its name, `none` first: the one list that names
/// them, for the properties program and for whatever runs once per bug.
inline constexpr PlantedBugName kPlantedBugs[] = {
    {PlantedBug::none, "none"},
    {PlantedBug::no_backoff, "no_backoff"},
    {PlantedBug::retry_run, "retry_run"},
    {PlantedBug::no_stop_on_release, "no_stop_on_release"},
    {PlantedBug::read_is_frame, "read_is_frame"},
    {PlantedBug::stale_at_5s, "stale_at_5s"},
    {PlantedBug::no_sp_retry, "no_sp_retry"},
    {PlantedBug::st_stop_first, "st_stop_first"},
    {PlantedBug::st_stop_once, "st_stop_once"},
    {PlantedBug::no_stop_after_move_timeout, "no_stop_after_move_timeout"},
    {PlantedBug::stale_at_2s, "stale_at_2s"},
    {PlantedBug::any_frame_clears_stale, "any_frame_clears_stale"},
};
// In the enum's order, one entry per bug: a bug added to the enum must be
// added here (the last bug's value is the table's last index).
static_assert([] {
  for (std::size_t i = 0; i < std::size(kPlantedBugs); ++i) {
    if (static_cast<std::size_t>(kPlantedBugs[i].bug) != i) return false;
  }
  return std::size(kPlantedBugs) ==
         static_cast<std::size_t>(PlantedBug::any_frame_clears_stale) + 1;
}());

/// The LOGI client core with `bug` planted (none: the client as shipped).
class PlantedBugCore : public LogiClientCore {
 public:
  PlantedBugCore(PlantedBug bug, ClientConfig config)
      : LogiClientCore(std::move(config)), bug_(bug) {}

 protected:
  bool retryable(const proto::Message& m) const override {
    if (const auto* st = std::get_if<proto::SetRun>(&m);
        st && st->run && planted(PlantedBug::retry_run))
      return true;
    if (std::holds_alternative<proto::SetSpeed>(m) && planted(PlantedBug::no_sp_retry))
      return false;
    return LogiClientCore::retryable(m);
  }
  Time reconnect_time(Time now, Duration delay) const override {
    return planted(PlantedBug::no_backoff) ? now : LogiClientCore::reconnect_time(now, delay);
  }
  Duration stale_after() const override {
    return planted(PlantedBug::stale_at_5s) ? link::seconds(5) : LogiClientCore::stale_after();
  }
  Time stale_at(Time last_stat) const override {
    if (planted(PlantedBug::stale_at_2s)) return last_stat + stale_after();
    return LogiClientCore::stale_at(last_stat);
  }
  bool refreshes_status(const proto::Message& m) const override {
    return planted(PlantedBug::any_frame_clears_stale) || LogiClientCore::refreshes_status(m);
  }
  bool resend_until_answered(const proto::Message& m) const override {
    return !planted(PlantedBug::st_stop_once) && LogiClientCore::resend_until_answered(m);
  }
  bool stop_after_timeout(const proto::Message& m) const override {
    return !planted(PlantedBug::no_stop_after_move_timeout) &&
           LogiClientCore::stop_after_timeout(m);
  }
  bool stop_on_release() const override { return !planted(PlantedBug::no_stop_on_release); }
  std::vector<proto::Message> emergency_stop_commands() const override {
    auto commands = LogiClientCore::emergency_stop_commands();
    if (planted(PlantedBug::st_stop_first)) std::reverse(commands.begin(), commands.end());
    return commands;
  }
  void decode(protocol::ByteView bytes, std::vector<proto::Item>& items) override {
    if (!planted(PlantedBug::read_is_frame)) return LogiClientCore::decode(bytes, items);
    proto::Decoder alone(config().decoder);  // what an earlier read left is lost
    alone.feed(bytes, items);
  }

 private:
  bool planted(PlantedBug bug) const { return bug_ == bug; }

  PlantedBug bug_;
};

/// A LogiSession over a PlantedBugCore.
class PlantedBugSession
    : public ConnectingSession<PlantedBugCore, Event, OpenConnection, SendBytes, CloseConnection> {
 public:
  PlantedBugSession(link::TransportContext& context, link::Endpoint endpoint, PlantedBug bug,
                    ClientConfig config, EventSink sink)
      : ConnectingSession(context, std::move(endpoint), std::move(sink),
                          PlantedBugCore(bug, std::move(config))) {}

  /// Runs `f(core, now)`, an operator call on the core, and performs what
  /// it caused; returns what `f` returns.
  template <class F>
  auto call(F&& f) {
    return feed([&](Time t) { return f(mutable_core(), t); });
  }
};

}  // namespace hil::client::logi::prop
