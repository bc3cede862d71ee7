#include "protocol/arduino/sketch.hpp"

#include <cstdint>
#include <limits>

namespace hil::protocol::arduino {
namespace {

constexpr char kHexDigits[] = "0123456789ABCDEF";

int nibble(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return 10 + c - 'A';
  if (c >= 'a' && c <= 'f') return 10 + c - 'a';
  return -1;
}

// The fields C's strtok gives for the delimiter '|': runs of '|' count as
// one and a leading or trailing one gives no empty field. The text ends at
// its first NUL byte, as a C string does.
std::vector<std::string_view> strtok_fields(std::string_view text, std::size_t most) {
  if (const auto nul = text.find('\0'); nul != std::string_view::npos) text = text.substr(0, nul);
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (fields.size() < most) {
    while (i < text.size() && text[i] == '|')
      ++i;
    if (i == text.size()) break;
    const std::size_t end = text.find('|', i);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end;
    fields.push_back(text.substr(i, stop - i));
    i = stop;
  }
  return fields;
}

// A C string's view of two stored bytes: it ends at a NUL.
std::string c_string(std::string_view text) {
  return std::string(text.substr(0, text.find('\0')));
}

}  // namespace

SketchVerdict judge_sketch_frame(std::string_view frame) {
  const std::size_t n = frame.size();
  if (n < kSketchMinFrameBytes) {
    return SketchDrop{"frame of " + std::to_string(n) + " bytes is shorter than 7"};
  }
  if (frame.front() != '^' || frame.back() != '$') {
    return SketchDrop{"frame does not start with '^' and end with '$'"};
  }
  const std::size_t star = frame.find('*', 1);
  if (star == std::string_view::npos || star >= n - 1) return SketchDrop{"no '*' before the '$'"};
  if (n - 1 - star != 3) {
    return SketchDrop{"the first '*' is followed by " + std::to_string(n - 2 - star) +
                      " characters before the '$', not 2"};
  }
  const int hi = nibble(frame[star + 1]);
  const int lo = nibble(frame[star + 2]);
  if (hi < 0 || lo < 0) return SketchDrop{"the checksum is not two hex digits"};
  // At least 7 bytes with the '*' three from the end: the content between
  // '^' and '*' is never empty here.
  const std::string_view content = frame.substr(1, star - 1);
  std::uint8_t sum = 0;
  for (const char c : content)
    sum = static_cast<std::uint8_t>(sum ^ static_cast<std::uint8_t>(c));
  if (sum != static_cast<std::uint8_t>(hi * 16 + lo)) {
    return SketchRefusal{content.size() >= 2 ? std::string(content.substr(0, 2)) : "00",
                         NackCode::bad_cs};
  }
  const auto fields = strtok_fields(content, 3);
  if (fields.size() < 3) {
    return SketchRefusal{!fields.empty() && fields[0].size() == 2 ? std::string(fields[0]) : "00",
                         NackCode::bad_fmt};
  }
  const std::string_view seq = fields[0];
  if (seq.size() != 2 || nibble(seq[0]) < 0 || nibble(seq[1]) < 0) {
    return SketchRefusal{"00", NackCode::bad_seq};
  }
  return SketchRequest{std::string(seq), std::string(fields[1]), std::string(fields[2])};
}

void SketchReceiver::feed(ByteView bytes, std::vector<SketchFrame>& out) {
  for (const std::uint8_t b : bytes) {
    const char c = static_cast<char>(b);
    if (!in_frame_) {
      if (c == '^') {
        in_frame_ = true;
        buffer_.assign(1, c);
      }
      continue;
    }
    if (buffer_.size() < kSketchFrameBytes) {
      buffer_.push_back(c);
    } else {
      // The byte that does not fit is lost with the frame, even a '^'.
      out.push_back(
          SketchFrame{to_bytes(buffer_), SketchDrop{"no '$' within 96 bytes of the '^'"}});
      in_frame_ = false;
      buffer_.clear();
    }
    if (c == '$') {
      in_frame_ = false;
      if (!buffer_.empty()) {
        out.push_back(SketchFrame{to_bytes(buffer_), judge_sketch_frame(buffer_)});
      }
      buffer_.clear();
    }
  }
}

void SketchReceiver::reset() {
  in_frame_ = false;
  buffer_.clear();
}

std::string sketch_frame(std::string_view seq, std::string_view cmd, std::string_view payload) {
  std::string content = c_string(seq) + "|" + c_string(cmd) + "|" + c_string(payload);
  if (content.size() > kSketchFrameBytes - 1) content.resize(kSketchFrameBytes - 1);
  std::uint8_t sum = 0;
  for (const char c : content)
    sum = static_cast<std::uint8_t>(sum ^ static_cast<std::uint8_t>(c));
  std::string frame = "^" + content + "*";
  frame.push_back(kHexDigits[sum >> 4]);
  frame.push_back(kHexDigits[sum & 0x0F]);
  frame.push_back('$');
  return frame;
}

long sketch_atol(std::string_view text) {
  constexpr long long kMax = std::numeric_limits<std::int32_t>::max();
  constexpr long long kMin = std::numeric_limits<std::int32_t>::min();
  std::size_t i = 0;
  while (i < text.size() && (text[i] == ' ' || (text[i] >= '\t' && text[i] <= '\r')))
    ++i;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
  long long value = 0;
  for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) {
    // Past 2^31 the value only saturates, so it stops growing there.
    if (value <= kMax + 1) value = value * 10 + (text[i] - '0');
  }
  if (negative) value = -value;
  return static_cast<long>(value > kMax ? kMax : value < kMin ? kMin : value);
}

}  // namespace hil::protocol::arduino
