#pragma once
// The usual visitor helper for std::visit over several lambdas.

namespace hil::protocol {

template <class... Fs>
struct Overloaded : Fs... {
  using Fs::operator()...;
};

}  // namespace hil::protocol
