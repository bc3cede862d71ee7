#pragma once
// The parts of the expectation checker. harness/expect.cpp finds an
// expectation's window and its matches and judges them by quantifier; how
// expectations, windows and times are put in words for the people who read
// a verdict is in harness/expect_text.cpp. Internal to hil::harness.

#include <cstdint>
#include <string>
#include <vector>

#include "harness/scenario.hpp"
#include "harness/timeline.hpp"

namespace hil::harness::expect_parts {

/// "300 ms", "1 s", "1.5 s": a duration as a scenario author would write it.
std::string duration_text(Duration d);

/// "1.000 s, 2.000 s and 3 more": the first few times, in seconds.
std::string times_text(const std::vector<Time>& times);

/// "once", "twice", "3 times".
std::string count_text(std::uint64_t count);

/// "wire frame", "client record": a source and a record kind.
std::string record_kind_text(Source source, const std::optional<RecordKind>& kind);

/// The matcher in the scenario's words, or built from its fields when it
/// has none ("wire frame where dir = \"to_car\"").
std::string matcher_text(const Matcher& matcher);

/// What a matcher's records must hold: its scenario words, else its field
/// tests ("dir = \"to_car\" and stage = \"delivered\"").
std::string tests_text(const Matcher& matcher);

/// "the 2nd step 'release' + 300 ms", "the start": where a window begins.
std::string anchor_text(const Anchor& anchor, bool with_offset = true);

/// The window as the scenario put it: "within 300 ms after step 'release'",
/// "between 5 s and 5.3 s", "" for the whole run.
std::string window_text(const Window& window);

/// The expectation as a person reads it: matcher, window and quantifier
/// ("car received MV:STOP within 300 ms after ..., exactly once").
std::string expectation_label(const Expectation& e);

/// `text` in single quotes.
std::string quoted(const std::string& text);

}  // namespace hil::harness::expect_parts
