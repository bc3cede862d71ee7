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

}  // namespace hil::test
