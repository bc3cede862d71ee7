#pragma once
// Random fault profiles for the property tests, drawn rule by rule inside
// rc::gen::exec, so a failing session shrinks to fewer and milder faults.

#include <utility>

#include <rapidcheck.h>

#include "link/faults/profile.hpp"

namespace hil::test {

class RandomFaults {
 public:
  /// Each rule that fires by chance does so with 1..max_percent %.
  explicit RandomFaults(int max_percent) : max_percent_(max_percent) {}

  /// Heads or tails: whether to add the next rule.
  static bool coin() { return *rc::gen::arbitrary<bool>(); }

  /// `action` on a random direction, firing with a random chance.
  void add_sometimes(link::FaultAction action) {
    add(direction(), sometimes(*rc::gen::inRange(1, max_percent_ + 1) / 100.0), std::move(action));
  }

  /// By chance (heads), `action` as add_sometimes() adds it.
  void maybe(link::FaultAction action) {
    if (coin()) add_sometimes(std::move(action));
  }

  /// By chance (heads), a delay of 0..max_ms, plus 0..max_ms of jitter.
  void maybe_delay(int max_ms) {
    if (coin())
      add_sometimes(link::Delay{link::milliseconds(*rc::gen::inRange(0, max_ms)),
                                link::milliseconds(*rc::gen::inRange(0, max_ms))});
  }

  /// By chance (heads), writes cut into pieces of 1..8 bytes, 0..30 ms apart.
  void maybe_fragment() {
    if (coin()) {
      const auto piece = *rc::gen::inRange<std::size_t>(1, 9);
      add_sometimes(link::Fragment{
          {1, piece}, {link::Duration::zero(), link::milliseconds(*rc::gen::inRange(0, 30))}});
    }
  }

  /// Up to two stalls of 100 ms .. max_stall_ms at random times in the
  /// first minute, each on a random direction.
  void add_stalls(int max_stall_ms) {
    for (int i = *rc::gen::inRange(0, 3); i > 0; --i)
      add(direction(), at(link::milliseconds(*rc::gen::inRange(0, 60'000))),
          link::Stall{link::milliseconds(*rc::gen::inRange(100, max_stall_ms))});
  }

  /// Up to two link breaks (a reset or a disconnect) in the first minute.
  void add_breaks() {
    for (int i = *rc::gen::inRange(0, 3); i > 0; --i) {
      const link::Time when{link::milliseconds(*rc::gen::inRange(0, 60'000))};
      if (coin())
        add(link::DirectionFilter::both, at(when), link::Reset{});
      else
        add(link::DirectionFilter::both, at(when), link::Disconnect{});
    }
  }

  /// The profile drawn so far, checked.
  link::FaultProfile take() {
    link::validate(profile_);
    return std::move(profile_);
  }

 private:
  static link::DirectionFilter direction() {
    return *rc::gen::element(link::DirectionFilter::both, link::DirectionFilter::to_car,
                             link::DirectionFilter::to_client);
  }
  static link::Trigger sometimes(double p) {
    link::Trigger t;
    t.probability = p;
    return t;
  }
  static link::Trigger at(link::Time when) {
    link::Trigger t;
    t.at = when;
    return t;
  }
  void add(link::DirectionFilter d, link::Trigger trigger, link::FaultAction action) {
    link::FaultRule rule;
    rule.direction = d;
    rule.trigger = std::move(trigger);
    rule.action = std::move(action);
    profile_.rules.push_back(std::move(rule));
  }

  int max_percent_;
  link::FaultProfile profile_;
};

/// Faults that change no byte a client reads, for protocols without a
/// checksum (a changed byte would be another valid packet): sometimes drops,
/// duplicates, delays of up to max_delay_ms, fragments and coalesced writes,
/// each firing with 1..max_percent %; stalls of up to max_stall_ms; breaks.
inline rc::Gen<link::FaultProfile> gen_faults_without_corruption(int max_percent, int max_delay_ms,
                                                                 int max_stall_ms) {
  return rc::gen::exec([=] {
    RandomFaults faults(max_percent);
    faults.maybe(link::Drop{});
    faults.maybe(link::Duplicate{1});
    faults.maybe_delay(max_delay_ms);
    faults.maybe_fragment();
    if (RandomFaults::coin())
      faults.add_sometimes(link::Coalesce{*rc::gen::inRange<std::size_t>(2, 6),
                                          link::milliseconds(*rc::gen::inRange(1, 300))});
    faults.add_stalls(max_stall_ms);
    faults.add_breaks();
    return faults.take();
  });
}

}  // namespace hil::test
