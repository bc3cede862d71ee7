#pragma once
// Checks expectations against a run's timeline: finds the window, counts
// what matches in it, and explains a failure with the evidence around it.

#include <optional>
#include <vector>

#include "harness/origin.hpp"
#include "harness/outcome.hpp"
#include "harness/scenario.hpp"
#include "harness/timeline.hpp"

namespace hil::harness {

/// Does `record` match? (source, kind, and every field test.)
bool matches(const Matcher& matcher, const Record& record);

/// When the anchor falls in this timeline: a run time counts from
/// `origin`, an event is looked for in the records up to `until`; nullopt
/// when its event never happened (then the expectation fails, saying so).
std::optional<Time> resolve(const Anchor& anchor, const Timeline& timeline, Time origin = Time(0),
                            Time until = Time::max());

/// The verdict on one expectation for a run that ended at `run_end`.
/// `slack` is room for a run in real time, where frames and events come
/// some milliseconds later than in virtual time: a window edge that is a
/// run time or lies `within` after another edge is known only to within
/// `slack`, so what must happen (exists, at_least, the lower bound of
/// exactly) may fall in the window widened by it, what must not (never,
/// at_most, the upper bound of exactly, always) is looked for in the
/// window narrowed by it, and `times` get it on their tolerance. Edges
/// that are events or the end of the run stay put. Zero changes nothing.
/// Run times (`at: 5s`, `between`, a window without an event) count from
/// `origin`, which a failure's message names when it is not the run's start.
ExpectationOutcome check(const Expectation& expectation, const Timeline& timeline, Time run_end,
                         Duration slack = Duration(0), const Origin& origin = {});

/// Every expectation of a scenario, in order.
std::vector<ExpectationOutcome> check_all(const std::vector<Expectation>& expectations,
                                          const Timeline& timeline, Time run_end,
                                          Duration slack = Duration(0), const Origin& origin = {});

}  // namespace hil::harness
