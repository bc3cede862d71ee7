#pragma once
// Helpers for tests that run the real-time driver: bounded runs of an
// io_context, so no test can hang.

#include <chrono>
#include <functional>

#include <asio/io_context.hpp>

namespace hil::link::test {

/// Runs the io_context until `done()` holds or `limit` passes. Returns
/// whether `done()` held.
inline bool run_until(asio::io_context& io, const std::function<bool()>& done,
                      std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    if (io.stopped()) io.restart();
    io.run_one_for(std::chrono::milliseconds(5));
  }
  return true;
}

/// Runs the io_context for about `d` (handlers keep running meanwhile).
inline void run_for(asio::io_context& io, std::chrono::milliseconds d) {
  const auto deadline = std::chrono::steady_clock::now() + d;
  while (std::chrono::steady_clock::now() < deadline) {
    if (io.stopped()) io.restart();
    io.run_one_until(deadline);
  }
}

}  // namespace hil::link::test
