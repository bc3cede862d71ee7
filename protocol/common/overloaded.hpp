#pragma once
// The usual visitor helper for std::visit over several lambdas.

namespace hil::protocol {

template <class... Fs>
struct Overloaded : Fs... {
  using Fs::operator()...;
};
// Clang 14 does not deduce aggregate template arguments by itself.
template <class... Fs>
Overloaded(Fs...) -> Overloaded<Fs...>;

}  // namespace hil::protocol
