#pragma once
// Draws the terminal UI model's Render with ncurses windows, and turns
// ncurses key codes into the model's codes.

#include <cstddef>
#include <optional>

#include "apps/logi-client/tui_model.hpp"

namespace hil::apps::logi_client {

/// Where each part of the screen goes for a terminal of `rows` x `columns`.
struct TuiLayout {
  struct Box {
    int top = 0;
    int left = 0;
    int height = 0;
    int width = 0;
  };
  Box header;
  Box banner;  ///< height 0 without the stale warning
  Box status;
  Box controls;
  Box log;
  Box message;
  Box help;
  /// Log lines that fit inside the log box's border.
  std::size_t log_rows() const {
    return log.height > 2 ? static_cast<std::size_t>(log.height - 2) : 0;
  }
};

/// Places the parts: header, stale banner (3 rows from 30 rows up, else 1),
/// status beside controls, the log taking what is left, message and help.
TuiLayout layout_screen(int rows, int columns, const Render& render);

/// The ncurses screen: initscr on construction, endwin on destruction.
class TuiScreen {
 public:
  TuiScreen();
  ~TuiScreen();
  TuiScreen(const TuiScreen&) = delete;
  TuiScreen& operator=(const TuiScreen&) = delete;

  /// Reads one key without waiting; nullopt when none is available.
  /// KEY_RESIZE is handled here (and reported as no key).
  std::optional<int> read_key();
  /// Takes the terminal's new size (after SIGWINCH).
  void resize();
  /// Lays out and draws the model's screen.
  void draw(const TuiModel& model, Time now);

 private:
  void destroy_windows();

  struct Windows;
  Windows* windows_ = nullptr;
  int rows_ = 0;
  int columns_ = 0;
  bool colors_ = false;
};

}  // namespace hil::apps::logi_client
