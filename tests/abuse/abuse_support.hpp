#pragma once
// What the abuse tests share: hil (or a client program) run as a real
// process whose pid, liveness and resident memory the test can see, and
// raw client/car ends (TCP sockets, pty ends) written and read with bounded
// waits.

#include <sys/resource.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>

#include "tests/support/connection.hpp"
#include "tests/support/process.hpp"
#include "tests/support/sanitizers.hpp"

namespace hil::test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

/// HIL_ABUSE_FULL=1 selects the full sizes (256 MiB, 10,000 cycles, a
/// whole frame at one byte a second); otherwise the short CI form, which
/// sends less under a sanitizer (kSanitizerBuild; the same properties are
/// asserted).
inline bool full_form() {
  const char* v = std::getenv("HIL_ABUSE_FULL");
  return v != nullptr && std::string(v) == "1";
}

/// Raises this process's open-file soft limit to the hard limit (for a
/// thousand sockets at once); processes started earlier keep theirs.
inline void raise_file_limit() {
  rlimit r{};
  if (::getrlimit(RLIMIT_NOFILE, &r) == 0 && r.rlim_cur < r.rlim_max) {
    r.rlim_cur = r.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &r);
  }
}

/// `n` bytes from a seeded generator (printed by the caller for replay).
inline std::string random_bytes(std::mt19937_64& rng, std::size_t n) {
  std::string out(n, '\0');
  for (std::size_t i = 0; i < n; i += 8) {
    const std::uint64_t v = rng();
    for (std::size_t k = 0; k < 8 && i + k < n; ++k)
      out[i + k] = static_cast<char>((v >> (8 * k)) & 0xFF);
  }
  return out;
}

}  // namespace hil::test
