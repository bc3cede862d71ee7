#include "link/faults/frame_faults.hpp"

#include <algorithm>
#include <cstdint>
#include <string_view>

namespace hil::link::faults {
namespace {

using protocol::Bytes;

bool is_digit(std::uint8_t c) {
  return c >= '0' && c <= '9';
}
bool is_upper(std::uint8_t c) {
  return c >= 'A' && c <= 'Z';
}
bool is_lower(std::uint8_t c) {
  return c >= 'a' && c <= 'z';
}
bool is_hex(std::uint8_t c) {
  return is_digit(c) || (c >= 'A' && c <= 'F') || (c >= 'a' && c <= 'f');
}

/// Another byte for `c`. In text, a checksum's hex digit becomes another
/// hex digit (in the checksum's case), a digit another digit, a letter
/// another letter of its case; anything else has one random bit flipped.
std::uint8_t substitute(std::uint8_t c, bool text, bool checksum, bool lower_hex,
                        FaultRandom& rng) {
  const auto other = [&](std::string_view set) {
    const auto pos = set.find(static_cast<char>(c));
    auto k = static_cast<std::size_t>(rng.below(set.size() - 1));
    if (pos != std::string_view::npos && k >= pos) ++k;  // skip c itself
    return static_cast<std::uint8_t>(set[k]);
  };
  if (text) {
    if (checksum && is_hex(c)) return other(lower_hex ? "0123456789abcdef" : "0123456789ABCDEF");
    if (is_digit(c)) return other("0123456789");
    if (is_upper(c)) return other("ABCDEFGHIJKLMNOPQRSTUVWXYZ");
    if (is_lower(c)) return other("abcdefghijklmnopqrstuvwxyz");
  }
  return static_cast<std::uint8_t>(c ^ (1U << rng.below(8)));
}

std::string flip_random_bits(std::size_t bits, Bytes& bytes, FaultRandom& rng) {
  const std::size_t total_bits = bytes.size() * 8;
  const std::size_t count = std::min(bits, total_bits);
  std::vector<std::size_t> chosen;
  while (chosen.size() < count) {
    const auto bit = static_cast<std::size_t>(rng.below(total_bits));
    if (std::find(chosen.begin(), chosen.end(), bit) != chosen.end()) continue;
    chosen.push_back(bit);
    bytes[bit / 8] = static_cast<std::uint8_t>(bytes[bit / 8] ^ (1U << (bit % 8)));
  }
  return std::to_string(count) + " random bit" + (count == 1 ? "" : "s") + " flipped";
}

}  // namespace

Duration between(FaultRandom& rng, Duration lo, Duration hi) {
  const auto span = static_cast<std::uint64_t>((hi - lo).count());
  return lo + Duration{static_cast<Duration::rep>(rng.between(0, span))};
}

std::size_t between(FaultRandom& rng, std::size_t lo, std::size_t hi) {
  return static_cast<std::size_t>(rng.between(lo, hi));
}

std::string corrupt(const Corrupt& c, Bytes& bytes, ByteRange range, bool text, FaultRandom& rng) {
  if (c.target == CorruptTarget::random) return flip_random_bits(c.bits, bytes, rng);
  // Checksum or field: change whole bytes, keeping text in its character
  // class so the frame still parses and only the value is wrong.
  const std::size_t width = range.second - range.first;
  const std::size_t count = std::min(c.bits, width);
  const bool checksum = c.target == CorruptTarget::checksum;
  bool lower_hex = false;
  for (std::size_t k = range.first; k < range.second; ++k) {
    lower_hex = lower_hex || (bytes[k] >= 'a' && bytes[k] <= 'f');
  }
  std::vector<std::size_t> chosen;
  while (chosen.size() < count) {
    const std::size_t at = range.first + static_cast<std::size_t>(rng.below(width));
    if (std::find(chosen.begin(), chosen.end(), at) != chosen.end()) continue;
    chosen.push_back(at);
    bytes[at] = substitute(bytes[at], text, checksum, lower_hex, rng);
  }
  return (checksum ? std::string("checksum") : "field " + c.field) + ": " + std::to_string(count) +
         " byte" + (count == 1 ? "" : "s") + " changed";
}

std::string drop_bytes(const Drop& d, Bytes& bytes, FaultRandom& rng) {
  const std::size_t k = std::min(bytes.size(), between(rng, d.count.min, d.count.max));
  const std::size_t at = between(rng, 0, bytes.size() - k);
  const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(at);
  bytes.erase(first, first + static_cast<std::ptrdiff_t>(k));
  return std::to_string(k) + " bytes dropped at offset " + std::to_string(at);
}

std::string duplicate(const Duplicate& d, Bytes& bytes) {
  const Bytes once = bytes;
  for (std::size_t c = 0; c < d.copies; ++c)
    bytes.insert(bytes.end(), once.begin(), once.end());
  return std::to_string(d.copies) + (d.copies == 1 ? " copy" : " copies") + " added";
}

std::string add_garbage(const Garbage& g, Bytes& bytes, FaultRandom& rng) {
  Bytes noise = g.fixed;
  if (noise.empty()) {
    noise.resize(between(rng, g.length.min, g.length.max));
    for (auto& b : noise)
      b = static_cast<std::uint8_t>(rng.below(256));
  }
  bytes.insert(bytes.begin(), noise.begin(), noise.end());
  return std::to_string(noise.size()) + " garbage bytes before the frame";
}

Duration delay_of(const Delay& d, FaultRandom& rng) {
  return d.base + between(rng, Duration{0}, d.jitter);
}

std::vector<Piece> fragment(const Fragment& f, std::size_t size, FaultRandom& rng) {
  std::vector<Piece> pieces;
  for (std::size_t left = size; left > 0;) {
    Piece p;
    p.bytes = std::min(left, between(rng, f.piece_bytes.min, f.piece_bytes.max));
    left -= p.bytes;
    p.gap = left > 0 ? between(rng, f.gap.min, f.gap.max) : Duration{0};
    pieces.push_back(p);
  }
  return pieces;
}

std::string describe(const std::vector<Piece>& pieces) {
  std::string detail = std::to_string(pieces.size()) + " pieces:";
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    detail += (k == 0 ? " " : " + ") + std::to_string(pieces[k].bytes);
  }
  return detail + " bytes";
}

}  // namespace hil::link::faults
