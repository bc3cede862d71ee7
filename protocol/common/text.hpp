#pragma once
// Small strict parsers for the decimal and hex fields of the text protocols.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hil::protocol {

/// Decimal integer with an optional leading '-' (and '+' when allow_plus),
/// at most `max_digits` digits, nothing else. Returns nullopt otherwise.
std::optional<long long> parse_decimal(std::string_view text, bool allow_sign,
                                       bool allow_plus = false, std::size_t max_digits = 9);

/// Exactly two hex digits; sets `lowercase` when any digit is a lowercase letter.
std::optional<std::uint8_t> parse_hex_byte(std::string_view text, bool* lowercase = nullptr);

/// Splits at every occurrence of `sep` (empty pieces kept).
std::vector<std::string_view> split(std::string_view text, char sep);

/// Printable ASCII (0x20..0x7E) only.
bool is_printable_ascii(std::string_view text);

/// The text with a..z made A..Z and every other byte kept (no locale).
std::string ascii_upper(std::string_view text);

/// Whether a frame's kind ("MV:FWD", "motor.all") starts with `pattern`
/// by whole ':'- or '.'-separated parts: "MV" matches "MV" and "MV:FWD",
/// not "MVX"; an empty pattern matches every kind. Fault rules and mock
/// behaviours pick frames by it.
bool kind_matches(std::string_view pattern, std::string_view kind);

/// `value` with exactly `decimals` digits after the point ("0.50"), for
/// status lines and logs.
std::string fixed_decimals(double value, int decimals);

}  // namespace hil::protocol
