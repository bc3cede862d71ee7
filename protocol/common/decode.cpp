#include "protocol/common/decode.hpp"

namespace hil::protocol {

std::string_view to_string(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::garbage:
      return "garbage";
    case ErrorKind::bad_checksum:
      return "bad_checksum";
    case ErrorKind::lowercase_checksum:
      return "lowercase_checksum";
    case ErrorKind::bad_format:
      return "bad_format";
    case ErrorKind::bad_value:
      return "bad_value";
    case ErrorKind::oversized:
      return "oversized";
    case ErrorKind::unknown_code:
      return "unknown_code";
    case ErrorKind::truncated:
      return "truncated";
  }
  return "unknown";
}

SequenceMatcher::SequenceMatcher(std::string_view sequence)
    : sequence_(sequence), failure_(sequence.size(), 0) {
  std::size_t k = 0;
  for (std::size_t i = 1; i < sequence_.size(); ++i) {
    while (k > 0 && sequence_[i] != sequence_[k])
      k = failure_[k - 1];
    if (sequence_[i] == sequence_[k]) ++k;
    failure_[i] = k;
  }
}

bool SequenceMatcher::feed(std::uint8_t byte) {
  const char c = static_cast<char>(byte);
  if (matched_ == sequence_.size()) matched_ = failure_[matched_ - 1];
  while (matched_ > 0 && sequence_[matched_] != c)
    matched_ = failure_[matched_ - 1];
  if (sequence_[matched_] == c) ++matched_;
  return matched_ == sequence_.size();
}

}  // namespace hil::protocol
