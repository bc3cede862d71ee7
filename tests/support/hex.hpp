#pragma once
// Test vectors written as hex text ("2A 2B 2C"): the bytes they spell.

#include <stdexcept>
#include <string>
#include <string_view>

#include "protocol/common/bytes.hpp"

namespace hil::test {

/// The bytes of a vector in any form protocol::parse_hex reads; a typo in
/// the vector throws, naming it, instead of testing the wrong bytes.
inline protocol::Bytes hex(std::string_view text) {
  auto bytes = protocol::parse_hex(text);
  if (!bytes) throw std::invalid_argument("bad hex in a test vector: " + std::string(text));
  return *bytes;
}

}  // namespace hil::test
