#pragma once
// Splits a byte stream into header..terminator candidates for the text
// protocols (LOGI, Arduino). Knows nothing of checksums or fields.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::protocol {

class DelimitedFramer {
 public:
  enum class Kind : std::uint8_t {
    frame,        ///< header .. terminator, inclusive
    garbage,      ///< bytes outside any frame
    interrupted,  ///< a header, then another header before the terminator
    oversized,    ///< a header, then more than max_frame_bytes without a terminator
    truncated,    ///< finish() inside a frame
  };
  struct Event {
    Kind kind;
    Bytes bytes;
  };

  /// `max_frame_bytes` bounds a frame including header and terminator.
  /// Between feeds the framer holds at most that many bytes; garbage and
  /// oversized runs are passed on in pieces of at most max_frame_bytes + 1.
  DelimitedFramer(std::string_view header, std::uint8_t terminator, std::size_t max_frame_bytes);

  void feed(ByteView bytes, std::vector<Event>& out);
  /// End of stream: hands back whatever is still held.
  void finish(std::vector<Event>& out);
  /// Bytes currently held (always <= max_frame_bytes).
  std::size_t buffered() const { return buf_.size(); }
  std::size_t max_frame_bytes() const { return max_frame_bytes_; }

 private:
  void emit(Kind kind, std::size_t count, std::vector<Event>& out);

  SequenceMatcher header_;
  std::uint8_t terminator_;
  std::size_t max_frame_bytes_;
  Bytes buf_;
  bool in_frame_ = false;
};

/// The decode error for a non-frame event (garbage, interrupted, oversized,
/// truncated); the event's bytes move into it.
DecodeError to_error(DelimitedFramer::Event&& event, std::size_t max_frame_bytes);

}  // namespace hil::protocol
