#include "apps/logi-client/stdin_actions.hpp"

#include <asio/io_context.hpp>

#include <csignal>
#include <deque>
#include <map>
#include <memory>
#include <ostream>
#include <utility>
#include <vector>

#include "apps/common/stdin_lines.hpp"
#include "client/common/operator_text.hpp"
#include "client/logi/session.hpp"
#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

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
    switch (c->state) {
      case ConnectionState::disconnected:
        return "event connection disconnected";
      case ConnectionState::connecting:
        return "event connection connecting";
      case ConnectionState::connected:
        return "event connection connected";
      case ConnectionState::waiting_to_reconnect:
        return "event connection reconnecting";
    }
    return std::nullopt;
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

/// Whether the car may be moving, for the stop at the end: it may after the
/// car accepted a move or a run (or left one unanswered) until a stop was
/// accepted, the link went down, or a STAT that had shown it moving shows it
/// at rest; and whenever the last STAT shows it moving. A move the car
/// refused does not count, though the direction stays held in the client.
class MotionTracker {
 public:
  void on_event(const logi::Event& e) {
    if (const auto* c = std::get_if<logi::CommandEvent>(&e)) {
      const bool ended_ok = c->state == logi::CommandState::accepted;
      const bool maybe = ended_ok || c->state == logi::CommandState::uncertain;
      if (const auto* m = std::get_if<proto::Move>(&c->command)) {
        if (m->direction != proto::Direction::stop && maybe) commanded_ = true;
        if (m->direction == proto::Direction::stop && ended_ok) commanded_ = false;
      } else if (const auto* r = std::get_if<proto::SetRun>(&c->command)) {
        if (r->run && maybe) commanded_ = true;
        if (!r->run && ended_ok) commanded_ = false;
      }
    } else if (const auto* s = std::get_if<logi::StatusEvent>(&e)) {
      const bool moving = s->status.running || s->status.manual != proto::Direction::stop;
      if (moving) {
        seen_moving_ = true;
      } else if (seen_moving_) {
        seen_moving_ = false;
        commanded_ = false;  // it moved and has stopped (an arrival, say)
      }
    } else if (const auto* conn = std::get_if<logi::ConnectionEvent>(&e)) {
      if (conn->state != ConnectionState::connected) commanded_ = seen_moving_ = false;
    }
  }

  bool may_be_moving(const logi::LogiClientCore& core) const {
    const auto& s = core.last_status();
    return commanded_ || (s && (s->running || s->manual != proto::Direction::stop));
  }

 private:
  bool commanded_ = false;
  bool seen_moving_ = false;
};

/// The program's run: stdin lines in, one runner per action, the session,
/// signals, and the way out.
class StdinActionsRun {
 public:
  StdinActionsRun(const BatchOptions& options, std::ostream& out, std::ostream& err)
      : options_(options),
        out_(out),
        err_(err),
        signals_(io_),
        input_(io_, StdinLines::Handlers{
                        [this](std::string line) { on_line(std::move(line)); },
                        [this](std::string rest) { on_input_end(std::move(rest)); },
                        [this] { return !stopping_; },
                    }) {
    logi::ClientConfig config;
    config.keepalive = options.keepalive;
    session_ = std::make_unique<logi::LogiSession>(
        context_, link::TcpEndpoint{options.host, options.port}, config,
        [this](logi::Time now, const logi::Event& e) { on_event(now, e); });
  }

  int run() {
    signals_.on_next([this](int signal) { on_signal(signal); });
    input_.start();
    io_.run();
    input_.stop();
    if (!options_.log_path.empty()) {
      std::string error;
      if (!write_log(*session_->log(), options_.log_path, error)) {
        err_ << "logi-client: " << error << '\n';
      }
    }
    out_.flush();
    return exit_code_;
  }

 private:
  // Every line is flushed at once: a program on the other end of a pipe
  // (hil) waits for it.
  void print(const std::string& line) { out_ << line << std::endl; }

  void on_line(std::string line) {
    Line entry;
    entry.parsed = parse_action_line(++line_number_, line);
    if (entry.parsed.step &&
        std::holds_alternative<logi::op::EmergencyStop>(entry.parsed.step->action) &&
        (busy_ || !pending_.empty()) && !stopping_) {
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
    if (busy_ || next_posted_ || stopping_) return;
    next_posted_ = true;
    executor_.post([this] {
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

  /// Starts the next action; answers the lines that do not parse, and the
  /// emergency stops that already ran, on the way; after the last line of
  /// ended input, shuts down.
  void run_next() {
    if (busy_ || stopping_) return;
    while (!pending_.empty()) {
      Line& front = pending_.front();
      if (front.early_result) {
        if (!*front.early_result) return;  // still under way: its result comes when it ends
        print(**front.early_result);
        pending_.pop_front();
        continue;
      }
      if (!front.parsed.error.empty()) {
        print(
            BatchReporter::result_line(failure(front.parsed, front.parsed.error, executor_.now())));
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
    if (input_ended_ && early_.empty()) shut_down(kExitOk, true);
  }

  /// Runner options for one action: `confirm` learns which request went
  /// unanswered before it (each action has a runner of its own).
  logi::OperatorRunnerOptions runner_options(const logi::OperatorStep& step) {
    auto options = options_.runner;
    if (std::holds_alternative<logi::op::Confirm>(step.action)) {
      options.confirmable = confirmable_;
      confirmable_.reset();
    }
    return options;
  }

  void start(logi::OperatorStep step) {
    busy_ = true;
    auto options = runner_options(step);
    std::vector<logi::OperatorStep> steps;
    steps.push_back(std::move(step));
    runner_ = std::make_unique<logi::OperatorRunner>(
        *session_, executor_, std::move(steps), options,
        [this](const logi::ActionResult& r) { print(BatchReporter::result_line(r)); },
        [this](const logi::RunSummary&) {
          // Leave the runner's callback before it is destroyed.
          executor_.post([this] {
            if (stopping_) return;
            runner_.reset();
            busy_ = false;
            run_next();
          });
        });
    runner_->start();
  }

  void start_early(const logi::OperatorStep& step,
                   std::shared_ptr<std::optional<std::string>> result) {
    const std::uint64_t id = ++early_ids_;
    auto runner = std::make_unique<logi::OperatorRunner>(
        *session_, executor_, std::vector<logi::OperatorStep>{step}, options_.runner,
        [result](const logi::ActionResult& r) { *result = BatchReporter::result_line(r); },
        [this, id](const logi::RunSummary&) {
          executor_.post([this, id] {
            early_.erase(id);
            if (!stopping_) run_next();
          });
        });
    auto* started = runner.get();
    early_.emplace(id, std::move(runner));
    started->start();
  }

  void on_event(logi::Time now, const logi::Event& e) {
    if (auto line = reporter_.event_line(now, e)) print(*line);
    if (auto line = contract_event_line(e)) print(*line);
    if (const auto* c = std::get_if<logi::CommandEvent>(&e)) {
      if (c->state == logi::CommandState::uncertain && c->resend_on_confirm) {
        confirmable_ = c->request;
      }
    } else if (const auto* conn = std::get_if<logi::ConnectionEvent>(&e)) {
      if (conn->state != ConnectionState::connected) confirmable_.reset();
    }
    motion_.on_event(e);
    if (runner_) runner_->on_event(now, e);
    for (auto& [id, runner] : early_)
      runner->on_event(now, e);
  }

  void on_signal(int signal) {
    if (stopping_) {
      // A signal while shutting down: out now, without waiting for the car.
      print(stamp(executor_.now()) + " interrupted again: leaving at once");
      exit_code_ = kExitInterrupted;
      io_.stop();
      return;
    }
    print(stamp(executor_.now()) + " interrupted (" + (signal == SIGTERM ? "SIGTERM" : "SIGINT") +
          "): stopping");
    signals_.on_next([this](int s) { on_signal(s); });
    shut_down(kExitInterrupted, true);
  }

  /// Ends the run: the action under way and the lines not begun (only
  /// when interrupted) fail as cancelled; an emergency stop if asked and
  /// the car may be moving; then disconnect and leave the io_context.
  void shut_down(int code, bool stop_car) {
    if (stopping_) return;
    stopping_ = true;
    exit_code_ = code;
    input_.stop();
    if (runner_) runner_->cancel();  // reports the action under way as cancelled
    for (auto& [id, runner] : early_)
      runner->cancel();  // fills in their results
    // Lines received but not begun are answered too: one result per line.
    for (; !pending_.empty(); pending_.pop_front()) {
      const Line& line = pending_.front();
      if (line.early_result) {
        print(*line.early_result
                  ? **line.early_result
                  : BatchReporter::result_line(failure(line.parsed, "cancelled", executor_.now())));
        continue;
      }
      if (!line.parsed.step && line.parsed.error.empty()) continue;
      print(BatchReporter::result_line(
          failure(line.parsed, line.parsed.error.empty() ? "cancelled" : line.parsed.error,
                  executor_.now())));
    }
    const bool connected = session_->core().state() == ConnectionState::connected;
    stop_car_then(
        *session_, executor_, stop_car && connected && motion_.may_be_moving(session_->core()),
        [this](const std::string& line) { print(line); }, [this] { finish(); });
  }

  void finish() {
    session_->disconnect();
    signals_.cancel();
    executor_.post([this] { io_.stop(); });
  }

  const BatchOptions& options_;
  std::ostream& out_;
  std::ostream& err_;
  asio::io_context io_;
  link::AsioExecutor executor_{io_};
  link::TransportContext context_{executor_, &io_};
  StopSignals signals_;
  StdinLines input_;
  std::unique_ptr<logi::LogiSession> session_;
  std::unique_ptr<logi::OperatorRunner> runner_;
  BatchReporter reporter_;
  /// A line of stdin waiting its turn.
  struct Line {
    ActionLine parsed;
    /// An emergency stop started at once: its result line once it ended.
    std::shared_ptr<std::optional<std::string>> early_result;
  };
  std::deque<Line> pending_;
  std::map<std::uint64_t, std::unique_ptr<logi::OperatorRunner>> early_;
  std::uint64_t early_ids_ = 0;
  std::optional<logi::RequestId> confirmable_;
  MotionTracker motion_;
  int line_number_ = 0;
  bool busy_ = false;
  bool next_posted_ = false;
  bool input_ended_ = false;
  bool stopping_ = false;
  int exit_code_ = kExitOk;
};

}  // namespace

int run_stdin_actions(const BatchOptions& options, std::ostream& out, std::ostream& err) {
  StdinActionsRun run(options, out, err);
  return run.run();
}

}  // namespace hil::apps::logi_client
