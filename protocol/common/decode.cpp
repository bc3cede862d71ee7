#include "protocol/common/decode.hpp"

#include "base/enum_names.hpp"

namespace hil::protocol {

constexpr auto kErrorKindNames = base::enum_names<ErrorKind>(
    {ErrorKind::garbage, "garbage"}, {ErrorKind::bad_checksum, "bad_checksum"},
    {ErrorKind::lowercase_checksum, "lowercase_checksum"}, {ErrorKind::bad_format, "bad_format"},
    {ErrorKind::bad_value, "bad_value"}, {ErrorKind::oversized, "oversized"},
    {ErrorKind::unknown_code, "unknown_code"}, {ErrorKind::truncated, "truncated"});

std::string_view to_string(ErrorKind kind) {
  return kErrorKindNames.name(kind, "unknown");
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
