#pragma once
// Leka Alpha command frames: 2A 2B 2C 2D, group length, command group,
// checksum. Encode, and an incremental stream decoder.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/leka/message.hpp"

namespace hil::protocol::leka {

inline constexpr std::array<std::uint8_t, 4> kStartSequence = {0x2A, 0x2B, 0x2C, 0x2D};
/// Start sequence, length byte and checksum byte around the group.
inline constexpr std::size_t kHeaderBytes = kStartSequence.size() + 1;
inline constexpr std::size_t kOverheadBytes = kHeaderBytes + 1;
/// The robot reads frames into a 128-byte serial buffer; a longer frame can
/// never arrive whole, so 128 is the frame bound and 122 the group bound.
inline constexpr std::size_t kMaxFrameBytes = 128;
inline constexpr std::size_t kMaxGroupBytes = kMaxFrameBytes - kOverheadBytes;

/// The 16-bit BSD checksum: per byte, rotate the sum right by one bit, then
/// add the byte (mod 2^16).
std::uint16_t bsd_checksum16(ByteView bytes);
/// The 8-bit BSD checksum: the same walk within one byte (rotate right by
/// one bit within 8 bits, then add the byte, mod 2^8).
std::uint8_t bsd_checksum8(ByteView bytes);
/// The frame's checksum byte for a command group (its length byte is
/// group.size()). readme: the low byte of the 16-bit BSD checksum of the
/// group alone, as the README's worked examples have it. comspecs_v3: the
/// 8-bit BSD checksum of the length byte and the group, as the third-party
/// generator computes it (docs/protocols/leka.md).
std::uint8_t checksum(ByteView group, Dialect dialect = Dialect::readme);

/// The wire bytes of the commands, in order, without checking values.
/// Throws std::invalid_argument for a command the dialect does not have
/// (led.ear.range in readme).
Bytes group_bytes(const CommandGroup& group, Dialect dialect = Dialect::readme);

/// Frames any group bytes as they are (for odd frames in fault injection and
/// QA). Throws std::invalid_argument only when the group does not fit the
/// one-byte length field (more than 255 bytes).
Bytes frame_group(ByteView group, Dialect dialect = Dialect::readme);

/// A complete frame. Throws std::invalid_argument for groups the robot cannot
/// take: no command, more than kMaxGroupBytes, a command the dialect does
/// not have, or a value outside its range under `limits` (use
/// frame_group(group_bytes(g)) to send such a group anyway).
Bytes encode(const Message& m, const ValueLimits& limits = {}, Dialect dialect = Dialect::readme);

struct GroupError {
  ErrorKind kind;  ///< bad_format or unknown_code
  std::string detail;
  std::string context;  ///< the command name (or unknown id) where parsing stopped
};

/// Splits command-group bytes into typed commands by the ids of `dialect`;
/// checks structure only (known ids, complete data), not value ranges.
std::variant<CommandGroup, GroupError> parse_group(ByteView group,
                                                   Dialect dialect = Dialect::readme);

struct DecoderOptions {
  /// Frame bound in bytes, start sequence to checksum (7..261). The default
  /// is the robot's serial buffer; it is also the most the decoder holds.
  std::size_t max_frame_bytes = kMaxFrameBytes;
  ValueLimits limits;
  /// Command ids and checksum of this convention.
  Dialect dialect = Dialect::readme;
  /// When false, a frame with a value out of range (ear/belt LED id, spin,
  /// motivator or guidance id) is a bad_value error; when true it decodes,
  /// marked tolerated = bad_value.
  bool accept_out_of_range = false;
};

using Item = DecodeItem<Message>;

/// Decodes exactly one complete frame (start sequence to checksum).
Item decode_frame(ByteView raw, const DecoderOptions& options = {});

/// The stream decoder (its contract: protocol/common/decode.hpp). Holds at
/// most options.max_frame_bytes bytes (128 by default): a frame never needs
/// more, and garbage is passed on in chunks of at most that size.
///
/// A candidate that fails its checksum is reported only up to the next start
/// sequence inside it, and decoding resumes there, so header-like garbage
/// cannot swallow a valid frame that follows it.
class Decoder {
 public:
  /// Throws std::invalid_argument for a max_frame_bytes outside 7..261.
  explicit Decoder(DecoderOptions options = {});

  void feed(ByteView bytes, std::vector<Item>& out);
  void finish(std::vector<Item>& out);
  std::size_t buffered() const { return buf_.size(); }

 private:
  enum class State : std::uint8_t { hunting, length, body };

  void advance(std::vector<Item>& out);
  void complete_candidate(std::vector<Item>& out);
  std::size_t resync_point(std::size_t end) const;
  void emit_error(std::size_t count, ErrorKind kind, std::string detail, std::string context,
                  std::vector<Item>& out);
  void restart_hunting();

  DecoderOptions options_;
  SequenceMatcher start_;
  Bytes buf_;             // bytes not yet handed out in an item
  std::size_t scan_ = 0;  // buf_[0, scan_) has been examined
  std::size_t need_ = 0;  // candidate size once its length byte is known
  State state_ = State::hunting;
};

}  // namespace hil::protocol::leka
