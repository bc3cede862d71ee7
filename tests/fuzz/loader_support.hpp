#pragma once
// Shared by the loader fuzz targets: the input bytes as YAML text, and a
// guard that turns any exception other than the loader's own into a crash.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string_view>
#include <typeinfo>

namespace hil::fuzz {

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Runs `load`; the loader's own `Error` type is a correct refusal, anything
/// else that escapes is a broken contract (reported as a crash, with its
/// type and message so the finding reads well).
template <class Error, class Load>
void expect_only(Load&& load) {
  try {
    load();
  } catch (const Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loader threw %s instead of its own error: %s\n", typeid(e).name(),
                 e.what());
    std::abort();
  }
}

}  // namespace hil::fuzz
