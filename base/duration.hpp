#pragma once
// Durations as text, both ways: the literals people write in scenarios,
// fault profiles, behaviours and operator scripts ("250ms", "1.5s"), and
// the seconds shown in reports, pictures and status lines ("1.500 s").

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace hil {

/// A duration as text: "250ms", "2s", "1.5s", "500us", "100ns". A
/// non-negative number and one of the units ns, us, ms, s; nullopt for
/// anything else (a bare number has no unit and is refused, and so is a
/// fraction finer than a nanosecond). Exact: no floating-point rounding.
std::optional<std::chrono::nanoseconds> parse_duration(std::string_view text);

/// The shortest literal parse_duration reads back to `d` exactly, in the
/// largest unit that divides it: "2s", "250ms", "1500us", "7ns".
std::string duration_literal(std::chrono::nanoseconds d);

/// Seconds with exactly `decimals` digits after the point and " s":
/// seconds_text(1500ms, 3) is "1.500 s". "-0.0 s" is written "0.0 s".
std::string seconds_text(std::chrono::nanoseconds d, int decimals);

}  // namespace hil
