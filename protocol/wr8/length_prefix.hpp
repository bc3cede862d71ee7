#pragma once
// The framing layer of the real WR8 programs (smart_vehicle_gui, both the
// 2019 version and the maintained one): one length byte before every
// packet, in both directions. The byte is a signed char holding the number
// of packet bytes after it, so a packet of 128 bytes or more cannot be
// framed; the receiver of the real programs then reads with a negative
// size (docs/protocols/wr8.md).
//
// This layer only cuts a stream into packets; what a packet means is the
// dialect's codec's business.

#include <cstddef>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::protocol::wr8 {

/// The longest packet one length byte can frame: 127 bytes.
inline constexpr std::size_t kLongestPrefixedPacket = 127;

/// `packet` with its length byte in front. Throws std::invalid_argument for
/// an empty packet or one longer than kLongestPrefixedPacket: no receiver
/// could read it back.
Bytes prefix_length(ByteView packet);

/// One framed packet: `message` is the packet without its length byte,
/// `raw` the length byte and the packet.
using PrefixedItem = DecodeItem<Bytes>;

/// Incremental splitter of a length-prefixed stream: any chunking gives the
/// same items, and every input byte is in exactly one item. Never throws.
/// A length byte of 0 (ErrorKind::bad_format) or of 0x80 and above
/// (ErrorKind::oversized) is an error item of that one byte, and the next
/// byte is read as a length byte again: the stream holds no other marker
/// to find the next packet by. Holds at most 128 bytes.
class LengthPrefixSplitter {
 public:
  void feed(ByteView bytes, std::vector<PrefixedItem>& out);
  /// End of stream: a packet cut short comes out as ErrorKind::truncated.
  void finish(std::vector<PrefixedItem>& out);
  std::size_t buffered() const { return buf_.size(); }

 private:
  Bytes buf_;             ///< the length byte and the packet bytes so far
  std::size_t want_ = 0;  ///< packet bytes the length byte declared
};

}  // namespace hil::protocol::wr8
