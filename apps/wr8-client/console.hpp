#pragma once
// What wr8-client does with actions, lines and session events, apart from
// any I/O loop: batch runs, the interactive command loop, the printed
// lines, log saving and the exit code (docs/clients/wr8-client.md).

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "apps/common/program.hpp"
#include "client/wr8/operator.hpp"

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

class Wr8Console {
 public:
  using Exit = std::function<void(int code)>;

  Wr8Console(link::Executor& executor, wr8::Wr8Session& session, wr8::OperatorRunner& runner,
             std::ostream& out, ConsoleOptions options, Exit exit);

  /// Every session event, after the runner has seen it.
  void on_event(link::Time now, const wr8::Event& event);

  /// Batch: runs the actions in order, stops at the first failure, exits.
  void run_batch(std::vector<wr8::OperatorAction> actions);

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
  void process();
  bool builtin(const std::string& text);
  void result(const wr8::ActionResult& r);
  void print(const std::string& text);
  void prompt();
  void exit(int code);
  std::string stamp(link::Time t) const;

  link::Executor& executor_;
  wr8::Wr8Session& session_;
  wr8::OperatorRunner& runner_;
  std::ostream& out_;
  ConsoleOptions options_;
  Exit exit_;
  bool exited_ = false;

  std::deque<std::string> pending_;
  bool input_ended_ = false;
  bool prompted_ = false;
  bool running_ = false;  // an action of ours is under way (until its result is printed)
  std::vector<std::string> history_;  // the actions run, with their results

  // --data: the last DATA printed.
  std::optional<link::Time> data_printed_at_;
  std::optional<wr8::proto::State> data_printed_state_;
};

}  // namespace hil::apps::wr8_client
