#pragma once
// Drives a FaultInjector the way the virtual-time driver does: writes go in
// at their times, and the injector is polled at exactly every time it asks
// for, so every delivery's time is exact.

#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "link/faults/fault_injector.hpp"
#include "link/protocol_adapter.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::link::test {

using protocol::Bytes;
using namespace std::chrono_literals;

struct Write {
  Time at{0};
  Bytes bytes;
};

struct Output {
  Time at{0};
  InjectorOutput what;
};

struct Run {
  std::vector<Output> outputs;
  std::vector<FaultEvent> events;

  /// Every delivered byte, in order.
  Bytes delivered() const {
    Bytes all;
    for (const auto& o : outputs) {
      if (const auto* d = std::get_if<Delivery>(&o.what))
        all.insert(all.end(), d->bytes.begin(), d->bytes.end());
    }
    return all;
  }
  std::vector<Output> deliveries() const {
    std::vector<Output> out;
    for (const auto& o : outputs) {
      if (std::holds_alternative<Delivery>(o.what)) out.push_back(o);
    }
    return out;
  }
  const LinkBreak* link_break() const {
    for (const auto& o : outputs) {
      if (const auto* b = std::get_if<LinkBreak>(&o.what)) return b;
    }
    return nullptr;
  }
  std::vector<FaultEvent> events_of(FaultKind kind) const {
    std::vector<FaultEvent> out;
    for (const auto& e : events) {
      if (e.kind == kind) out.push_back(e);
    }
    return out;
  }
};

/// Polls `injector` at each time it is due, up to and including `until`.
inline void poll_until(FaultInjector& injector, Time until, Run& run) {
  std::vector<InjectorOutput> out;
  for (int guard = 0; guard < 1'000'000; ++guard) {
    const auto due = injector.next_due();
    if (!due || *due > until) return;
    out.clear();
    injector.poll(*due, out);
    for (auto& o : out)
      run.outputs.push_back(Output{*due, std::move(o)});
  }
}

/// Pushes every write at its time (times must not decrease), then, when
/// `finish` is set, ends the stream at the last write's time and drains.
/// Without `finish` it drains until `drain_until`.
inline Run drive(FaultInjector& injector, const std::vector<Write>& writes, bool finish = true,
                 Time drain_until = Time::max()) {
  Run run;
  std::vector<InjectorOutput> out;
  Time now{0};
  for (const auto& w : writes) {
    poll_until(injector, w.at, run);
    now = w.at;
    injector.push(now, w.bytes);
    out.clear();
    injector.poll(now, out);
    for (auto& o : out)
      run.outputs.push_back(Output{now, std::move(o)});
  }
  if (finish) {
    injector.finish(now);
    out.clear();
    injector.poll(now, out);
    for (auto& o : out)
      run.outputs.push_back(Output{now, std::move(o)});
  }
  poll_until(injector, drain_until, run);
  return run;
}

/// An injector framing by `adapter` whose events land in `run_events`.
inline std::unique_ptr<FaultInjector> make_injector(std::shared_ptr<const ProtocolAdapter> adapter,
                                                    FaultProfile profile,
                                                    std::vector<FaultEvent>& run_events,
                                                    std::uint64_t seed = 1,
                                                    Direction direction = Direction::to_car) {
  return std::make_unique<FaultInjector>(
      direction, std::move(adapter), std::move(profile), seed,
      [&run_events](const FaultEvent& e) { run_events.push_back(e); });
}

/// An injector for `protocol`'s default profile.
inline std::unique_ptr<FaultInjector> make_injector(const std::string& protocol,
                                                    FaultProfile profile,
                                                    std::vector<FaultEvent>& run_events,
                                                    std::uint64_t seed = 1,
                                                    Direction direction = Direction::to_car) {
  return make_injector(protocol_adapter(protocol), std::move(profile), run_events, seed, direction);
}

/// Drives a fresh injector framing by `adapter` and returns the run with its events.
inline Run run_injector(std::shared_ptr<const ProtocolAdapter> adapter, FaultProfile profile,
                        const std::vector<Write>& writes, std::uint64_t seed = 1,
                        bool finish = true) {
  std::vector<FaultEvent> events;
  auto injector = make_injector(std::move(adapter), std::move(profile), events, seed);
  Run run = drive(*injector, writes, finish);
  run.events = std::move(events);
  return run;
}

/// The same for `protocol`'s default profile.
inline Run run_injector(const std::string& protocol, FaultProfile profile,
                        const std::vector<Write>& writes, std::uint64_t seed = 1,
                        bool finish = true) {
  return run_injector(protocol_adapter(protocol), std::move(profile), writes, seed, finish);
}

/// What a receiver framing by `adapter` makes of a byte stream.
inline std::vector<WireFrame> decode(const ProtocolAdapter& adapter, const Bytes& stream) {
  auto splitter = adapter.splitter();
  std::vector<WireFrame> frames;
  splitter->feed(stream, frames);
  splitter->finish(frames);
  return frames;
}

/// What a receiver of `protocol`'s default profile makes of a byte stream.
inline std::vector<WireFrame> decode(const std::string& protocol, const Bytes& stream) {
  return decode(*protocol_adapter(protocol), stream);
}

inline FaultRule rule(FaultAction action, Trigger trigger = {}, TimeWindow window = {}) {
  FaultRule r;
  r.action = std::move(action);
  r.trigger = std::move(trigger);
  r.window = window;
  return r;
}

inline FaultProfile profile_of(std::vector<FaultRule> rules) {
  return FaultProfile{std::move(rules)};
}

inline Bytes concat(const std::vector<Bytes>& parts) {
  Bytes all;
  for (const auto& p : parts)
    all.insert(all.end(), p.begin(), p.end());
  return all;
}

}  // namespace hil::link::test
