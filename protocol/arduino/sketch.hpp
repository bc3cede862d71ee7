#pragma once
// The Arduino robot's real receive path (profile `firmware`): what the
// sketch of andrii-mazurchuk/arduino_robot_steering- at 8dcfab0
// (arduino.ino) does with every byte it reads, and the reply frames it
// writes. It differs from the protocol README, which Decoder follows:
// the payload field must not be empty, a malformed frame is dropped
// without an answer, the checksum separator is the first '*', and a '^'
// inside a frame is a byte like any other (docs/protocols/arduino.md).

#include <cstddef>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/arduino/message.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::protocol::arduino {

/// The sketch's receive buffer: a frame of more bytes, '^' and '$'
/// included, is dropped.
inline constexpr std::size_t kSketchFrameBytes = 96;
/// Frames shorter than this ('^' and '$' included) are dropped.
inline constexpr std::size_t kSketchMinFrameBytes = 7;

/// A frame the sketch acts on: three non-empty '|' fields, the first two
/// hex digits. `cmd` and `payload` are as sent; the sketch matches the
/// command without regard to case.
struct SketchRequest {
  std::string seq;  ///< two hex digits, echoed as received (case kept)
  std::string cmd;
  std::string payload;
  friend bool operator==(const SketchRequest&, const SketchRequest&) = default;
};

/// A frame the sketch refuses with a NACK before looking at its command.
struct SketchRefusal {
  /// What the NACK carries as its SEQ: for BAD_CS the first two content
  /// bytes whatever they are, for BAD_FMT the first field when it is two
  /// characters long, else "00".
  std::string seq;
  NackCode code = NackCode::bad_fmt;
  friend bool operator==(const SketchRefusal&, const SketchRefusal&) = default;
};

/// A frame the sketch drops without a word.
struct SketchDrop {
  std::string reason;
  friend bool operator==(const SketchDrop&, const SketchDrop&) = default;
};

using SketchVerdict = std::variant<SketchRequest, SketchRefusal, SketchDrop>;

/// One frame the receiver took in: its bytes as stored and what the sketch
/// makes of it.
struct SketchFrame {
  Bytes raw;
  SketchVerdict verdict;
};

/// The sketch's verdict on one stored frame ('^' first, '$' last).
SketchVerdict judge_sketch_frame(std::string_view frame);

/// The sketch's byte loop: bytes before a '^' are ignored; from a '^' every
/// byte is stored (another '^' too) until '$'; a frame that would pass
/// kSketchFrameBytes is dropped and the byte after the 96th is lost with
/// it. Never throws; holds at most kSketchFrameBytes bytes.
class SketchReceiver {
 public:
  void feed(ByteView bytes, std::vector<SketchFrame>& out);
  /// A board reset: the buffer is gone.
  void reset();
  std::size_t buffered() const { return buffer_.size(); }

 private:
  bool in_frame_ = false;
  std::string buffer_;
};

/// The reply frame exactly as the sketch writes it: '^', SEQ|CMD|PAYLOAD
/// cut at 95 characters, '*', the XOR checksum as two upper-case hex
/// digits, '$'.
std::string sketch_frame(std::string_view seq, std::string_view cmd, std::string_view payload);

/// The number the sketch reads from a payload with C's atol: leading
/// blanks skipped, an optional sign, decimal digits up to the first other
/// character; no digits reads 0 ("abc" and " " are 0). Beyond the board's
/// 32-bit long the result saturates (the board's own result is undefined).
long sketch_atol(std::string_view text);

}  // namespace hil::protocol::arduino
