#pragma once
// What every stream decoder hands back: decoded frames and typed errors,
// both carrying the exact bytes they were made from.
//
// Every protocol's stream Decoder keeps one contract: feed(bytes, out)
// appends the items the bytes complete, and finish(out) hands out what is
// still held at the end of the stream (a partial frame as
// ErrorKind::truncated). Any chunking of a stream yields the same items in
// the same order, every input byte lands in exactly one item's raw bytes,
// input never makes it throw, and buffered() is the number of bytes held.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"

namespace hil::protocol {

/// Why bytes on the wire did not make a valid frame.
enum class ErrorKind : std::uint8_t {
  garbage,             ///< bytes between frames that start no frame; discarded
  bad_checksum,        ///< the frame's checksum does not match its contents
  lowercase_checksum,  ///< checksum value right, but written in lowercase hex
  bad_format,          ///< framing found, but the fields do not parse
  bad_value,           ///< fields parse, but a value is outside its range
  oversized,           ///< longer than the protocol's frame bound; discarded
  unknown_code,        ///< well-formed, but the command or packet code is unknown
  truncated,           ///< the stream ended (finish()) inside a frame
};

std::string_view to_string(ErrorKind kind);

struct DecodeError {
  ErrorKind kind{};
  Bytes raw;            ///< the offending bytes, exactly as received
  std::string detail;   ///< what was wrong and where, for a person
  std::string context;  ///< the command or packet kind recognised before failing, if any

  friend bool operator==(const DecodeError&, const DecodeError&) = default;
};

/// A frame that decoded. `tolerated` names a violation the decoder was
/// configured to accept (for example a lowercase LOGI checksum).
template <class Message>
struct Frame {
  Message message;
  Bytes raw;
  std::optional<ErrorKind> tolerated;

  friend bool operator==(const Frame&, const Frame&) = default;
};

template <class Message>
using DecodeItem = std::variant<Frame<Message>, DecodeError>;

/// The exact bytes an item was made from, frame or error.
template <class Message>
const Bytes& raw_of(const DecodeItem<Message>& item) {
  if (const auto* e = std::get_if<DecodeError>(&item)) return e->raw;
  return std::get<Frame<Message>>(item).raw;
}

/// Incremental matcher for a fixed start sequence (a frame header), fed one
/// byte at a time. Keeps the length of the longest header prefix that ends at
/// the last byte, so a header split across reads or preceded by a partial
/// false start is still found.
class SequenceMatcher {
 public:
  explicit SequenceMatcher(std::string_view sequence);

  /// Feeds one byte; returns true when the whole sequence has just ended here.
  bool feed(std::uint8_t byte);
  /// Length of the header prefix matched so far.
  std::size_t matched() const { return matched_; }
  std::size_t size() const { return sequence_.size(); }
  void reset() { matched_ = 0; }

 private:
  std::string sequence_;
  std::vector<std::size_t> failure_;  // KMP failure function
  std::size_t matched_ = 0;
};

}  // namespace hil::protocol
