#pragma once
// What the link layer needs to know about a protocol: where frames begin and
// end in a byte stream, what kind each frame is, and where its checksum and
// fields are, so faults can act on frames and captures can show messages.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "link/faults/profile.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/wr8/profile.hpp"

namespace hil::link {

/// One frame (or one undecodable run of bytes) cut from a stream.
struct WireFrame {
  protocol::Bytes raw;
  bool valid = false;  ///< decoded cleanly
  /// Hierarchical kind, ':'-separated, matched by prefix: "FB:ST", "MV:FWD",
  /// "STAT" (LOGI); "V", "ACK" (Arduino); "TASK", "HIGH_FREQ_DATA" (WR8); the first
  /// command's name (Leka). For invalid bytes, the decoder's context if any.
  std::string kind;
  std::string text;  ///< the decoded message or the error, one line
};

/// Cuts a byte stream into WireFrames. Every input byte lands in exactly one
/// frame; any chunking gives the same frames.
class FrameSplitter {
 public:
  virtual ~FrameSplitter() = default;
  virtual void feed(protocol::ByteView bytes, std::vector<WireFrame>& out) = 0;
  virtual void finish(std::vector<WireFrame>& out) = 0;
  /// Bytes held that belong to no frame yet.
  virtual std::size_t buffered() const = 0;
};

/// Byte range [first, second) within a frame.
using ByteRange = std::pair<std::size_t, std::size_t>;

class ProtocolAdapter {
 public:
  virtual ~ProtocolAdapter() = default;
  /// "logi", "wr8", "arduino", "leka" or "raw".
  virtual std::string_view name() const = 0;
  /// The car's profile the adapter frames by ("firmware", "comspecs-v3",
  /// ...; protocol/common/car_profile.hpp); empty for raw.
  virtual std::string_view profile() const = 0;
  /// `with_text` false leaves WireFrame::text empty for valid frames: the
  /// fault injector needs kinds, not descriptions, and skipping them is most
  /// of the cost of splitting a fast stream.
  virtual std::unique_ptr<FrameSplitter> splitter(bool with_text = true) const = 0;
  /// The splitter for one direction of a link. Most protocols frame both
  /// directions alike; Leka's robot answers in text lines, not command frames.
  virtual std::unique_ptr<FrameSplitter> splitter_for(Direction direction,
                                                      bool with_text = true) const {
    (void)direction;
    return splitter(with_text);
  }
  /// Whether frames are lines of text (LOGI, Arduino): a fault that changes
  /// a checksum or field then keeps each character in its class (a digit
  /// stays a digit, a letter a letter), so the frame still parses.
  virtual bool text_frames() const = 0;
  /// Where the checksum is written in a frame; nullopt when the protocol has
  /// none (WR8, raw) or the frame is not one.
  virtual std::optional<ByteRange> checksum_field(protocol::ByteView frame) const = 0;
  /// A named field of a frame (names per protocol, see docs/faults.md).
  virtual std::optional<ByteRange> field(protocol::ByteView frame, std::string_view name) const = 0;
  /// The names field() knows.
  virtual std::vector<std::string> field_names() const = 0;
};

/// The adapter for a protocol name; throws std::invalid_argument naming the
/// known protocols for an unknown one.
std::shared_ptr<const ProtocolAdapter> protocol_adapter(std::string_view name);

/// The adapter for a car's profile (protocol/common/car_profile.hpp); an
/// empty profile is the car's default. Arduino `firmware` judges the frames
/// towards the board as the real sketch does; Leka `comspecs-v3` decodes by
/// the spec's YAML ids and checksum; WR8 `svgui-2019` and `svgui-head` cut
/// the stream by the length byte before every packet, so a frame is the
/// length byte and its packet (protocol/wr8/svgui.hpp). Throws
/// protocol::ProfileError for a profile the car does not have (or any
/// profile for "raw").
std::shared_ptr<const ProtocolAdapter> protocol_adapter(std::string_view name,
                                                        std::string_view profile);

/// The WR8 adapter of the `document` dialect for a firmware whose byte
/// order, block sizes or DATA table differ from the default
/// (protocol_adapter("wr8") uses the default).
std::shared_ptr<const ProtocolAdapter> wr8_adapter(const protocol::wr8::Profile& profile);

}  // namespace hil::link
