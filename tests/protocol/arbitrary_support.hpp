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

template <class Member>
struct ClassOf;
template <class Class, class T>
struct ClassOf<T Class::*> {
  using type = Class;
};

/// rapidcheck's Arbitrary for a struct whose data members `first`,
/// `rest`... take arbitrary values (see HIL_ARBITRARY_FIELDS).
template <auto first, auto... rest>
struct ArbitraryFields {
  using Type = typename ClassOf<decltype(first)>::type;
  static rc::Gen<Type> arbitrary() {
    return rc::gen::build<Type>(rc::gen::set(first), rc::gen::set(rest)...);
  }
};

/// Inside namespace rc: rapidcheck's Arbitrary for `Type`, built from the
/// members named after it (&Type::member, ...), each arbitrary.
#define HIL_ARBITRARY_FIELDS(Type, ...) \
  template <>                           \
  struct Arbitrary<Type> : hil::test::ArbitraryFields<__VA_ARGS__> {}

/// Up to `n` arbitrary values of T.
template <class T>
rc::Gen<std::vector<T>> up_to(std::size_t n) {
  return rc::gen::resize(static_cast<int>(n),
                         rc::gen::container<std::vector<T>>(rc::gen::arbitrary<T>()));
}

}  // namespace hil::test
