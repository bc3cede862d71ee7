#include "client/common/operator_text.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <numeric>

#include "base/duration.hpp"

namespace hil::client {

std::string to_lower(std::string_view text) {
  std::string out(text);
  for (auto& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string to_upper(std::string_view text) {
  std::string out(text);
  for (auto& c : out)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim_end(std::string_view text, std::string_view blanks) {
  while (!text.empty() && blanks.find(text.back()) != std::string_view::npos)
    text.remove_suffix(1);
  return text;
}

std::string_view trim(std::string_view text, std::string_view blanks) {
  while (!text.empty() && blanks.find(text.front()) != std::string_view::npos)
    text.remove_prefix(1);
  return trim_end(text, blanks);
}

SplitLine split_words(std::string_view line, std::string_view blanks, CommentStart comment) {
  const auto is_blank = [&](char c) { return blanks.find(c) != std::string_view::npos; };
  // Inside a word a '#' ends it only when comments may start anywhere.
  const auto ends_word = [&](char c) {
    return is_blank(c) || (c == '#' && comment == CommentStart::anywhere);
  };
  SplitLine out;
  std::size_t i = 0;
  while (i < line.size()) {
    if (is_blank(line[i])) {
      ++i;
      continue;
    }
    if (line[i] == '#') break;
    const std::size_t start = i;
    ++i;
    while (i < line.size() && !ends_word(line[i]))
      ++i;
    out.words.push_back({line.substr(start, i - start), start + 1});
    out.end_column = i + 1;
  }
  return out;
}

ParsedInteger parse_integer(std::string_view text, std::int64_t lo, std::int64_t hi,
                            IntegerSyntax syntax) {
  ParsedInteger out;
  out.error = ParsedInteger::Error::not_a_number;
  bool negative = false;
  if (!text.empty() &&
      ((text.front() == '+' && syntax.plus) || (text.front() == '-' && syntax.minus))) {
    negative = text.front() == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (syntax.hex && text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  if (text.empty() || text.size() > syntax.max_digits) return out;
  std::uint64_t magnitude = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), magnitude, base);
  if (end != text.data() + text.size()) return out;
  // Digits only: from_chars took all of them, so a failure now is size.
  if (ec != std::errc{} || magnitude > static_cast<std::uint64_t>(INT64_MAX)) {
    out.error = ParsedInteger::Error::out_of_range;
    return out;
  }
  out.value =
      negative ? -static_cast<std::int64_t>(magnitude) : static_cast<std::int64_t>(magnitude);
  out.error = out.value < lo || out.value > hi ? ParsedInteger::Error::out_of_range
                                               : ParsedInteger::Error::none;
  return out;
}

std::optional<link::Duration> parse_duration(std::string_view text, link::Duration max) {
  constexpr std::int64_t kMaxScale = 1'000'000'000'000'000'000;  // 18 digits after the point
  std::size_t i = 0;
  std::int64_t whole = 0;
  std::int64_t fraction = 0;
  std::int64_t scale = 1;  // 10^(digits after the point)
  bool digits = false;
  bool point = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      digits = true;
      if (point) {
        if (scale >= kMaxScale) return std::nullopt;
        fraction = fraction * 10 + (c - '0');
        scale *= 10;
      } else {
        if (whole > 1'000'000'000'000) return std::nullopt;  // beyond any limit in ns
        whole = whole * 10 + (c - '0');
      }
    } else if (c == '.' && !point) {
      point = true;
    } else {
      break;
    }
  }
  if (!digits || (point && scale == 1)) return std::nullopt;
  const std::string unit = to_lower(text.substr(i));
  std::int64_t unit_ns = 0;
  if (unit == "ms") {
    unit_ns = 1'000'000;
  } else if (unit == "s") {
    unit_ns = 1'000'000'000;
  } else if (unit == "m" || unit == "min") {
    unit_ns = 60'000'000'000;
  } else {
    return std::nullopt;
  }
  const std::int64_t max_ns = max.count();
  if (whole > max_ns / unit_ns) return std::nullopt;
  // fraction / scale units in whole nanoseconds, or it is finer than one.
  const std::int64_t g = std::gcd(unit_ns, scale);
  if (fraction % (scale / g) != 0) return std::nullopt;
  const std::int64_t ns = whole * unit_ns + fraction / (scale / g) * (unit_ns / g);
  if (ns > max_ns) return std::nullopt;
  return link::Duration(ns);
}

namespace {

// "<whole>.<part>" with `part` written in `digits` digits, trailing zeros dropped.
std::string decimal_text(std::int64_t whole, std::int64_t part, std::size_t digits) {
  std::string frac = std::to_string(part);
  frac.insert(0, digits - frac.size(), '0');
  while (frac.back() == '0')
    frac.pop_back();
  return std::to_string(whole) + "." + frac;
}

}  // namespace

std::string duration_text(link::Duration d, DurationStyle style) {
  constexpr std::int64_t kMinute = 60'000'000'000;
  constexpr std::int64_t kSecond = 1'000'000'000;
  constexpr std::int64_t kMilli = 1'000'000;
  const auto ns = d.count();
  const bool largest = style == DurationStyle::largest_unit;
  if (largest && ns != 0 && ns % kMinute == 0) return std::to_string(ns / kMinute) + "m";
  // Whole seconds or milliseconds: "2s", "250ms" (and "1500ms" unless largest).
  if (ns % kSecond == 0 || (ns % kMilli == 0 && (ns < kSecond || !largest)))
    return hil::duration_literal(d);
  if (ns % kMilli == 0) return decimal_text(ns / kSecond, ns % kSecond / kMilli, 3) + "s";
  return decimal_text(ns / kMilli, ns % kMilli, 6) + "ms";
}

std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    lines.push_back(text.substr(0, nl));
    if (nl == std::string_view::npos) break;
    text.remove_prefix(nl + 1);
  }
  return lines;
}

std::string format_location(std::string_view file, std::size_t line, std::size_t column,
                            std::string_view message) {
  return std::string(file) + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
         std::string(message);
}

std::string ScriptError::to_string() const {
  if (line == 0) return file + ": " + message;
  return format_location(file, line, column, message);
}

}  // namespace hil::client
