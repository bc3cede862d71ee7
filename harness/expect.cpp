#include "harness/expect.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <string>
#include <utility>

#include "mocks/behaviour.hpp"

namespace hil::harness {

namespace {

// Evidence limits: enough to see what happened around a verdict without
// burying the report.
constexpr std::size_t max_matches_in_evidence = 10;
constexpr std::size_t max_evidence = 20;
constexpr Duration evidence_margin = std::chrono::milliseconds(500);
// Times listed in a message before "and N more".
constexpr std::size_t max_listed_times = 5;

using Json = nlohmann::json;

// ------------------------------------------------------------ formatting

std::string seconds_text(Duration d) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3f s", std::chrono::duration<double>(d).count());
  return buffer;
}

std::string trimmed_decimal(double value) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3f", value);
  std::string text = buffer;
  while (!text.empty() && text.back() == '0')
    text.pop_back();
  if (!text.empty() && text.back() == '.') text.pop_back();
  return text;
}

/// "300 ms", "1 s", "1.5 s": a duration as a scenario author would write it.
std::string duration_text(Duration d) {
  using std::chrono::milliseconds;
  using std::chrono::seconds;
  if (d % seconds(1) == Duration(0)) return std::to_string(d / seconds(1)) + " s";
  if (d >= seconds(1) || d <= -seconds(1))
    return trimmed_decimal(std::chrono::duration<double>(d).count()) + " s";
  if (d % milliseconds(1) == Duration(0)) return std::to_string(d / milliseconds(1)) + " ms";
  return trimmed_decimal(std::chrono::duration<double, std::milli>(d).count()) + " ms";
}

std::string times_text(const std::vector<Time>& times) {
  std::string text;
  const std::size_t shown = std::min(times.size(), max_listed_times);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) text += ", ";
    text += seconds_text(times[i]);
  }
  if (times.size() > shown) text += " and " + std::to_string(times.size() - shown) + " more";
  return text;
}

std::string ordinal(int n) {
  const int last_two = n % 100;
  const int last = n % 10;
  const char* suffix = "th";
  if (last_two < 11 || last_two > 13) {
    if (last == 1) suffix = "st";
    if (last == 2) suffix = "nd";
    if (last == 3) suffix = "rd";
  }
  return std::to_string(n) + suffix;
}

std::string op_text(FieldTest::Op op) {
  switch (op) {
    case FieldTest::Op::equals:
      return "=";
    case FieldTest::Op::not_equals:
      return "!=";
    case FieldTest::Op::kind_prefix:
      return "starts with";
    case FieldTest::Op::contains:
      return "contains";
    case FieldTest::Op::less:
      return "<";
    case FieldTest::Op::less_equal:
      return "<=";
    case FieldTest::Op::greater:
      return ">";
    case FieldTest::Op::greater_equal:
      return ">=";
    case FieldTest::Op::kind_either_prefix:
      return "starts with, or is cut short of,";
  }
  return "?";
}

std::string test_text(const FieldTest& test) {
  return test.field + " " + op_text(test.op) + " " + test.value.dump();
}

std::string record_kind_text(Source source, const std::string& kind) {
  return std::string(to_string(source)) + " " + (kind.empty() ? std::string("record") : kind);
}

/// The matcher in the scenario's words, or built from its fields when it
/// has none ("wire frame where dir = \"to_car\"").
std::string matcher_text(const Matcher& matcher) {
  if (!matcher.text.empty()) return matcher.text;
  std::string text = record_kind_text(matcher.source, matcher.kind);
  for (std::size_t i = 0; i < matcher.tests.size(); ++i)
    text += (i == 0 ? " where " : " and ") + test_text(matcher.tests[i]);
  return text;
}

std::string tests_text(const Matcher& matcher) {
  if (!matcher.text.empty()) return matcher.text;
  std::string text;
  for (std::size_t i = 0; i < matcher.tests.size(); ++i)
    text += (i == 0 ? "" : " and ") + test_text(matcher.tests[i]);
  return text.empty() ? record_kind_text(matcher.source, matcher.kind) : text;
}

std::string anchor_text(const Anchor& anchor, bool with_offset = true) {
  std::string text;
  if (anchor.occurrence == -1)
    text = "the last ";
  else if (anchor.occurrence < -1)
    text = "the " + ordinal(-anchor.occurrence) + "-last ";
  else if (anchor.occurrence != 1)
    text = "the " + ordinal(anchor.occurrence) + " ";
  text += anchor.event ? matcher_text(*anchor.event) : "the start";
  if (!with_offset) return text;
  if (anchor.offset > Duration(0)) text += " + " + duration_text(anchor.offset);
  if (anchor.offset < Duration(0)) text += " - " + duration_text(-anchor.offset);
  return text;
}

/// The window as the scenario put it: "within 300 ms after step 'release'",
/// "between 5 s and 5.3 s", "" for the whole run.
std::string window_text(const Window& window) {
  if (window.from.event) {
    if (window.within)
      return "within " + duration_text(*window.within) + " after " + anchor_text(window.from);
    return "after " + anchor_text(window.from);
  }
  const Duration start = window.from.offset;
  if (window.within)
    return "between " + duration_text(start) + " and " + duration_text(start + *window.within);
  if (start != Duration(0)) return "from " + duration_text(start) + " on";
  return {};
}

std::string count_text(std::uint64_t count) {
  if (count == 1) return "once";
  if (count == 2) return "twice";
  return std::to_string(count) + " times";
}

std::string quantifier_suffix(const Expectation& e) {
  switch (e.quantifier) {
    case Quantifier::exists:
      return {};
    case Quantifier::never:
      return "never";
    case Quantifier::exactly:
      return "exactly " + count_text(e.count);
    case Quantifier::at_least:
      return "at least " + count_text(e.count);
    case Quantifier::at_most:
      return "at most " + count_text(e.count);
    case Quantifier::at_times: {
      std::string text = e.only ? "only at " : "at ";
      for (std::size_t i = 0; i < e.times.size(); ++i)
        text += (i == 0 ? "" : ", ") + duration_text(e.times[i]);
      return text + " ± " + duration_text(e.tolerance);
    }
    case Quantifier::always:
      return "always";
  }
  return {};
}

std::string make_label(const Expectation& e) {
  std::string label = matcher_text(e.what);
  const std::string window = window_text(e.window);
  if (!window.empty()) label += " " + window;
  const std::string suffix = quantifier_suffix(e);
  if (!suffix.empty()) label += ", " + suffix;
  return label;
}

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
    kind_value = record.kind;
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
  return record.source == matcher.source && (matcher.kind.empty() || record.kind == matcher.kind);
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
      text += "kind = " + Json(record.kind).dump();
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
    if (records[i].source != source || !near_edge(records[i].at)) continue;
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
      best = Nearest{
          i, at,
          seconds_text(at) + ", " + seconds_text(distance) + (at < from ? " early" : " late")};
    }
  }
  return best;
}

ExpectationOutcome start_outcome(const Expectation& e) {
  ExpectationOutcome outcome;
  outcome.line = e.line;
  outcome.label = e.label.empty() ? make_label(e) : e.label;
  return outcome;
}

std::string quoted(const std::string& text) {
  return "'" + text + "'";
}

}  // namespace

bool matches(const Matcher& matcher, const Record& record) {
  if (!same_source_and_kind(matcher, record)) return false;
  return std::all_of(matcher.tests.begin(), matcher.tests.end(),
                     [&](const FieldTest& test) { return test_holds(test, record); });
}

std::optional<Time> resolve(const Anchor& anchor, const Timeline& timeline) {
  if (!anchor.event) return Time(0) + anchor.offset;
  std::vector<Time> seen;
  for (const auto& record : timeline.records())
    if (matches(*anchor.event, record)) seen.push_back(record.at);
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
                         Duration slack) {
  ExpectationOutcome outcome = start_outcome(e);
  const std::string what = quoted(matcher_text(e.what));
  const std::string window_label = window_text(e.window);

  const auto start = resolve(e.window.from, timeline);
  if (!start) {
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

  const Time from = *start;
  const Time to = e.window.within ? from + *e.window.within : run_end;
  // With slack (real time) the edges are known only to within it: what
  // must happen may fall in the wider window, what must not is looked for
  // in the narrower one. An edge that is an event or the end of the run
  // is where it is; a run time or an edge `within` after one moves.
  const bool movable_start = !e.window.from.event && slack > Duration(0);
  const bool movable_end = e.window.within.has_value() && slack > Duration(0);
  const Time wide_from = movable_start ? std::max(Time(0), from - slack) : from;
  const Time wide_to = movable_end ? to + slack : to;
  const Time narrow_from = movable_start ? from + slack : from;
  const Time narrow_to = movable_end ? std::max(narrow_from, to - slack) : to;
  outcome.window_from = from;
  outcome.window_to = to;
  const auto in_window = [&](Time at) { return at >= wide_from && at <= wide_to; };
  const auto in_narrow = [&](Time at) { return at >= narrow_from && at <= narrow_to; };

  std::string where = "between " + seconds_text(from) + " and " + seconds_text(to);
  if (e.window.from.event) where += " (" + window_label + ")";
  if (slack > Duration(0)) where += " (± " + seconds_text(slack) + " for real time)";

  const auto& records = timeline.records();
  std::vector<std::size_t> all_matches;
  std::vector<std::size_t> window_matches;
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (!matches(e.what, records[i])) continue;
    all_matches.push_back(i);
    if (in_window(records[i].at)) window_matches.push_back(i);
  }
  std::vector<Time> window_times;
  for (const auto i : window_matches)
    window_times.push_back(records[i].at);
  const std::uint64_t found = window_matches.size();

  if (e.quantifier == Quantifier::always) {
    std::vector<std::size_t> judged;
    std::vector<std::size_t> failing;
    for (std::size_t i = 0; i < records.size(); ++i) {
      if (!judged_by(e.what, records[i]) || !in_narrow(records[i].at)) continue;
      judged.push_back(i);
      if (!matches(e.what, records[i])) failing.push_back(i);
    }
    const std::string subject = record_kind_text(e.what.source, e.what.kind);
    std::string message =
        "expected every " + subject + " " + where + " to satisfy " + quoted(tests_text(e.what));
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
    outcome.evidence = evidence_of(timeline, failing.empty() ? judged : failing,
                                   failing.empty() ? judged : failing, e.what.source, from, to);
    return outcome;
  }

  if (e.quantifier == Quantifier::at_times) {
    // Each time claims the earliest unused match in reach; with one
    // tolerance for all, taking times in order makes that assignment
    // succeed whenever any assignment would.
    std::vector<std::size_t> order(e.times.size());
    for (std::size_t i = 0; i < order.size(); ++i)
      order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return e.times[a] < e.times[b]; });
    const Duration tolerance = e.tolerance + slack;
    std::vector<std::optional<std::size_t>> claimed(e.times.size());
    std::vector<bool> used(window_matches.size(), false);
    for (const auto t : order) {
      const Time target = from + e.times[t];
      for (std::size_t m = 0; m < window_matches.size(); ++m) {
        const Time at = records[window_matches[m]].at;
        if (used[m] || at < target - tolerance || at > target + tolerance) continue;
        used[m] = true;
        claimed[t] = m;
        break;
      }
    }

    std::vector<Time> targets;
    for (const auto& t : e.times)
      targets.push_back(from + t);
    std::string message = "expected " + what + (e.only ? " only at " : " at ");
    for (std::size_t i = 0; i < targets.size(); ++i)
      message += (i == 0 ? "" : ", ") + seconds_text(targets[i]);
    message += " (± " + seconds_text(tolerance) + ") " + where;

    std::vector<Time> hit_times;
    std::string missing;
    for (std::size_t t = 0; t < e.times.size(); ++t) {
      if (claimed[t]) {
        hit_times.push_back(records[window_matches[*claimed[t]]].at);
        continue;
      }
      missing += "; nothing at " + seconds_text(targets[t]);
      // The nearest match no other time took, wherever it is.
      std::optional<Time> nearest;
      for (const auto i : all_matches) {
        const auto pos = std::find(window_matches.begin(), window_matches.end(), i);
        if (pos != window_matches.end() &&
            used[static_cast<std::size_t>(pos - window_matches.begin())])
          continue;
        const Time at = records[i].at;
        const auto distance = [&](Time x) {
          return x < targets[t] ? targets[t] - x : x - targets[t];
        };
        if (!nearest || distance(at) < distance(*nearest)) nearest = at;
      }
      if (nearest) {
        const Duration off = *nearest - targets[t];
        missing += ", the nearest at " + seconds_text(*nearest) + ", " +
                   seconds_text(off < Duration(0) ? -off : off) +
                   (off < Duration(0) ? " early" : " late");
      } else {
        missing += ", and no other match in the run";
      }
    }
    std::vector<Time> extra_times;
    if (e.only)
      for (std::size_t m = 0; m < window_matches.size(); ++m)
        if (!used[m] && in_narrow(records[window_matches[m]].at))
          extra_times.push_back(records[window_matches[m]].at);

    outcome.passed = missing.empty() && extra_times.empty();
    message += hit_times.empty() ? ", found none of them" : ", found at " + times_text(hit_times);
    message += missing;
    if (!extra_times.empty())
      message += "; " + std::to_string(extra_times.size()) + " more outside those times: at " +
                 times_text(extra_times);
    outcome.message = std::move(message);
    outcome.evidence =
        evidence_of(timeline, window_matches, window_matches, e.what.source, from, to);
    return outcome;
  }

  // The counting quantifiers: a lower bound is met in the wide window, an
  // upper bound in the narrow one (the same window without slack).
  const auto narrow_found = static_cast<std::uint64_t>(
      std::count_if(window_times.begin(), window_times.end(), in_narrow));
  std::string wanted;
  bool needs_more = false;
  switch (e.quantifier) {
    case Quantifier::exists:
      wanted = "at least one";
      outcome.passed = found >= 1;
      needs_more = true;
      break;
    case Quantifier::never:
      wanted = "no";
      outcome.passed = narrow_found == 0;
      break;
    case Quantifier::exactly:
      wanted = "exactly " + std::to_string(e.count);
      outcome.passed = narrow_found <= e.count && e.count <= found;
      needs_more = found < e.count;
      break;
    case Quantifier::at_least:
      wanted = "at least " + std::to_string(e.count);
      outcome.passed = found >= e.count;
      needs_more = true;
      break;
    case Quantifier::at_most:
      wanted = "at most " + std::to_string(e.count);
      outcome.passed = narrow_found <= e.count;
      break;
    case Quantifier::at_times:
    case Quantifier::always:
      break;
  }
  // An upper bound failed in the narrow window: show what was found there.
  const bool upper_only = e.quantifier == Quantifier::never || e.quantifier == Quantifier::at_most;
  std::vector<Time> shown_times = window_times;
  if (upper_only) std::erase_if(shown_times, [&](Time at) { return !in_narrow(at); });
  const std::uint64_t shown_found = upper_only ? narrow_found : found;
  std::string message = "expected " + wanted + " " + what + " " + where;
  message += shown_found == 0
                 ? ", found none"
                 : ", found " + std::to_string(shown_found) + ": at " + times_text(shown_times);
  std::vector<std::size_t> shown = window_matches;
  if (!outcome.passed && needs_more) {
    const auto nearest = nearest_outside(timeline, all_matches, from, to);
    if (nearest) {
      message += (found == 0 ? "; the nearest at " : "; the nearest outside the window at ") +
                 nearest->text;
      shown.insert(shown.begin(), nearest->index);
    } else if (found == 0) {
      message += " in the whole run";
    }
  }
  outcome.message = std::move(message);
  outcome.evidence = evidence_of(timeline, std::move(shown), all_matches, e.what.source, from, to);
  return outcome;
}

std::vector<ExpectationOutcome> check_all(const std::vector<Expectation>& expectations,
                                          const Timeline& timeline, Time run_end, Duration slack) {
  std::vector<ExpectationOutcome> outcomes;
  outcomes.reserve(expectations.size());
  for (const auto& e : expectations)
    outcomes.push_back(check(e, timeline, run_end, slack));
  return outcomes;
}

}  // namespace hil::harness
