#pragma once
// What the expectation checker's tests share: matchers as the loader builds
// them, records and timelines built by hand, and expectations over them.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "harness/expect.hpp"

namespace hil::harness::test {

using Op = FieldTest::Op;
using std::chrono::milliseconds;
using std::chrono::nanoseconds;
using std::chrono::seconds;

inline Time ms(std::int64_t n) {
  return Time(milliseconds(n));
}

inline FieldTest test_of(std::string field, Op op, nlohmann::json value) {
  return FieldTest{std::move(field), op, std::move(value)};
}

// The matchers as the loader builds them from QA's shorthand.
inline Matcher car_received(const std::string& frame) {
  return Matcher{Source::wire,
                 WireKind::frame,
                 {test_of("dir", Op::equals, "to_car"), test_of("stage", Op::equals, "delivered"),
                  test_of("frame", Op::kind_prefix, frame)},
                 "car received " + frame};
}

inline Matcher step_end(const std::string& text) {
  return Matcher{
      Source::step, StepKind::end, {test_of("text", Op::equals, text)}, "step '" + text + "'"};
}

inline Matcher client_state(const std::string& state) {
  return Matcher{Source::client,
                 ClientKind::connection,
                 {test_of("state", Op::equals, state)},
                 "client " + state};
}

inline nlohmann::json frame_data(const std::string& dir, const std::string& stage,
                                 const std::string& frame) {
  return {{"dir", dir}, {"stage", stage}, {"frame", frame}, {"valid", true}};
}

inline void add_delivered(Timeline& t, Time at, const std::string& frame) {
  t.add(at, WireKind::frame, frame_data("to_car", "delivered", frame));
}

inline void add_step_end(Timeline& t, Time at, const std::string& text) {
  t.add(at, StepKind::end, {{"index", 0}, {"line", 10}, {"text", text}, {"ok", true}});
}

inline Record record_with(nlohmann::json data, RecordKind kind = SimKind::sample) {
  return Record{ms(0), kind, std::move(data)};
}

inline Expectation expect_in(Matcher what, Window window, Quantifier q = Quantifier::exists,
                             std::uint64_t count = 0) {
  Expectation e;
  e.line = 7;
  e.what = std::move(what);
  e.window = std::move(window);
  e.quantifier = q;
  e.count = count;
  return e;
}

/// "The car received MV:STOP within 300 ms after the (first) step 'release'".
inline Expectation stop_within_300ms_of_release() {
  return expect_in(car_received("MV:STOP"),
                   Window{Anchor{step_end("release"), 1, {}}, milliseconds(300)});
}

/// The step 'release' ending at 1 s, then the car receiving MV:STOP at `stop`.
inline Timeline release_then_stop(Time stop) {
  Timeline t;
  add_step_end(t, ms(1000), "release");
  add_delivered(t, stop, "MV:STOP");
  return t;
}

inline Window whole_run() {
  return Window{};
}

inline Window between(Time from, Duration within) {
  return Window{Anchor{std::nullopt, 1, from}, within};
}

inline std::vector<Time> times_of(const std::vector<Record>& records) {
  std::vector<Time> times;
  for (const auto& r : records)
    times.push_back(r.at);
  return times;
}

/// Expects `o` to have passed, with `label` and `message`.
inline void expect_passed(const ExpectationOutcome& o, const std::string& label,
                          const std::string& message) {
  EXPECT_TRUE(o.passed) << o.message;
  EXPECT_EQ(o.label, label);
  EXPECT_EQ(o.message, message);
}

}  // namespace hil::harness::test
