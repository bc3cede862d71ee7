#include "apps/logi-client/stdin_actions.hpp"

#include <algorithm>
#include <array>
#include <deque>
#include <memory>
#include <ostream>
#include <utility>
#include <vector>

#include "apps/common/stdin_lines.hpp"
#include "apps/logi-client/actions_program.hpp"
#include "client/common/operator_text.hpp"
#include "client/logi/session.hpp"

namespace hil::apps::logi_client {

namespace proto = hil::protocol::logi;
using logi::ConnectionState;

namespace {

/// One event is one line, whatever the text holds.
std::string one_line(std::string text) {
  for (char& ch : text)
    if (ch == '\n' || ch == '\r') ch = ' ';
  return text;
}

}  // namespace

std::optional<std::string> contract_event_line(const logi::Event& event) {
  if (const auto* c = std::get_if<logi::ConnectionEvent>(&event)) {
    // LOGI never reaches authenticating, degraded or down.
    constexpr std::array kLogiStates = {ConnectionState::disconnected, ConnectionState::connecting,
                                        ConnectionState::connected, ConnectionState::reconnecting};
    if (std::find(kLogiStates.begin(), kLogiStates.end(), c->state) == kLogiStates.end())
      return std::nullopt;
    return "event connection " + std::string(client::to_string(c->state));
  }
  if (const auto* c = std::get_if<logi::CommandEvent>(&event)) {
    return "event command " + proto::kind_of(c->command) + " " +
           std::string(logi::to_string(c->state));
  }
  if (const auto* s = std::get_if<logi::StaleEvent>(&event)) {
    return s->stale ? "event stale" : "event fresh";
  }
  if (const auto* n = std::get_if<logi::NoticeEvent>(&event)) {
    return "event notice " + one_line(n->text);
  }
  if (const auto* p = std::get_if<logi::ParseErrorEvent>(&event)) {
    std::string text(protocol::to_string(p->error.kind));
    if (!p->error.detail.empty()) text += ": " + p->error.detail;
    return "event parse_error " + one_line(text);
  }
  if (const auto* m = std::get_if<logi::MovementEvent>(&event)) {
    std::string line = m->enabled ? "event movement enabled" : "event movement disabled";
    if (!m->reason.empty()) line += " " + one_line(m->reason);
    return line;
  }
  return std::nullopt;
}

ActionLine parse_action_line(int number, std::string_view line) {
  ActionLine out;
  out.text = std::string(client::trim(line.substr(0, line.find('#')), " \t\r\v\f"));
  const auto parsed = logi::parse_operator_action(line);
  if (parsed.error) {
    if (out.text.empty()) out.text = std::string(client::trim(line, " \t\r\v\f"));
    out.error = "column " + std::to_string(parsed.error->column) + ": " + parsed.error->message;
    return out;
  }
  if (parsed.action) out.step = logi::OperatorStep{number, out.text, *parsed.action};
  return out;
}

namespace {

/// The run of stdin's lines, one run of the action host per action; the
/// run ends after the last line of ended input.
class StdinActionsRun final : public ActionsProgram {
 public:
  StdinActionsRun(const BatchOptions& options, std::ostream& out, std::ostream& err)
      : ActionsProgram(options, out, err),
        input_(program_.io(), StdinLines::Handlers{
                                  [this](std::string line) { on_line(std::move(line)); },
                                  [this](std::string rest) { on_input_end(std::move(rest)); },
                                  [this] { return !stopping(); },
                              }) {}

 private:
  /// A line of stdin waiting its turn.
  struct Line {
    ActionLine parsed;
    /// An emergency stop started at once: its result line once it ended.
    std::shared_ptr<std::optional<std::string>> early_result;
  };

  void begin() override { input_.start(); }
  void after_loop() override { input_.stop(); }

  void on_line(std::string line) {
    Line entry;
    entry.parsed = parse_action_line(++line_number_, line);
    if (entry.parsed.step &&
        std::holds_alternative<logi::op::EmergencyStop>(entry.parsed.step->action) &&
        (busy_ || !pending_.empty()) && !stopping()) {
      // An emergency stop never waits for the actions before it; only its
      // result line does, so that results still come in the order of the
      // lines.
      entry.early_result = std::make_shared<std::optional<std::string>>();
      start_early(*entry.parsed.step, entry.early_result);
    }
    pending_.push_back(std::move(entry));
    schedule_next();
  }

  void on_input_end(std::string rest) {
    if (!rest.empty()) on_line(std::move(rest));
    input_ended_ = true;
    schedule_next();
  }

  void schedule_next() {
    if (busy_ || next_posted_ || stopping()) return;
    next_posted_ = true;
    program_.executor().post([this] {
      next_posted_ = false;
      run_next();
    });
  }

  static logi::ActionResult failure(const ActionLine& line, std::string reason, logi::Time now) {
    logi::ActionResult failed;
    failed.line = line.step ? line.step->line : 0;
    failed.text = line.text;
    failed.reason = std::move(reason);
    failed.started = failed.ended = now;
    return failed;
  }

  /// The result line of a line that did not run to its end.
  std::string unfinished(const ActionLine& line, const std::string& reason) {
    return BatchReporter::result_line(failure(line, reason, time_now()));
  }

  /// Starts the next action; answers the lines that do not parse, and the
  /// emergency stops that already ran, on the way; after the last line of
  /// ended input, shuts down.
  void run_next() {
    if (busy_ || stopping()) return;
    while (!pending_.empty()) {
      Line& front = pending_.front();
      if (front.early_result) {
        if (!*front.early_result) return;  // still under way: its result comes when it ends
        print(**front.early_result);
        pending_.pop_front();
        continue;
      }
      if (!front.parsed.error.empty()) {
        print(unfinished(front.parsed, front.parsed.error));
        pending_.pop_front();
        continue;
      }
      if (!front.parsed.step) {  // blank or comment: not an action, no result
        pending_.pop_front();
        continue;
      }
      logi::OperatorStep step = std::move(*front.parsed.step);
      pending_.pop_front();
      start(std::move(step));
      return;
    }
    // Only early emergency stops can be under way here.
    if (input_ended_ && actions_->runs() == 0) shut_down(kExitOk, true);
  }

  void start(logi::OperatorStep step) {
    busy_ = true;
    std::vector<logi::OperatorStep> steps;
    steps.push_back(std::move(step));
    actions_->run(
        std::move(steps), options_.runner,
        [this](const logi::ActionResult& r) { print(BatchReporter::result_line(r)); },
        [this](const logi::RunSummary&, const auto&) {
          if (stopping()) return;
          busy_ = false;
          run_next();
        });
  }

  void start_early(const logi::OperatorStep& step,
                   std::shared_ptr<std::optional<std::string>> result) {
    actions_->run(
        {step}, options_.runner,
        [result](const logi::ActionResult& r) { *result = BatchReporter::result_line(r); },
        [this](const logi::RunSummary&, const auto&) {
          if (!stopping()) run_next();
        });
  }

  void event_lines(const logi::Event& e) override {
    if (auto line = contract_event_line(e)) print(*line);
  }

  /// The action under way and the lines not begun (only when interrupted)
  /// fail as cancelled.
  void abandon() override {
    input_.stop();
    // Reports the action under way as cancelled, and fills in the results
    // of the emergency stops under way.
    actions_->cancel();
    // Lines received but not begun are answered too: one result per line.
    for (; !pending_.empty(); pending_.pop_front()) {
      const Line& line = pending_.front();
      if (line.early_result) {
        print(*line.early_result ? **line.early_result : unfinished(line.parsed, "cancelled"));
        continue;
      }
      if (!line.parsed.step && line.parsed.error.empty()) continue;
      print(unfinished(line.parsed, line.parsed.error.empty() ? "cancelled" : line.parsed.error));
    }
  }

  StdinLines input_;
  std::deque<Line> pending_;
  int line_number_ = 0;
  bool busy_ = false;
  bool next_posted_ = false;
  bool input_ended_ = false;
};

}  // namespace

int run_stdin_actions(const BatchOptions& options, std::ostream& out, std::ostream& err) {
  StdinActionsRun run(options, out, err);
  return run.run();
}

}  // namespace hil::apps::logi_client
