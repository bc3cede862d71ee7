// Expectations, windows and times in words: the labels of expectations and
// the pieces of the messages that explain a verdict.

#include <algorithm>
#include <cstddef>
#include <cstdio>

#include "base/duration.hpp"
#include "base/enum_names.hpp"
#include "harness/expect_parts.hpp"

namespace hil::harness::expect_parts {
namespace {

// Times listed in a message before "and N more".
constexpr std::size_t max_listed_times = 5;

std::string trimmed_decimal(double value) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.3f", value);
  std::string text = buffer;
  while (!text.empty() && text.back() == '0')
    text.pop_back();
  if (!text.empty() && text.back() == '.') text.pop_back();
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

constexpr auto kFieldTestOpTexts = base::enum_names<FieldTest::Op>(
    {FieldTest::Op::equals, "="}, {FieldTest::Op::not_equals, "!="},
    {FieldTest::Op::kind_prefix, "starts with"}, {FieldTest::Op::contains, "contains"},
    {FieldTest::Op::less, "<"}, {FieldTest::Op::less_equal, "<="}, {FieldTest::Op::greater, ">"},
    {FieldTest::Op::greater_equal, ">="},
    {FieldTest::Op::kind_either_prefix, "starts with, or is cut short of,"});

std::string op_text(FieldTest::Op op) {
  return std::string(kFieldTestOpTexts.name(op));
}

std::string test_text(const FieldTest& test) {
  return test.field + " " + op_text(test.op) + " " + test.value.dump();
}

}  // namespace

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
    text += hil::seconds_text(times[i], 3);
  }
  if (times.size() > shown) text += " and " + std::to_string(times.size() - shown) + " more";
  return text;
}

std::string count_text(std::uint64_t count) {
  if (count == 1) return "once";
  if (count == 2) return "twice";
  return std::to_string(count) + " times";
}

std::string record_kind_text(Source source, const std::optional<RecordKind>& kind) {
  return std::string(to_string(source)) + " " + (kind ? std::string(kind->name()) : "record");
}

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

std::string anchor_text(const Anchor& anchor, bool with_offset) {
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

namespace {

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

}  // namespace

std::string expectation_label(const Expectation& e) {
  std::string label = matcher_text(e.what);
  const std::string window = window_text(e.window);
  if (!window.empty()) label += " " + window;
  const std::string suffix = quantifier_suffix(e);
  if (!suffix.empty()) label += ", " + suffix;
  return label;
}

std::string quoted(const std::string& text) {
  return "'" + text + "'";
}

}  // namespace hil::harness::expect_parts
