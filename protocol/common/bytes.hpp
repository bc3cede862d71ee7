#pragma once
// Byte buffers and the hex/text renderings every protocol tool shares.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hil::protocol {

using Bytes = std::vector<std::uint8_t>;
using ByteView = std::span<const std::uint8_t>;

/// Bytes of an ASCII/text string, unchanged.
Bytes to_bytes(std::string_view text);

/// The bytes as a string, unchanged (may contain non-printable characters).
std::string to_string(ByteView bytes);

/// Spaced uppercase hex: "2A 2B 2C".
std::string to_hex(ByteView bytes);

/// One byte as a C literal: "0x2A".
std::string hex_literal(std::uint8_t byte);

/// Parses hex written with or without spaces, commas or a 0x prefix per byte
/// ("2A 2B", "2a2b", "0x2A,0x2B"). Returns nullopt on an odd digit count or a
/// character that is not hex.
std::optional<Bytes> parse_hex(std::string_view text);

/// Printable rendering for logs: printable ASCII as is, anything else as \xHH.
std::string escape(ByteView bytes);

}  // namespace hil::protocol
