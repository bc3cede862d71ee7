#pragma once
// The names of an enum's values, one table for both ways: name() for
// printing, parse() for reading a word back, and list() / names() for the
// "expected a, b or c" of an error message. Each entry pairs a value with
// its name, so the table does not depend on the enum's order, leaves out
// values that have no name, and serves integer codes as well as enums:
//
//   constexpr auto kCarKindNames = base::enum_names<CarKind>(
//       {CarKind::logi, "logi"}, {CarKind::wr8, "wr8"}, {CarKind::arduino, "arduino"});
//   kCarKindNames.name(CarKind::wr8)     // "wr8"
//   kCarKindNames.parse("arduino")       // CarKind::arduino
//   kCarKindNames.list(" or ")           // "logi, wr8 or arduino"

#include <array>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hil::base {

/// One value and its name.
template <typename E>
struct EnumName {
  E value;
  std::string_view name;
};

/// A fixed table of names, in the order given (the order list() and names()
/// write). No value and no name appears twice: a constexpr table with a
/// repeat does not compile, any other throws std::logic_error.
template <typename E, std::size_t N>
class EnumNames {
 public:
  constexpr explicit EnumNames(const std::array<EnumName<E>, N>& entries) : entries_(entries) {
    for (std::size_t i = 0; i < N; ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if (entries_[i].value == entries_[j].value || entries_[i].name == entries_[j].name)
          throw std::logic_error("an enum name table names a value or uses a name twice");
      }
    }
  }

  /// The name of `value`; nullopt for a value the table leaves out.
  constexpr std::optional<std::string_view> find(E value) const {
    for (const auto& entry : entries_) {
      if (entry.value == value) return entry.name;
    }
    return std::nullopt;
  }

  /// The name of `value`, or `fallback` for a value the table leaves out.
  constexpr std::string_view name(E value, std::string_view fallback = "?") const {
    return find(value).value_or(fallback);
  }

  /// The value named exactly `text` (case and all); nullopt for another word.
  constexpr std::optional<E> parse(std::string_view text) const {
    for (const auto& entry : entries_) {
      if (entry.name == text) return entry.value;
    }
    return std::nullopt;
  }

  /// The names joined with ", ", the last two with `last`: list() is
  /// "a, b, c", list(" or ") is "a, b or c" (and "a or b" for two).
  std::string list(std::string_view last = ", ") const {
    std::string out;
    for (std::size_t i = 0; i < N; ++i) {
      if (i > 0) out += i + 1 == N ? last : std::string_view(", ");
      out += entries_[i].name;
    }
    return out;
  }

  /// The names, for a search of the closest one to a misspelt word.
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    out.reserve(N);
    for (const auto& entry : entries_)
      out.emplace_back(entry.name);
    return out;
  }

  constexpr std::size_t size() const { return N; }
  constexpr auto begin() const { return entries_.begin(); }
  constexpr auto end() const { return entries_.end(); }

 private:
  std::array<EnumName<E>, N> entries_;
};

namespace enum_names_detail {

template <typename E, std::size_t>
using Entry = EnumName<E>;

/// The maker of a table of exactly sizeof...(I) entries.
template <typename E, typename Indices>
struct MakerOf;
template <typename E, std::size_t... I>
struct MakerOf<E, std::index_sequence<I...>> {
  constexpr EnumNames<E, sizeof...(I)> operator()(Entry<E, I>... entries) const {
    return EnumNames<E, sizeof...(I)>({entries...});
  }
};

/// One call operator per table size from 1 to sizeof...(N): the entries
/// are plain arguments, so each may be a braced {value, "name"} pair.
template <typename E, typename Sizes>
struct Maker;
template <typename E, std::size_t... N>
struct Maker<E, std::index_sequence<N...>> : MakerOf<E, std::make_index_sequence<N + 1>>... {
  using MakerOf<E, std::make_index_sequence<N + 1>>::operator()...;
};

}  // namespace enum_names_detail

/// The most entries one enum_names call takes.
inline constexpr std::size_t kMaxEnumNames = 32;

/// A table from {value, "name"} pairs, one argument each:
/// `enum_names<Colour>({Colour::red, "red"}, {Colour::green, "green"})`.
template <typename E>
inline constexpr enum_names_detail::Maker<E, std::make_index_sequence<kMaxEnumNames>> enum_names{};

}  // namespace hil::base
