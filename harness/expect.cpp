#include "harness/expect.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

#include "base/duration.hpp"
#include "harness/expect_parts.hpp"
#include "mocks/behaviour.hpp"

namespace hil::harness {
namespace expect_parts {

// Evidence limits: enough to see what happened around a verdict without
// burying the report.
constexpr std::size_t max_matches_in_evidence = 10;
constexpr std::size_t max_evidence = 20;
constexpr Duration evidence_margin = std::chrono::milliseconds(500);

using Json = nlohmann::json;

// -------------------------------------------------------------- matching

bool is_number(const Json& j) {
  return j.is_number();
}

bool json_equal(const Json& a, const Json& b) {
  // 2 == 2.0: QA writes numbers without caring how the record stored them.
  if (is_number(a) && is_number(b)) return a.get<double>() == b.get<double>();
  return a == b;
}

/// The record's value of `field`: a key of its data, or a path into an
/// object of it ("fields.percent"); nullptr when there is none.
const Json* field_of(const Record& record, const std::string& field) {
  if (!record.data.is_object()) return nullptr;
  if (const auto it = record.data.find(field); it != record.data.end()) return &*it;
  const Json* at = &record.data;
  std::size_t from = 0;
  while (true) {
    const auto dot = field.find('.', from);
    if (!at->is_object()) return nullptr;
    const auto it = at->find(field.substr(from, dot == std::string::npos ? dot : dot - from));
    if (it == at->end()) return nullptr;
    at = &*it;
    if (dot == std::string::npos) return at;
    from = dot + 1;
  }
}

bool test_holds(const FieldTest& test, const Record& record) {
  Json kind_value;
  const Json* value = nullptr;
  if (test.field == "kind") {
    kind_value = std::string(record.kind.name());
    value = &kind_value;
  } else {
    value = field_of(record, test.field);
  }
  if (value == nullptr) return test.op == FieldTest::Op::not_equals;

  switch (test.op) {
    case FieldTest::Op::equals:
      return json_equal(*value, test.value);
    case FieldTest::Op::not_equals:
      return !json_equal(*value, test.value);
    case FieldTest::Op::kind_prefix:
      return value->is_string() && test.value.is_string() &&
             mocks::kind_matches(test.value.get_ref<const std::string&>(),
                                 value->get_ref<const std::string&>());
    case FieldTest::Op::kind_either_prefix: {
      if (!value->is_string() || !test.value.is_string()) return false;
      const auto& wanted = test.value.get_ref<const std::string&>();
      const auto& got = value->get_ref<const std::string&>();
      return mocks::kind_matches(wanted, got) || (!got.empty() && mocks::kind_matches(got, wanted));
    }
    case FieldTest::Op::contains:
      return value->is_string() && test.value.is_string() &&
             value->get_ref<const std::string&>().find(test.value.get_ref<const std::string&>()) !=
                 std::string::npos;
    case FieldTest::Op::less:
    case FieldTest::Op::less_equal:
    case FieldTest::Op::greater:
    case FieldTest::Op::greater_equal: {
      if (!is_number(*value) || !is_number(test.value)) return false;
      const double v = value->get<double>();
      const double limit = test.value.get<double>();
      if (test.op == FieldTest::Op::less) return v < limit;
      if (test.op == FieldTest::Op::less_equal) return v <= limit;
      if (test.op == FieldTest::Op::greater) return v > limit;
      return v >= limit;
    }
  }
  return false;
}

bool same_source_and_kind(const Matcher& matcher, const Record& record) {
  return record.source() == matcher.source && (!matcher.kind || record.kind == *matcher.kind);
}

/// Tests that say which records a matcher is about rather than what they
/// must hold: a wire frame's direction, stage and kind. `always` judges
/// every STAT the client received, not every frame on the wire.
bool selects(const Matcher& matcher, const FieldTest& test) {
  return matcher.source == Source::wire &&
         (test.field == "dir" || test.field == "stage" || test.field == "frame");
}

/// The records `always` judges: the matcher's source and kind, and its
/// selecting tests.
bool judged_by(const Matcher& matcher, const Record& record) {
  if (!same_source_and_kind(matcher, record)) return false;
  return std::all_of(matcher.tests.begin(), matcher.tests.end(), [&](const FieldTest& test) {
    return !selects(matcher, test) || test_holds(test, record);
  });
}

/// What a failing record had in the fields its tests looked at.
std::string failed_fields_text(const Matcher& matcher, const Record& record) {
  std::string text;
  for (const auto& test : matcher.tests) {
    if (test_holds(test, record)) continue;
    if (!text.empty()) text += ", ";
    if (test.field == "kind") {
      text += "kind = " + Json(std::string(record.kind.name())).dump();
    } else if (const Json* value = field_of(record, test.field)) {
      text += test.field + " = " + value->dump();
    } else {
      text += "no " + test.field;
    }
  }
  return text;
}

// -------------------------------------------------------------- evidence

/// `chosen` first (the matches, at most ten), then records of `source` near
/// the window's edges that are not among `candidates` left out by the cap.
std::vector<Record> evidence_of(const Timeline& timeline, std::vector<std::size_t> chosen,
                                const std::vector<std::size_t>& candidates, Source source,
                                Time from, Time to) {
  if (chosen.size() > max_matches_in_evidence) chosen.resize(max_matches_in_evidence);
  const auto& records = timeline.records();
  const auto near_edge = [&](Time at) {
    const auto close = [&](Time edge) {
      return at >= edge - evidence_margin && at <= edge + evidence_margin;
    };
    return close(from) || close(to);
  };
  for (std::size_t i = 0; i < records.size() && chosen.size() < max_evidence; ++i) {
    if (records[i].source() != source || !near_edge(records[i].at)) continue;
    if (std::find(candidates.begin(), candidates.end(), i) != candidates.end() &&
        std::find(chosen.begin(), chosen.end(), i) == chosen.end())
      continue;
    if (std::find(chosen.begin(), chosen.end(), i) == chosen.end()) chosen.push_back(i);
  }
  std::sort(chosen.begin(), chosen.end());
  std::vector<Record> evidence;
  evidence.reserve(chosen.size());
  for (const auto i : chosen)
    evidence.push_back(records[i]);
  std::stable_sort(evidence.begin(), evidence.end(),
                   [](const Record& a, const Record& b) { return a.at < b.at; });
  return evidence;
}

/// "5.812 s, 0.512 s late" for the match outside [from, to] closest to it.
struct Nearest {
  std::size_t index = 0;
  Time at{0};
  std::string text;
};

std::optional<Nearest> nearest_outside(const Timeline& timeline,
                                       const std::vector<std::size_t>& all, Time from, Time to) {
  std::optional<Nearest> best;
  Duration best_distance{0};
  for (const auto i : all) {
    const Time at = timeline.records()[i].at;
    if (at >= from && at <= to) continue;
    const Duration distance = at < from ? from - at : at - to;
    if (!best || distance < best_distance) {
      best_distance = distance;
      best = Nearest{i, at,
                     hil::seconds_text(at, 3) + ", " + hil::seconds_text(distance, 3) +
                         (at < from ? " early" : " late")};
    }
  }
  return best;
}

// -------------------------------------------------------------- judging

ExpectationOutcome start_outcome(const Expectation& e) {
  ExpectationOutcome outcome;
  outcome.line = e.line;
  outcome.label = e.label.empty() ? expectation_label(e) : e.label;
  return outcome;
}

/// The verdict when the event the window starts at never happened, with
/// what did match that event as evidence.
ExpectationOutcome missing_anchor_outcome(const Expectation& e, const Timeline& timeline,
                                          ExpectationOutcome outcome) {
  const Matcher& event = *e.window.from.event;
  std::vector<std::size_t> seen;
  for (std::size_t i = 0; i < timeline.size(); ++i)
    if (matches(event, timeline.records()[i])) seen.push_back(i);
  outcome.passed = false;
  outcome.message = "expected " + outcome.label + ", but " + anchor_text(e.window.from, false) +
                    " never happened";
  if (!seen.empty())
    outcome.message += " (" + matcher_text(event) + " happened " + count_text(seen.size()) + ")";
  if (seen.size() > max_matches_in_evidence) seen.resize(max_matches_in_evidence);
  for (const auto i : seen)
    outcome.evidence.push_back(timeline.records()[i]);
  return outcome;
}

/// The window an expectation is judged in: its edges as resolved and, for
/// a run in real time, as widened (what must happen may fall there) and
/// narrowed (what must not is looked for there) by the slack.
struct ExpectWindow {
  Time from{0};
  Time to{0};
  /// Where `times` count from: the window's anchor (`from` but for a
  /// window from the start, which opens at the run's start so that what
  /// came before the origin is not missed, and whose times count from the
  /// origin).
  Time times_from{0};
  Time wide_from{0};
  Time wide_to{0};
  Time narrow_from{0};
  Time narrow_to{0};
  /// "between 5.000 s and 5.300 s (within 300 ms after ...)" for messages.
  std::string where;

  bool in_wide(Time at) const { return at >= wide_from && at <= wide_to; }
  bool in_narrow(Time at) const { return at >= narrow_from && at <= narrow_to; }
};

ExpectWindow expect_window(const Expectation& e, Time from, Time run_end, Duration slack,
                           const Origin& origin) {
  ExpectWindow w;
  const bool from_the_start = !e.window.from.event && e.window.from.offset == Duration(0);
  w.from = from_the_start ? Time(0) : from;
  w.times_from = from;
  w.to = e.window.within ? from + *e.window.within : run_end;
  // With slack (real time) the edges are known only to within it: what
  // must happen may fall in the wider window, what must not is looked for
  // in the narrower one. An edge that is an event or the end of the run
  // is where it is; a run time or an edge `within` after one moves.
  const bool movable_start = !e.window.from.event && slack > Duration(0);
  const bool movable_end = e.window.within.has_value() && slack > Duration(0);
  w.wide_from = movable_start ? std::max(Time(0), w.from - slack) : w.from;
  w.wide_to = movable_end ? w.to + slack : w.to;
  w.narrow_from = movable_start ? w.from + slack : w.from;
  w.narrow_to = movable_end ? std::max(w.narrow_from, w.to - slack) : w.to;
  w.where = "between " + hil::seconds_text(w.from, 3) + " and " + hil::seconds_text(w.to, 3);
  if (e.window.from.event) w.where += " (" + window_text(e.window) + ")";
  if (!e.window.from.event && origin.cause != Origin::Cause::run_start) {
    const std::string written = window_text(e.window);
    w.where += " (" + (written.empty() ? std::string("the run") : written) + " from the origin, " +
               origin_text(origin) + ")";
  }
  if (slack > Duration(0)) w.where += " (± " + hil::seconds_text(slack, 3) + " for real time)";
  return w;
}

/// The records an expectation's matcher matches, as indices into the
/// timeline: all of them, and those in the (wide) window with their times.
struct ExpectMatches {
  std::vector<std::size_t> all;
  std::vector<std::size_t> in_window;
  std::vector<Time> window_times;
};

ExpectMatches find_expect_matches(const Expectation& e, const Timeline& timeline,
                                  const ExpectWindow& w) {
  ExpectMatches m;
  const auto& records = timeline.records();
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (!matches(e.what, records[i])) continue;
    m.all.push_back(i);
    if (w.in_wide(records[i].at)) m.in_window.push_back(i);
  }
  for (const auto i : m.in_window)
    m.window_times.push_back(records[i].at);
  return m;
}

/// `always`: every record the matcher selects in the narrow window holds
/// its tests, and there is at least one.
void check_always(const Expectation& e, const Timeline& timeline, const ExpectWindow& w,
                  ExpectationOutcome& outcome) {
  const auto& records = timeline.records();
  std::vector<std::size_t> judged;
  std::vector<std::size_t> failing;
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (!judged_by(e.what, records[i]) || !w.in_narrow(records[i].at)) continue;
    judged.push_back(i);
    if (!matches(e.what, records[i])) failing.push_back(i);
  }
  const std::string subject = record_kind_text(e.what.source, e.what.kind);
  std::string message =
      "expected every " + subject + " " + w.where + " to satisfy " + quoted(tests_text(e.what));
  if (judged.empty()) {
    outcome.passed = false;
    message += ", but there was no record to judge";
  } else if (failing.empty()) {
    outcome.passed = true;
    message += judged.size() == 1 ? ", and the only one did"
                                  : ", and all " + std::to_string(judged.size()) + " did";
  } else {
    outcome.passed = false;
    std::vector<Time> failing_times;
    for (const auto i : failing)
      failing_times.push_back(records[i].at);
    message += "; " + std::to_string(failing.size()) + " of " + std::to_string(judged.size()) +
               " did not: at " + times_text(failing_times) + " (the first had " +
               failed_fields_text(e.what, records[failing.front()]) + ")";
  }
  outcome.message = std::move(message);
  const auto& shown = failing.empty() ? judged : failing;
  outcome.evidence = evidence_of(timeline, shown, shown, e.what.source, w.from, w.to);
}

/// Which match in the window each of the expectation's times claimed (an
/// index into ExpectMatches::in_window), and which matches were claimed.
struct ClaimedTimes {
  std::vector<std::optional<std::size_t>> claimed;
  std::vector<bool> used;
};

/// Each time claims the earliest unused match within `tolerance` of it;
/// with one tolerance for all, taking times in order makes that
/// assignment succeed whenever any assignment would.
ClaimedTimes claim_times(const Expectation& e, const Timeline& timeline, const ExpectMatches& m,
                         Time from, Duration tolerance) {
  std::vector<std::size_t> order(e.times.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return e.times[a] < e.times[b]; });
  ClaimedTimes c{std::vector<std::optional<std::size_t>>(e.times.size()),
                 std::vector<bool>(m.in_window.size(), false)};
  for (const auto t : order) {
    const Time target = from + e.times[t];
    for (std::size_t k = 0; k < m.in_window.size(); ++k) {
      const Time at = timeline.records()[m.in_window[k]].at;
      if (c.used[k] || at < target - tolerance || at > target + tolerance) continue;
      c.used[k] = true;
      c.claimed[t] = k;
      break;
    }
  }
  return c;
}

/// "; nothing at 5.000 s, the nearest at 5.812 s, 0.812 s late": a time no
/// match claimed, and the nearest match no other time took, wherever it is.
std::string missed_time_text(Time target, const Timeline& timeline, const ExpectMatches& m,
                             const std::vector<bool>& used) {
  std::string text = "; nothing at " + hil::seconds_text(target, 3);
  std::optional<Time> nearest;
  for (const auto i : m.all) {
    const auto pos = std::find(m.in_window.begin(), m.in_window.end(), i);
    if (pos != m.in_window.end() && used[static_cast<std::size_t>(pos - m.in_window.begin())])
      continue;
    const Time at = timeline.records()[i].at;
    const auto distance = [&](Time x) { return x < target ? target - x : x - target; };
    if (!nearest || distance(at) < distance(*nearest)) nearest = at;
  }
  if (!nearest) return text + ", and no other match in the run";
  const Duration off = *nearest - target;
  return text + ", the nearest at " + hil::seconds_text(*nearest, 3) + ", " +
         hil::seconds_text(off < Duration(0) ? -off : off, 3) +
         (off < Duration(0) ? " early" : " late");
}

/// `at` (and `only at`): a match near each time, and with `only` none in
/// the narrow window that no time claimed.
void check_at_times(const Expectation& e, const Timeline& timeline, const ExpectWindow& w,
                    const ExpectMatches& m, Duration slack, ExpectationOutcome& outcome) {
  const auto& records = timeline.records();
  const Duration tolerance = e.tolerance + slack;
  const ClaimedTimes c = claim_times(e, timeline, m, w.times_from, tolerance);

  std::vector<Time> targets;
  for (const auto& t : e.times)
    targets.push_back(w.times_from + t);
  std::string message =
      "expected " + quoted(matcher_text(e.what)) + (e.only ? " only at " : " at ");
  for (std::size_t i = 0; i < targets.size(); ++i)
    message += (i == 0 ? "" : ", ") + hil::seconds_text(targets[i], 3);
  message += " (± " + hil::seconds_text(tolerance, 3) + ") " + w.where;

  std::vector<Time> hit_times;
  std::string missing;
  for (std::size_t t = 0; t < e.times.size(); ++t) {
    if (c.claimed[t])
      hit_times.push_back(records[m.in_window[*c.claimed[t]]].at);
    else
      missing += missed_time_text(targets[t], timeline, m, c.used);
  }
  std::vector<Time> extra_times;
  if (e.only)
    for (std::size_t k = 0; k < m.in_window.size(); ++k)
      if (!c.used[k] && w.in_narrow(records[m.in_window[k]].at))
        extra_times.push_back(records[m.in_window[k]].at);

  outcome.passed = missing.empty() && extra_times.empty();
  message += hit_times.empty() ? ", found none of them" : ", found at " + times_text(hit_times);
  message += missing;
  if (!extra_times.empty())
    message += "; " + std::to_string(extra_times.size()) + " more outside those times: at " +
               times_text(extra_times);
  outcome.message = std::move(message);
  outcome.evidence = evidence_of(timeline, m.in_window, m.in_window, e.what.source, w.from, w.to);
}

/// What a counting quantifier asked for ("exactly 2"), whether the count
/// met it, and whether it failed for want of matches (then the nearest
/// match outside the window is worth showing).
struct CountVerdict {
  std::string wanted;
  bool passed = false;
  bool needs_more = false;
};

/// A lower bound is met by the matches in the wide window (`found`), an
/// upper bound by those in the narrow one (`narrow_found`).
CountVerdict count_verdict(const Expectation& e, std::uint64_t found, std::uint64_t narrow_found) {
  switch (e.quantifier) {
    case Quantifier::exists:
      return {"at least one", found >= 1, true};
    case Quantifier::never:
      return {"no", narrow_found == 0, false};
    case Quantifier::exactly:
      return {"exactly " + std::to_string(e.count), narrow_found <= e.count && e.count <= found,
              found < e.count};
    case Quantifier::at_least:
      return {"at least " + std::to_string(e.count), found >= e.count, true};
    case Quantifier::at_most:
      return {"at most " + std::to_string(e.count), narrow_found <= e.count, false};
    case Quantifier::at_times:
    case Quantifier::always:
      break;
  }
  return {};
}

/// exists, never, exactly, at least, at most: how many matched, against
/// the bound.
void check_counting(const Expectation& e, const Timeline& timeline, const ExpectWindow& w,
                    const ExpectMatches& m, ExpectationOutcome& outcome) {
  const std::uint64_t found = m.in_window.size();
  const auto narrow_found = static_cast<std::uint64_t>(std::count_if(
      m.window_times.begin(), m.window_times.end(), [&](Time at) { return w.in_narrow(at); }));
  const CountVerdict verdict = count_verdict(e, found, narrow_found);
  outcome.passed = verdict.passed;
  // An upper bound failed in the narrow window: show what was found there.
  const bool upper_only = e.quantifier == Quantifier::never || e.quantifier == Quantifier::at_most;
  std::vector<Time> shown_times = m.window_times;
  if (upper_only) std::erase_if(shown_times, [&](Time at) { return !w.in_narrow(at); });
  const std::uint64_t shown_found = upper_only ? narrow_found : found;
  std::string message =
      "expected " + verdict.wanted + " " + quoted(matcher_text(e.what)) + " " + w.where;
  message += shown_found == 0
                 ? ", found none"
                 : ", found " + std::to_string(shown_found) + ": at " + times_text(shown_times);
  std::vector<std::size_t> shown = m.in_window;
  if (!outcome.passed && verdict.needs_more) {
    const auto nearest = nearest_outside(timeline, m.all, w.from, w.to);
    if (nearest) {
      message += (found == 0 ? "; the nearest at " : "; the nearest outside the window at ") +
                 nearest->text;
      shown.insert(shown.begin(), nearest->index);
    } else if (found == 0) {
      message += " in the whole run";
    }
  }
  outcome.message = std::move(message);
  outcome.evidence = evidence_of(timeline, std::move(shown), m.all, e.what.source, w.from, w.to);
}

}  // namespace expect_parts

bool matches(const Matcher& matcher, const Record& record) {
  if (!expect_parts::same_source_and_kind(matcher, record)) return false;
  return std::all_of(matcher.tests.begin(), matcher.tests.end(),
                     [&](const FieldTest& test) { return expect_parts::test_holds(test, record); });
}

std::optional<Time> resolve(const Anchor& anchor, const Timeline& timeline, Time origin,
                            Time until) {
  if (!anchor.event) return origin + anchor.offset;
  std::vector<Time> seen;
  for (const auto& record : timeline.records())
    if (record.at <= until && matches(*anchor.event, record)) seen.push_back(record.at);
  // occurrence n counts from the first (1) or, negative, from the last (-1).
  const long long n = anchor.occurrence;
  const long long size = static_cast<long long>(seen.size());
  long long index = -1;
  if (n > 0 && n <= size) index = n - 1;
  if (n < 0 && -n <= size) index = size + n;
  if (index < 0) return std::nullopt;
  return seen[static_cast<std::size_t>(index)] + anchor.offset;
}

ExpectationOutcome check(const Expectation& e, const Timeline& timeline, Time run_end,
                         Duration slack, const Origin& origin) {
  using namespace expect_parts;
  ExpectationOutcome outcome = start_outcome(e);
  const auto start = resolve(e.window.from, timeline, origin.at, run_end);
  if (!start) return missing_anchor_outcome(e, timeline, std::move(outcome));
  const ExpectWindow w = expect_window(e, *start, run_end, slack, origin);
  outcome.window_from = w.from;
  outcome.window_to = w.to;
  const ExpectMatches m = find_expect_matches(e, timeline, w);
  if (e.quantifier == Quantifier::always)
    check_always(e, timeline, w, outcome);
  else if (e.quantifier == Quantifier::at_times)
    check_at_times(e, timeline, w, m, slack, outcome);
  else
    check_counting(e, timeline, w, m, outcome);
  return outcome;
}

std::vector<ExpectationOutcome> check_all(const std::vector<Expectation>& expectations,
                                          const Timeline& timeline, Time run_end, Duration slack,
                                          const Origin& origin) {
  std::vector<ExpectationOutcome> outcomes;
  outcomes.reserve(expectations.size());
  for (const auto& e : expectations)
    outcomes.push_back(check(e, timeline, run_end, slack, origin));
  return outcomes;
}

}  // namespace hil::harness
