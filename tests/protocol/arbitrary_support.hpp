#pragma once
// Building blocks for the protocols' rapidcheck generators.

#include <rapidcheck.h>

#include <cstddef>
#include <vector>

namespace hil::test {

/// rapidcheck's Arbitrary for a type whose every value `all` lists (see
/// HIL_ARBITRARY_ELEMENT_OF).
template <const auto& all>
struct ArbitraryElementOf {
  static auto arbitrary() { return rc::gen::elementOf(all); }
};

/// Inside namespace rc: rapidcheck's Arbitrary for `Type`, drawn from the
/// array `all` of its every value.
#define HIL_ARBITRARY_ELEMENT_OF(Type, all) \
  template <>                               \
  struct Arbitrary<Type> : hil::test::ArbitraryElementOf<all> {}

/// Up to `n` arbitrary values of T.
template <class T>
rc::Gen<std::vector<T>> up_to(std::size_t n) {
  return rc::gen::resize(static_cast<int>(n),
                         rc::gen::container<std::vector<T>>(rc::gen::arbitrary<T>()));
}

}  // namespace hil::test
