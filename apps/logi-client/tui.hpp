#pragma once
// The logi-client interactive terminal UI: every control of a LOGI upper
// computer on one ncurses screen, over a LogiSession.

#include <cstdint>
#include <string>

namespace hil::apps::logi_client {

struct TuiOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 9000;
  bool connect_at_start = true;  ///< connect as the screen opens
  bool keepalive = false;        ///< repeat the held MV every 300 ms
  std::string log_dir = ".";     ///< where the log is saved from the UI
};

/// Runs the terminal UI until the operator quits; returns the exit code.
int run_tui(const TuiOptions& options);

}  // namespace hil::apps::logi_client
