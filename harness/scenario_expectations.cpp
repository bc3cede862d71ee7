#include "harness/scenario_parts.hpp"

#include "base/duration.hpp"

namespace hil::harness::scenario_parts {
namespace {

/// `schedule:` (steps at a run time or on an event) and `expect:` (what must, or must not, happen
/// and when).
class ExpectationReader : public config::Reader {
 public:
  explicit ExpectationReader(const ScenarioFacts& facts)
      : config::Reader(facts.file), facts_(facts) {}

  std::vector<ScheduledStep> schedule(const YAML::Node& list) const {
    std::vector<ScheduledStep> out;
    if (list.IsNull()) return out;
    if (!list.IsSequence()) fail(list, "'schedule' must be a list of {at: 5s, <step>} entries");
    std::size_t index = 0;
    for (const auto& item : list) {
      const std::string where = "schedule " + std::to_string(++index);
      if (!item.IsMap()) {
        fail(item, where + ": a scheduled step is a map with 'at' or 'when' and one step key");
      }
      ScheduledStep s;
      Keys allowed = kStepKeys;
      allowed.insert(allowed.end(), {"at", "when", "occurrence", "offset", "timeout", "expect"});
      check_keys(item, allowed, where);
      const auto at = item["at"];
      const auto when = item["when"];
      if (at && when) fail(when, where + ": 'at' and 'when' do not go together");
      if (!at && !when)
        fail(item, where + ": 'at' (a run time like 5s) or 'when' (a matcher) is missing");
      if (at) {
        for (const char* k : {"occurrence", "offset"}) {
          if (item[k]) fail(item[k], where + ": '" + std::string(k) + "' goes with 'when'");
        }
        s.when.offset = duration(at, where + ": 'at'");
      } else {
        s.when = read_anchor(facts_, when, where + ": 'when'", false);
        if (when.IsMap()) {
          for (const char* k : {"occurrence", "offset"}) {
            if (item[k] && when[k])
              fail(item[k], where + ": '" + std::string(k) + "' is given twice");
          }
        }
        read_anchor_occurrence(facts_, item, s.when, where);
      }
      bool has_step = false;
      for (const auto& k : kStepKeys)
        has_step = has_step || item[k];
      if (!has_step) fail(item, where + ": what to do is missing (one of " + join(kStepKeys) + ")");
      if (item["wait"] || item["wait_until"]) {
        fail(item["wait"] ? item["wait"] : item["wait_until"],
             where + ": a scheduled step cannot wait; put waits in 'steps'");
      }
      s.step = read_step(facts_, item, where, {"at", "when", "occurrence", "offset"});
      out.push_back(std::move(s));
    }
    return out;
  }

  std::vector<Expectation> expectations(const YAML::Node& list) const {
    std::vector<Expectation> out;
    if (list.IsNull()) return out;
    if (!list.IsSequence()) fail(list, "'expect' must be a list of expectations");
    std::size_t index = 0;
    for (const auto& item : list) {
      out.push_back(expectation(item, "expectation " + std::to_string(++index)));
    }
    return out;
  }

  Expectation expectation(const YAML::Node& n, const std::string& where) const {
    if (!n.IsMap()) {
      fail(n, where +
                  ": an expectation is a map like {received: \"MV:STOP\", within: 300ms, after: "
                  "release}");
    }
    Keys allowed = {"label"};
    allowed.insert(allowed.end(), kMatcherSources.begin(), kMatcherSources.end());
    allowed.insert(allowed.end(), kWireDirections.begin(), kWireDirections.end());
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    allowed.insert(allowed.end(), kWindowKeys.begin(), kWindowKeys.end());
    allowed.insert(allowed.end(), kQuantifierKeys.begin(), kQuantifierKeys.end());
    allowed.insert(allowed.end(), {"tolerance", "only"});
    check_keys(n, allowed, where);

    Expectation e;
    e.line = n.Mark().line + 1;
    std::optional<YAML::Node> nested;
    const std::string quantifier = read_quantifier(n, where, e, nested);
    // The matcher.
    if (nested) {
      for (const auto& k : kMatcherSources) {
        if (n[k]) fail(n[k], where + ": the matcher is inside '" + quantifier + "' already");
      }
      for (const auto& k : kWireDirections) {
        if (n[k]) fail(n[k], where + ": the matcher is inside '" + quantifier + "' already");
      }
      e.what = read_matcher_node(facts_, *nested, where + ": '" + quantifier + "'");
    } else {
      e.what = read_matcher(facts_, n, where);
    }
    read_window(n, where, e);
    if (auto label = n["label"]) {
      e.label = scalar(label, "'label'");
    } else {
      e.label = make_label(e);
    }
    return e;
  }

  /// never, always, count, at_least, at_most or times; `nested` is the
  /// matcher map of `never: {...}` or `always: {...}`. Returns the key.
  std::string read_quantifier(const YAML::Node& n, const std::string& where, Expectation& e,
                              std::optional<YAML::Node>& nested) const {
    const std::string quantifier =
        one_key(n, kQuantifierKeys, [&](const std::string& first, const std::string& second) {
          return where + ": '" + first + "' and '" + second + "' do not go together";
        });
    // Assigning one YAML::Node to another rebinds the data both refer to,
    // so the nested matcher is kept apart instead.
    if (quantifier == "never") {
      const auto v = n["never"];
      if (v.IsMap()) {
        nested.emplace(v);
        e.quantifier = Quantifier::never;
      } else if (boolean(v, "'never'")) {
        e.quantifier = Quantifier::never;
      }
    } else if (quantifier == "always") {
      const auto v = n["always"];
      if (v.IsMap()) {
        nested.emplace(v);
      } else if (!boolean(v, "'always'")) {
        fail(v, where + ": write always: true or always: {matcher}");
      }
      e.quantifier = Quantifier::always;
    } else if (quantifier == "count" || quantifier == "at_least" || quantifier == "at_most") {
      e.quantifier = quantifier == "count"      ? Quantifier::exactly
                     : quantifier == "at_least" ? Quantifier::at_least
                                                : Quantifier::at_most;
      e.count = whole(n[quantifier], "'" + quantifier + "'", 0);
    } else if (quantifier == "times") {
      e.quantifier = Quantifier::at_times;
      const auto v = n["times"];
      if (!v.IsSequence() || v.size() == 0) {
        fail(v, where + ": 'times' must be a list of run times like [6s, 8s, 11s]");
      }
      for (const auto& t : v)
        e.times.push_back(duration(t, where + ": 'times'"));
      if (!std::is_sorted(e.times.begin(), e.times.end())) {
        fail(v, where + ": 'times' must be in increasing order");
      }
      if (auto t = n["tolerance"]) e.tolerance = duration(t, where + ": 'tolerance'");
      if (auto o = n["only"]) e.only = boolean(o, "'only'");
    }
    if (quantifier != "times") {
      for (const char* k : {"tolerance", "only"}) {
        if (n[k]) fail(n[k], where + ": '" + std::string(k) + "' goes with 'times'");
      }
    }
    return quantifier;
  }

  /// within, after, at or between.
  void read_window(const YAML::Node& n, const std::string& where, Expectation& e) const {
    const auto within = n["within"];
    const auto after = n["after"];
    const auto at = n["at"];
    const auto between = n["between"];
    if (at && n["step"] && at.IsScalar() && (at.Scalar() == "start" || at.Scalar() == "end")) {
      fail(at,
           where +
               ": here 'at' is a run time; for a step's start write step: {text: ..., at: start}");
    }
    if (between) {
      for (const auto& other : {within, after, at}) {
        if (other)
          fail(other,
               where + ": 'between' gives the whole window; drop '" + key_name(n, other) + "'");
      }
      if (!between.IsSequence() || between.size() != 2) {
        fail(between, where + ": 'between' must be [from, to] like [5s, 12s]");
      }
      const Duration from = duration(between[0], where + ": 'between'");
      const Duration to = duration(between[1], where + ": 'between'");
      if (to < from) fail(between, where + ": 'between' must be [from, to] with from <= to");
      e.window.from.offset = from;
      e.window.within = to - from;
    } else if (at) {
      if (after)
        fail(after, where + ": 'at' is a time from the start; it does not go with 'after'");
      e.window.from.offset = duration(at, where + ": 'at'");
      e.window.within = within ? duration(within, where + ": 'within'") : Duration{0};
    } else {
      if (after) e.window.from = read_anchor(facts_, after, where + ": 'after'", true);
      if (within) e.window.within = duration(within, where + ": 'within'");
    }
  }

  static std::string key_name(const YAML::Node& map, const YAML::Node& value) {
    for (auto it : map) {
      if (it.second.Mark().line == value.Mark().line &&
          it.second.Mark().column == value.Mark().column) {
        return it.first.Scalar();
      }
    }
    return "?";
  }

  static std::string make_label(const Expectation& e) {
    std::string text;
    switch (e.quantifier) {
      case Quantifier::exists:
        text = e.what.text;
        break;
      case Quantifier::never:
        text = "never: " + e.what.text;
        break;
      case Quantifier::exactly:
        text = "exactly " + std::to_string(e.count) + " x " + e.what.text;
        break;
      case Quantifier::at_least:
        text = "at least " + std::to_string(e.count) + " x " + e.what.text;
        break;
      case Quantifier::at_most:
        text = "at most " + std::to_string(e.count) + " x " + e.what.text;
        break;
      case Quantifier::at_times: {
        std::string times;
        for (const auto t : e.times)
          times += (times.empty() ? "" : ", ") + duration_literal(t);
        text = e.what.text + " at " + times + " (+/- " + duration_literal(e.tolerance) + ")";
        if (e.only) text += " and no other time";
        break;
      }
      case Quantifier::always:
        text = "always: " + e.what.text;
        break;
    }
    const Anchor& from = e.window.from;
    if (from.event) {
      if (e.window.within) text += " within " + duration_literal(*e.window.within);
      text += " after " + from.event->text;
      if (from.occurrence == -1) text += " (the last)";
      if (from.occurrence > 1) text += " (occurrence " + std::to_string(from.occurrence) + ")";
      if (from.offset.count() != 0) text += " + " + duration_literal(from.offset);
    } else if (e.window.within) {
      if (from.offset.count() == 0) {
        text += " within " + duration_literal(*e.window.within);
      } else if (e.window.within->count() == 0) {
        text += " at " + duration_literal(from.offset);
      } else {
        text += " between " + duration_literal(from.offset) + " and " +
                duration_literal(from.offset + *e.window.within);
      }
    } else if (from.offset.count() != 0) {
      text += " after " + duration_literal(from.offset);
    }
    return text;
  }

 private:
  const ScenarioFacts& facts_;
};

}  // namespace

std::vector<ScheduledStep> read_schedule(const ScenarioFacts& facts, const YAML::Node& list) {
  return ExpectationReader(facts).schedule(list);
}

std::vector<Expectation> read_expectations(const ScenarioFacts& facts, const YAML::Node& list) {
  return ExpectationReader(facts).expectations(list);
}

}  // namespace hil::harness::scenario_parts
