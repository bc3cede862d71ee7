#include "apps/logi-client/tui_view.hpp"

#include <curses.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <clocale>
#include <iterator>
#include <string>

namespace hil::apps::logi_client {

namespace {

enum ColorPair : short { kBanner = 1, kWarning, kGood, kAlert, kTitle };

int attributes(Style style, bool colors) {
  switch (style) {
    case Style::normal:
      return A_NORMAL;
    case Style::dim:
      return A_DIM;
    case Style::bold:
      return A_BOLD;
    case Style::good:
      return colors ? static_cast<int>(COLOR_PAIR(kGood)) : A_NORMAL;
    case Style::warning:
      return colors ? static_cast<int>(COLOR_PAIR(kWarning) | A_BOLD) : A_BOLD;
    case Style::alert:
      return colors ? static_cast<int>(COLOR_PAIR(kAlert) | A_BOLD) : (A_BOLD | A_REVERSE);
  }
  return A_NORMAL;
}

int to_model_key(int ch) {
  // kCurses[i], curses' code, is the model's kModel[i].
  static constexpr int kCurses[] = {
      KEY_UP,    KEY_DOWN,      KEY_LEFT, KEY_RIGHT, KEY_PPAGE, KEY_NPAGE, KEY_HOME, KEY_END,
      KEY_F(10), KEY_BACKSPACE, KEY_DC,   8,         127,       KEY_ENTER, '\r',     '\n'};
  static constexpr int kModel[] = {
      key::kUp,        key::kDown,  key::kLeft,  key::kRight,     key::kPageUp,    key::kPageDown,
      key::kHome,      key::kEnd,   key::kF10,   key::kBackspace, key::kBackspace, key::kBackspace,
      key::kBackspace, key::kEnter, key::kEnter, key::kEnter};
  static_assert(std::size(kCurses) == std::size(kModel));
  for (std::size_t i = 0; i < std::size(kModel); ++i) {
    if (ch == kCurses[i]) return kModel[i];
  }
  return ch;
}

// Writes `text` from column `x` on row `y`, cut to fit the window.
void put(WINDOW* w, int y, int x, const std::string& text, int attr) {
  const int width = getmaxx(w) - x;
  if (width <= 0 || y < 0 || y >= getmaxy(w)) return;
  wattron(w, attr);
  mvwaddnstr(w, y, x, text.c_str(), width);
  wattroff(w, attr);
}

void draw_panel(WINDOW* w, const Panel& panel, bool colors) {
  if (w == nullptr) return;
  werase(w);
  box(w, 0, 0);
  put(w, 0, 2, " " + panel.title + " ", colors ? static_cast<int>(COLOR_PAIR(kTitle)) : A_BOLD);
  const int inner = getmaxy(w) - 2;
  for (int i = 0; i < inner && i < static_cast<int>(panel.lines.size()); ++i) {
    const auto& line = panel.lines[static_cast<std::size_t>(i)];
    // Keep the right border: cut one column early.
    const int width = getmaxx(w) - 3;
    if (width > 0)
      put(w, i + 1, 1, " " + line.text.substr(0, static_cast<std::size_t>(width)),
          attributes(line.style, colors));
  }
  wnoutrefresh(w);
}

}  // namespace

namespace {
constexpr int kControlsWidth = 41;
}  // namespace

TuiLayout layout_screen(int rows, int columns, const Render& render) {
  TuiLayout l;
  int row = 0;
  l.header = {row, 0, 1, columns};
  row += 1;
  if (render.stale) {
    const int h = rows >= 30 ? 3 : 1;
    l.banner = {row, 0, h, columns};
    row += h;
  }
  const int help_rows = rows >= 20 ? static_cast<int>(render.help.size()) : 1;
  const int bottom = 1 + help_rows;  // message line + help
  const int wanted =
      static_cast<int>(std::max(render.status.lines.size(), render.controls.lines.size())) + 2;
  // The log keeps at least 3 lines of its own when the screen allows.
  const int room = rows - row - bottom - 5;
  const int top_height = std::max(3, std::min(wanted, room));
  // The controls keep the 41 columns their longest line needs with its
  // frame ("Speed   [##########] 100 % Enter sends"); the status takes the
  // rest, 26 to 40: at 80 columns its 36 characters hold the longest
  // STAT line ("RPM  LR -113 LF -113 RF -113 RR -113").
  const int status_width = std::clamp(columns - kControlsWidth, 26, 40);
  l.status = {row, 0, top_height, status_width};
  l.controls = {row, status_width, top_height, columns - status_width};
  row += top_height;
  l.log = {row, 0, std::max(0, rows - row - bottom), columns};
  row += l.log.height;
  l.message = {row, 0, 1, columns};
  l.help = {row + 1, 0, help_rows, columns};
  return l;
}

struct TuiScreen::Windows {
  WINDOW* header = nullptr;
  WINDOW* banner = nullptr;
  WINDOW* status = nullptr;
  WINDOW* controls = nullptr;
  WINDOW* log = nullptr;
  WINDOW* message = nullptr;
  WINDOW* help = nullptr;
  TuiLayout layout;
};

TuiScreen::TuiScreen() {
  // A short escape delay makes Esc (an emergency stop) act at once.
  set_escdelay(25);
  // The terminal's own character set draws the borders (UTF-8 line drawing).
  std::setlocale(LC_ALL, "");
  initscr();
  raw();  // Ctrl-C and Ctrl-Q arrive as keys; Ctrl-Z cannot suspend a moving car's controller
  noecho();
  nonl();
  keypad(stdscr, TRUE);
  nodelay(stdscr, TRUE);
  curs_set(0);
  colors_ = has_colors();
  if (colors_) {
    start_color();
    use_default_colors();
    init_pair(kBanner, COLOR_WHITE, COLOR_RED);
    init_pair(kWarning, COLOR_YELLOW, -1);
    init_pair(kGood, COLOR_GREEN, -1);
    init_pair(kAlert, COLOR_RED, -1);
    init_pair(kTitle, COLOR_CYAN, -1);
  }
  getmaxyx(stdscr, rows_, columns_);
}

TuiScreen::~TuiScreen() {
  destroy_windows();
  endwin();
}

void TuiScreen::destroy_windows() {
  if (windows_ == nullptr) return;
  for (WINDOW* w : {windows_->header, windows_->banner, windows_->status, windows_->controls,
                    windows_->log, windows_->message, windows_->help})
    if (w != nullptr) delwin(w);
  delete windows_;
  windows_ = nullptr;
}

std::optional<int> TuiScreen::read_key() {
  const int ch = getch();
  if (ch == ERR) return std::nullopt;
  if (ch == KEY_RESIZE) {
    resize();
    return std::nullopt;
  }
  return to_model_key(ch);
}

void TuiScreen::resize() {
  winsize size{};
  if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_row > 0 && size.ws_col > 0)
    resizeterm(size.ws_row, size.ws_col);
  getmaxyx(stdscr, rows_, columns_);
  destroy_windows();
  clear();
  wnoutrefresh(stdscr);
}

void TuiScreen::draw(const TuiModel& model, Time now) {
  getmaxyx(stdscr, rows_, columns_);
  const Render shape = model.render(now, 0);
  const TuiLayout layout = layout_screen(rows_, columns_, shape);
  const Render r = model.render(now, layout.log_rows());

  auto same = [](const TuiLayout::Box& a, const TuiLayout::Box& b) {
    return a.top == b.top && a.left == b.left && a.height == b.height && a.width == b.width;
  };
  const bool relayout =
      windows_ == nullptr || !same(windows_->layout.banner, layout.banner) ||
      !same(windows_->layout.status, layout.status) || !same(windows_->layout.log, layout.log) ||
      !same(windows_->layout.help, layout.help) || !same(windows_->layout.header, layout.header);
  if (relayout) {
    destroy_windows();
    erase();
    wnoutrefresh(stdscr);
    windows_ = new Windows;
    windows_->layout = layout;
    auto make = [&](const TuiLayout::Box& b) -> WINDOW* {
      if (b.height <= 0 || b.width <= 0 || b.top + b.height > rows_ || b.left + b.width > columns_)
        return nullptr;
      return newwin(b.height, b.width, b.top, b.left);
    };
    windows_->header = make(layout.header);
    windows_->banner = make(layout.banner);
    windows_->status = make(layout.status);
    windows_->controls = make(layout.controls);
    windows_->log = make(layout.log);
    windows_->message = make(layout.message);
    windows_->help = make(layout.help);
  }
  Windows& w = *windows_;

  if (w.header != nullptr) {
    werase(w.header);
    put(w.header, 0, 0, r.header.text,
        attributes(r.header.style, colors_) | static_cast<int>(A_BOLD));
    const std::string name = "logi-client";
    const int x = columns_ - static_cast<int>(name.size()) - 1;
    if (x > static_cast<int>(r.header.text.size()) + 2) put(w.header, 0, x, name, A_DIM);
    wnoutrefresh(w.header);
  }
  if (w.banner != nullptr && r.stale) {
    const int attr = colors_ ? static_cast<int>(COLOR_PAIR(kBanner) | A_BOLD)
                             : static_cast<int>(A_REVERSE | A_BOLD);
    wbkgd(w.banner, static_cast<chtype>(attr));
    werase(w.banner);
    const std::string text = "!!! " + *r.stale + " !!!";
    const int height = getmaxy(w.banner);
    const int x = std::max(0, (columns_ - static_cast<int>(text.size())) / 2);
    put(w.banner, height / 2, x, text, attr);
    wnoutrefresh(w.banner);
  }
  draw_panel(w.status, r.status, colors_);
  draw_panel(w.controls, r.controls, colors_);
  draw_panel(w.log, r.log, colors_);
  if (w.message != nullptr) {
    werase(w.message);
    if (r.edit) {
      put(w.message, 0, 0, "> " + *r.edit, A_BOLD | A_REVERSE);
    } else {
      put(w.message, 0, 0, r.message.text, attributes(r.message.style, colors_));
    }
    wnoutrefresh(w.message);
  }
  if (w.help != nullptr) {
    werase(w.help);
    const int lines = getmaxy(w.help);
    for (int i = 0; i < lines && i < static_cast<int>(r.help.size()); ++i)
      put(w.help, i, 0, r.help[static_cast<std::size_t>(i)], A_DIM);
    wnoutrefresh(w.help);
  }
  doupdate();
}

}  // namespace hil::apps::logi_client
