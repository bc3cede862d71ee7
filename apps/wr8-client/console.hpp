#pragma once
// What wr8-client does with actions, lines and session events, apart from
// any I/O loop: batch runs, the interactive command loop, the printed
// lines, log saving and the exit code (docs/clients/wr8-client.md). One
// console serves both dialects' clients; a kit says what differs.

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "apps/common/program.hpp"
#include "client/wr8/operator.hpp"
#include "client/wr8/svgui_operator.hpp"

namespace hil::apps::wr8_client {

namespace wr8 = client::wr8;

using apps::kExitFailed;
using apps::kExitInterrupted;
using apps::kExitOk;
using apps::kExitUsage;

struct ConsoleOptions {
  bool interactive = false;
  bool prompt = false;      ///< print "wr8> " (stdin is a terminal)
  bool print_data = false;  ///< batch: print DATA (on change, else once a second)
  bool keep_going = false;  ///< batch: run every action after a failure (exit 1 at the end)
  std::string log_path;     ///< written at exit when not empty
};

/// The live state as the `state` command prints it (several lines).
std::string format_state(const wr8::Wr8ClientCore& core, link::Time now);
/// One DATA as a line: "STOP odo 12 cm  speed 0.00 m/s  angle 0.0 deg  battery 100 %".
std::string format_live(const wr8::LiveState& live);

/// The interactive-mode command words both dialects share, for help.
extern const std::string_view kConsoleCommands;
/// What a connection change prints interactively, if anything.
std::optional<std::string> connection_text(const wr8::ConnectionEvent& e);
/// "timed_out" -> "timed out".
std::string underscores_to_spaces(std::string_view s);

/// What `--data` prints of one DATA packet: the stream it belongs to (each
/// is printed on its own once-a-second schedule), its state code (a change
/// prints at once; -1 for a stream without one), and the line.
struct DataLine {
  int stream = 0;
  int state = -1;
  std::string text;
};

/// One dialect's client as the console drives it. What a dialect prints
/// is in overloads on its Session (parse_line, action_text, state_text,
/// event_text, data_line, help_text): the document's in console.cpp, the
/// real programs' below.
template <class SessionT, class RunnerT, class ActionT, class EventT, class ResultT>
struct ConsoleKit {
  using Session = SessionT;
  using Runner = RunnerT;
  using Action = ActionT;
  using Event = EventT;
  using Result = ResultT;
};
using DocumentKit = ConsoleKit<wr8::Wr8Session, wr8::OperatorRunner, wr8::OperatorAction,
                               wr8::Event, wr8::ActionResult>;
using SvguiKit = ConsoleKit<wr8::SvguiSession, wr8::SvguiRunner, wr8::SvguiAction, wr8::SvguiEvent,
                            wr8::SvguiActionResult>;

// ---- what the real programs' dialects print (svgui_console.cpp) ----

/// The state command's text for a real program's vehicle.
std::string format_svgui_state(const wr8::SvguiClientCore& core, link::Time now);
/// A typed line as an action of the session's profile.
wr8::ParsedSvguiLine parse_line(const wr8::SvguiSession& session, std::string_view line);
/// An action as the history and the result lines show it.
std::string action_text(const wr8::SvguiSession& session, const wr8::SvguiAction& action);
/// The `state` command's text.
std::string state_text(const wr8::SvguiSession& session, link::Time now);
/// The interactive line an event prints (without its time), if any.
std::optional<std::string> event_text(const wr8::SvguiSession& session,
                                      const wr8::SvguiEvent& event);
/// What `--data` prints of an event, if it is a DATA packet.
std::optional<DataLine> data_line(const wr8::SvguiEvent& event);
/// The `help` command's text.
std::string help_text(const wr8::SvguiSession& session);

/// wr8-client's console over one dialect's session and runner.
template <class Kit>
class BasicConsole {
 public:
  using Exit = std::function<void(int code)>;
  using Session = typename Kit::Session;
  using Runner = typename Kit::Runner;
  using Action = typename Kit::Action;

  BasicConsole(link::Executor& executor, Session& session, Runner& runner, std::ostream& out,
               ConsoleOptions options, Exit exit);

  /// Every session event, after the runner has seen it.
  void on_event(link::Time now, const typename Kit::Event& event);

  /// Batch: runs the actions in order, stops at the first failure, exits.
  void run_batch(std::vector<Action> actions);

  /// Interactive: the first prompt.
  void start();
  /// Interactive: one line typed or piped in; runs after what came before.
  void line(std::string text);
  /// Interactive: no more input; exits 0 once the queued lines have run.
  void end_of_input();
  /// SIGINT / SIGTERM: disconnects and exits 130.
  void interrupt();

  bool exited() const { return exited_; }

 private:
  struct Printed {
    link::Time at{0};
    int state = -1;
  };

  void process();
  bool builtin(const std::string& text);
  void result(const typename Kit::Result& r);
  void print(const std::string& text);
  void prompt();
  void exit(int code);
  std::string stamp(link::Time t) const;

  link::Executor& executor_;
  Session& session_;
  Runner& runner_;
  std::ostream& out_;
  ConsoleOptions options_;
  Exit exit_;
  bool exited_ = false;

  std::deque<std::string> pending_;
  bool input_ended_ = false;
  bool prompted_ = false;
  bool running_ = false;  // an action of ours is under way (until its result is printed)
  std::vector<std::string> history_;  // the actions run, with their results

  // --data: the last line printed of each stream.
  std::map<int, Printed> data_printed_;
};

using Wr8Console = BasicConsole<DocumentKit>;
using SvguiConsole = BasicConsole<SvguiKit>;

extern template class BasicConsole<DocumentKit>;
extern template class BasicConsole<SvguiKit>;

}  // namespace hil::apps::wr8_client
