#pragma once
// Part of the fault injector (fault_injector.hpp): what the rules that change
// a frame's bytes, or choose its timing, do to one frame. Each function
// draws its random choices from `rng` in a fixed order, so a seed gives the
// same faults on every build; those that change bytes return what they did,
// for a person.

#include <cstddef>
#include <string>
#include <vector>

#include "link/faults/profile.hpp"
#include "link/faults/random.hpp"
#include "link/protocol_adapter.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::link::faults {

/// Uniform in [lo, hi].
Duration between(FaultRandom& rng, Duration lo, Duration hi);
std::size_t between(FaultRandom& rng, std::size_t lo, std::size_t hi);

/// Changes `bytes` within `range` as `c` says. With `text` (the protocol's
/// frames are text, ProtocolAdapter::text_frames) a changed character stays
/// in its class: a digit becomes another digit, a letter another letter.
std::string corrupt(const Corrupt& c, protocol::Bytes& bytes, ByteRange range, bool text,
                    FaultRandom& rng);
/// Removes d.count consecutive bytes at a random place; `bytes` is not empty.
std::string drop_bytes(const Drop& d, protocol::Bytes& bytes, FaultRandom& rng);
/// Appends d.copies copies of the frame.
std::string duplicate(const Duplicate& d, protocol::Bytes& bytes);
/// Puts g's bytes (or random ones) before the frame.
std::string add_garbage(const Garbage& g, protocol::Bytes& bytes, FaultRandom& rng);
/// How long `d` holds one frame back.
Duration delay_of(const Delay& d, FaultRandom& rng);

/// One piece of a fragmented write and the gap after it.
struct Piece {
  std::size_t bytes = 0;
  Duration gap{0};
};
/// The pieces `f` cuts a write of `size` bytes into (the last gap is 0).
std::vector<Piece> fragment(const Fragment& f, std::size_t size, FaultRandom& rng);
/// "3 pieces: 4 + 4 + 2 bytes".
std::string describe(const std::vector<Piece>& pieces);

}  // namespace hil::link::faults
