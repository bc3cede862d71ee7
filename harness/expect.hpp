#pragma once
// Checks expectations against a run's timeline: finds the window, counts
// what matches in it, and explains a failure with the evidence around it.

#include <optional>
#include <vector>

#include "harness/outcome.hpp"
#include "harness/scenario.hpp"
#include "harness/timeline.hpp"

namespace hil::harness {

/// Does `record` match? (source, kind, and every field test.)
bool matches(const Matcher& matcher, const Record& record);

/// When the anchor falls in this timeline; nullopt when its event never
/// happened (then the expectation fails, saying so).
std::optional<Time> resolve(const Anchor& anchor, const Timeline& timeline);

/// The verdict on one expectation for a run that ended at `run_end`.
ExpectationOutcome check(const Expectation& expectation, const Timeline& timeline, Time run_end);

/// Every expectation of a scenario, in order.
std::vector<ExpectationOutcome> check_all(const std::vector<Expectation>& expectations,
                                          const Timeline& timeline, Time run_end);

}  // namespace hil::harness
