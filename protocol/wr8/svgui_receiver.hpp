#pragma once
// How the real smart_vehicle_gui programs read their socket, one Qt
// readyRead event at a time (docs/protocols/wr8.md, "The real programs").
// Neither program reassembles a stream: each event takes the length byte
// and then
//  - v2019: everything that is available, as one packet, whatever the
//    length byte said (coalesced packets are read as one, a split packet
//    as a short one and its rest as the next);
//  - head: as many bytes as the length byte says, or fewer if fewer have
//    come, and leaves the rest unread until the next event. Qt raises the
//    next event only when more bytes arrive, so under coalescing the
//    program runs one packet behind.
// A mock vehicle that plays a real version reads its client this way, so
// a client that only works with a reassembling peer fails against it as it
// would against the car.

#include <cstddef>
#include <cstdint>

#include "protocol/common/bytes.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::protocol::wr8::svgui {

/// What one read event hands the program's packet handler.
struct ReadEvent {
  std::uint8_t length_byte = 0;
  /// The bytes taken as the packet (code first); empty when none were.
  Bytes packet;
  /// Fewer bytes than the length byte declared were there (head), or a
  /// different number (v2019, which reads whatever is there).
  bool length_mismatch = false;
  /// head only: a length byte of 0, or of 0x80 and above (negative as a
  /// signed char): the real program reads no packet and its handler then
  /// indexes an empty buffer.
  bool unreadable_length = false;
  friend bool operator==(const ReadEvent&, const ReadEvent&) = default;
};

class ProgramReceiver {
 public:
  explicit ProgramReceiver(Version version) : version_(version) {}

  /// Bytes that arrived: raises one read event over everything unread
  /// (what came before and was left, and `arrived`). Returns false, and
  /// leaves `event` alone, when nothing is unread.
  bool on_arrival(ByteView arrived, ReadEvent& event);
  /// Bytes left unread after the last event (head only).
  std::size_t unread() const { return unread_.size(); }
  Version version() const { return version_; }
  /// A new connection: nothing unread.
  void reset() { unread_.clear(); }

 private:
  Version version_;
  Bytes unread_;
};

}  // namespace hil::protocol::wr8::svgui
