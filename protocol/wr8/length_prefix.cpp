#include "protocol/wr8/length_prefix.hpp"

#include <stdexcept>
#include <string>

namespace hil::protocol::wr8 {

Bytes prefix_length(ByteView packet) {
  if (packet.empty()) throw std::invalid_argument("WR8 length prefix: an empty packet");
  if (packet.size() > kLongestPrefixedPacket) {
    throw std::invalid_argument("WR8 length prefix: a packet of " + std::to_string(packet.size()) +
                                " bytes; one length byte frames at most " +
                                std::to_string(kLongestPrefixedPacket));
  }
  Bytes out;
  out.reserve(packet.size() + 1);
  out.push_back(static_cast<std::uint8_t>(packet.size()));
  out.insert(out.end(), packet.begin(), packet.end());
  return out;
}

namespace {

DecodeError bad_length(std::uint8_t length) {
  if (length == 0) {
    return DecodeError{ErrorKind::bad_format, Bytes{length},
                       "length byte 0x00 frames no packet", "length"};
  }
  return DecodeError{ErrorKind::oversized, Bytes{length},
                     "length byte " + hex_literal(length) +
                         " is negative as a signed char: a packet of 128 bytes or more cannot be "
                         "framed",
                     "length"};
}

}  // namespace

void LengthPrefixSplitter::feed(ByteView bytes, std::vector<PrefixedItem>& out) {
  for (const std::uint8_t b : bytes) {
    if (buf_.empty()) {
      if (b == 0 || b > kLongestPrefixedPacket) {
        out.emplace_back(bad_length(b));
        continue;
      }
      want_ = b;
      buf_.push_back(b);
      continue;
    }
    buf_.push_back(b);
    if (buf_.size() == want_ + 1) {
      Bytes packet(buf_.begin() + 1, buf_.end());
      out.emplace_back(Frame<Bytes>{std::move(packet), std::move(buf_), std::nullopt});
      buf_.clear();
      want_ = 0;
    }
  }
}

void LengthPrefixSplitter::finish(std::vector<PrefixedItem>& out) {
  if (buf_.empty()) return;
  const std::size_t got = buf_.size() - 1;
  out.emplace_back(DecodeError{ErrorKind::truncated, std::move(buf_),
                               "the stream ended " + std::to_string(got) + " of " +
                                   std::to_string(want_) + " packet bytes after its length byte",
                               "length"});
  buf_.clear();
  want_ = 0;
}

}  // namespace hil::protocol::wr8
