#include "base/duration.hpp"

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <limits>

namespace hil {
namespace {

std::optional<std::uint64_t> parse_digits(std::string_view text) {
  std::uint64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc{} || ptr != end || text.empty()) return std::nullopt;
  return value;
}

std::int64_t unit_ns_of(std::string_view unit) {
  if (unit == "ns") return 1;
  if (unit == "us") return 1'000;
  if (unit == "ms") return 1'000'000;
  if (unit == "s") return 1'000'000'000;
  return 0;
}

}  // namespace

std::optional<std::chrono::nanoseconds> parse_duration(std::string_view text) {
  std::size_t digits_end = 0;
  while (digits_end < text.size() &&
         ((text[digits_end] >= '0' && text[digits_end] <= '9') || text[digits_end] == '.'))
    ++digits_end;
  const std::string_view number = text.substr(0, digits_end);
  const std::int64_t unit_ns = unit_ns_of(text.substr(digits_end));
  if (unit_ns == 0) return std::nullopt;
  // Whole and fractional parts are read separately so "1.5s" is exactly
  // 1 500 000 000 ns.
  const auto dot = number.find('.');
  const std::string_view whole = number.substr(0, dot);
  const std::string_view fraction =
      dot == std::string_view::npos ? std::string_view{} : number.substr(dot + 1);
  if (whole.empty() || (dot != std::string_view::npos && fraction.empty())) return std::nullopt;
  if (fraction.find('.') != std::string_view::npos || fraction.size() > 9) return std::nullopt;
  const auto w = parse_digits(whole);
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (!w || *w > kMax / static_cast<std::uint64_t>(unit_ns) / 2) return std::nullopt;
  std::int64_t ns = static_cast<std::int64_t>(*w) * unit_ns;
  if (!fraction.empty()) {
    const auto f = parse_digits(fraction);
    if (!f) return std::nullopt;
    std::int64_t scale = 1;
    for (std::size_t i = 0; i < fraction.size(); ++i)
      scale *= 10;
    const auto scaled = static_cast<std::int64_t>(*f) * unit_ns;
    if (scaled % scale != 0) return std::nullopt;  // finer than a nanosecond
    ns += scaled / scale;
  }
  return std::chrono::nanoseconds{ns};
}

std::string duration_literal(std::chrono::nanoseconds d) {
  const auto ns = d.count();
  if (ns % 1'000'000'000 == 0) return std::to_string(ns / 1'000'000'000) + "s";
  if (ns % 1'000'000 == 0) return std::to_string(ns / 1'000'000) + "ms";
  if (ns % 1'000 == 0) return std::to_string(ns / 1'000) + "us";
  return std::to_string(ns) + "ns";
}

std::string seconds_text(std::chrono::nanoseconds d, int decimals) {
  char buffer[64];
  const double s = std::chrono::duration<double>(d).count();
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, s);
  std::string text = buffer;
  if (text.starts_with('-') && text.find_first_not_of("-0.") == std::string::npos)
    text.erase(0, 1);
  return text + " s";
}

}  // namespace hil
