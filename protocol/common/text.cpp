#include "protocol/common/text.hpp"

#include <cstdio>

namespace hil::protocol {

std::optional<long long> parse_decimal(std::string_view text, bool allow_sign, bool allow_plus,
                                       std::size_t max_digits) {
  bool negative = false;
  if (!text.empty() && allow_sign && text.front() == '-') {
    negative = true;
    text.remove_prefix(1);
  } else if (!text.empty() && allow_plus && text.front() == '+') {
    text.remove_prefix(1);
  }
  if (text.empty() || text.size() > max_digits) return std::nullopt;
  long long value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
  }
  return negative ? -value : value;
}

std::optional<std::uint8_t> parse_hex_byte(std::string_view text, bool* lowercase) {
  if (text.size() != 2) return std::nullopt;
  int value = 0;
  bool lower = false;
  for (const char c : text) {
    int v = 0;
    if (c >= '0' && c <= '9') {
      v = c - '0';
    } else if (c >= 'A' && c <= 'F') {
      v = c - 'A' + 10;
    } else if (c >= 'a' && c <= 'f') {
      v = c - 'a' + 10;
      lower = true;
    } else {
      return std::nullopt;
    }
    value = value * 16 + v;
  }
  if (lowercase != nullptr) *lowercase = lower;
  return static_cast<std::uint8_t>(value);
}

std::vector<std::string_view> split(std::string_view text, char sep) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t pos = text.find(sep, start);
    if (pos == std::string_view::npos) {
      out.push_back(text.substr(start));
      return out;
    }
    out.push_back(text.substr(start, pos - start));
    start = pos + 1;
  }
}

bool is_printable_ascii(std::string_view text) {
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u > 0x7E) return false;
  }
  return true;
}

std::string ascii_upper(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  }
  return out;
}

bool kind_matches(std::string_view pattern, std::string_view kind) {
  if (pattern.empty()) return true;
  if (kind.size() < pattern.size() || kind.substr(0, pattern.size()) != pattern) return false;
  if (kind.size() == pattern.size()) return true;
  const char next = kind[pattern.size()];
  return next == ':' || next == '.';
}

std::string fixed_decimals(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

}  // namespace hil::protocol
