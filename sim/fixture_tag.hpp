#pragma once
// What a Box2D fixture stands for, packed into its user data.

#include <cstdint>

namespace hil::sim::detail {

enum class FixtureKind : std::uintptr_t { none = 0, wall = 1, obstacle = 2, vehicle = 3 };

inline std::uintptr_t fixture_tag(FixtureKind kind, std::uintptr_t index) {
  return (static_cast<std::uintptr_t>(kind) << 32) | index;
}
inline FixtureKind fixture_kind(std::uintptr_t tag) {
  return static_cast<FixtureKind>(tag >> 32);
}
inline std::uintptr_t fixture_index(std::uintptr_t tag) {
  return tag & 0xFFFFFFFFu;
}

}  // namespace hil::sim::detail
