#pragma once
// What the conformance tests share: the exchanges on which hil's mock in
// one profile answers a probe written in another differently.
#include <set>
#include <string>
#include <string_view>

#include "conform/check.hpp"

namespace hil::conform::test {

/// The names of the exchanges of `car`'s probe, written in profile
/// `probed` and played by the mock in `probed`, that the mock in `mock`
/// answers differently (both runs in virtual time).
inline std::set<std::string> differing(mocks::CarKind car, std::string_view probed,
                                       std::string_view mock) {
  const auto probe = make_probe(car, probed);
  const auto as_car = probe_mock(probe, probed);
  const auto comparison = compare(as_car, probe_mock(probe, mock), probe, std::string(mock));
  std::set<std::string> names;
  for (const auto& e : comparison.exchanges) {
    if (!e.matches()) names.insert(e.name);
  }
  return names;
}

}  // namespace hil::conform::test
