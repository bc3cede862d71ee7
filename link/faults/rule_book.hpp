#pragma once
// Part of the fault injector (fault_injector.hpp): the rules of one
// direction and what each has counted so far, and the decision whether a
// rule acts on a frame or, for rules with `at`, when it fires.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "link/faults/profile.hpp"
#include "link/faults/random.hpp"
#include "link/protocol_adapter.hpp"
#include "link/time.hpp"

namespace hil::link::faults {

class RuleBook {
 public:
  /// Replaces the rules with `profile` (already valid) for direction `d`.
  /// The time triggers still to come at `now` are armed; every counter
  /// starts again, except the bytes a limit_data rule has let pass when the
  /// new profile keeps that rule (same name, same limit): a link's limit
  /// is not lifted by changing its other rules.
  void install(FaultProfile profile, Direction d, Time now);

  const FaultProfile& profile() const { return profile_; }
  std::size_t size() const { return profile_.rules.size(); }
  const FaultRule& rule(std::size_t i) const { return profile_.rules[i]; }
  /// Rule `i`'s action when it is of kind `Action`, else nullptr.
  template <class Action>
  const Action* action(std::size_t i) const {
    return std::get_if<Action>(&profile_.rules[i].action);
  }
  /// The rule's name for events: its own, or "#<n>" after its position.
  std::string name(std::size_t i) const;

  /// Whether rule `i` is for this direction.
  bool applies(std::size_t i) const { return state_[i].applies; }
  /// Whether no rule is for this direction.
  bool none_apply() const;

  /// Whether rule `i` acts on frame number `n` arriving at `now`. Counts the
  /// frame towards `first`/`every` and draws `probability` from `rng` only
  /// once the cheaper conditions hold, so the random stream depends on
  /// nothing else. `applicable` false (the frame has no place for the
  /// action) rejects the frame before anything is counted.
  bool selected(std::size_t i, const WireFrame& frame, Time now, std::uint64_t n, FaultRandom& rng,
                bool applicable = true);

  /// The first bandwidth rule for this direction active at `t`.
  std::optional<std::size_t> bandwidth_at(Time t) const;

  /// Whether rule `i` has a time trigger still to fire.
  bool armed(std::size_t i) const { return state_[i].armed; }
  void disarm(std::size_t i) { state_[i].armed = false; }
  /// The armed rule that fires first by `now`, and before `before` when
  /// that is set; the first in profile order at equal times.
  std::optional<std::size_t> first_armed(Time now, std::optional<Time> before) const;
  /// When the next armed rule fires.
  std::optional<Time> next_armed() const;

  /// Bytes limit_data rule `i` has let pass so far.
  std::uint64_t& bytes_passed(std::size_t i) { return state_[i].bytes_passed; }

  /// The refuse rule that refuses a connection at `now`, and when its
  /// refusal ends.
  std::optional<std::pair<std::size_t, Time>> refusing(Time now) const;

 private:
  struct RuleState {
    bool applies = false;            // the rule is for this direction
    bool armed = false;              // a time trigger still to fire
    std::uint64_t matched = 0;       // frames that passed window and match
    std::uint64_t bytes_passed = 0;  // limit_data: bytes let through
  };

  FaultProfile profile_;
  std::vector<RuleState> state_;
};

}  // namespace hil::link::faults
