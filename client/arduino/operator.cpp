#include "client/arduino/operator.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <utility>

#include "client/common/operator_text.hpp"

namespace hil::client::arduino {

namespace proto = protocol::arduino;

namespace {

// A day is far beyond any robot script.
std::optional<Duration> parse_wait(std::string_view text) {
  return parse_duration(text, link::seconds(86400));
}

const char* kExpected =
    "PING, STATUS, V, M, R, S, B, I, HELP, history, save-log, reconnect, wait or quit";

OperatorLine error_at(std::size_t column, std::string message) {
  OperatorLine out;
  out.error = OperatorParseError{column, std::move(message)};
  return out;
}

OperatorLine command_line(OperatorCommand command) {
  OperatorLine out;
  out.action = std::move(command);
  return out;
}

}  // namespace

std::string to_text(const OperatorCommand& command) {
  return std::visit(
      [](const auto& c) -> std::string {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, RobotRequest>) {
          if (c.raw) return *c.raw;
          std::string word(proto::command_of(c.body));
          if (auto* v = std::get_if<proto::SetSpeed>(&c.body))
            return word + " " + std::to_string(v->pwm);
          if (auto* m = std::get_if<proto::Move>(&c.body))
            return word + " " + std::to_string(m->distance_cm);
          if (auto* r = std::get_if<proto::Rotate>(&c.body))
            return word + " " + std::to_string(r->angle_deg);
          return word;
        } else if constexpr (std::is_same_v<T, WaitCommand>) {
          return "wait " + duration_text(c.duration);
        } else if constexpr (std::is_same_v<T, HistoryCommand>) {
          return "history";
        } else if constexpr (std::is_same_v<T, SaveLogCommand>) {
          return "save-log " + c.path;
        } else if constexpr (std::is_same_v<T, ReconnectCommand>) {
          return "reconnect";
        } else {
          return "quit";
        }
      },
      command);
}

namespace {
OperatorLine parse_typed_line(std::string_view line, const std::vector<Word>& words);
}  // namespace

OperatorLine parse_operator_line(std::string_view line) {
  if (const auto hash = line.find('#'); hash != std::string_view::npos) {
    line = line.substr(0, hash);
  }
  const auto words = split_words(line).words;
  if (words.empty()) return {};
  OperatorLine typed = parse_typed_line(line, words);
  // One word in the raw form CMD:PAYLOAD that hil would not type goes to
  // the robot as given, as the robot's own CLI sends it ("V:999" is the
  // board's NACK BAD_V to report, not a usage error).
  const std::string_view token = words.front().text;
  if (typed.error && words.size() == 1 && token.find(':') != std::string_view::npos &&
      token.front() != ':' &&
      std::all_of(token.begin(), token.end(), [](char c) { return proto::is_field_char(c); })) {
    return command_line(RobotRequest{proto::Ping{}, std::string(token)});
  }
  return typed;
}

namespace {
OperatorLine parse_typed_line(std::string_view line, const std::vector<Word>& words) {
  // "V:160" is the seed CLI's raw form of "V 160".
  Word head = words.front();
  std::optional<Word> glued;
  if (const auto colon = head.text.find(':'); colon != std::string_view::npos) {
    glued = Word{head.text.substr(colon + 1), head.column + colon + 1};
    head.text = head.text.substr(0, colon);
  }
  std::vector<Word> args;
  if (glued) args.push_back(*glued);
  args.insert(args.end(), words.begin() + 1, words.end());
  const std::size_t line_end = line.find_last_not_of(" \t\r\n") + 2;
  const std::string word = to_lower(head.text);

  auto no_args = [&](std::string_view name, OperatorCommand command) -> OperatorLine {
    // "PING:" is the raw form with its empty payload.
    if (glued && glued->text.empty()) args.erase(args.begin());
    if (!args.empty()) {
      return error_at(args.front().column, std::string(name) + " takes no argument, got '" +
                                               std::string(args.front().text) + "'");
    }
    return command_line(std::move(command));
  };
  // V, M and R take exactly one whole number within [lo, hi].
  auto one_number = [&](char letter, long long lo, long long hi, const std::string& what,
                        auto make) -> OperatorLine {
    const std::string need = std::string(1, letter) + " needs " + what;
    if (args.empty() || args.front().text.empty()) {
      return error_at(args.empty() ? line_end : args.front().column, need);
    }
    const auto value = parse_integer(args.front().text, lo, hi);
    if (!value) {
      return error_at(args.front().column, need + ", not '" + std::string(args.front().text) + "'");
    }
    if (args.size() > 1) {
      return error_at(args[1].column, "unexpected '" + std::string(args[1].text) + "' after " +
                                          std::string(1, letter) + " " +
                                          std::to_string(value.value));
    }
    return command_line(RobotRequest{make(static_cast<int>(value.value))});
  };

  if (word == "ping") return no_args("PING", RobotRequest{proto::Ping{}});
  if (word == "status") return no_args("STATUS", RobotRequest{proto::StatusRequest{}});
  if (word == "s") return no_args("S", RobotRequest{proto::Stop{}});
  if (word == "b") return no_args("B", RobotRequest{proto::SonarRead{}});
  if (word == "i") return no_args("I", RobotRequest{proto::IrRead{}});
  if (word == "help") return no_args("HELP", RobotRequest{proto::Help{}});
  if (word == "v") {
    return one_number('V', 0, 255, "a number 0..255",
                      [](int n) -> proto::Body { return proto::SetSpeed{n}; });
  }
  if (word == "m") {
    return one_number('M', -32768, 32767, "a distance in cm, a whole number -32768..32767",
                      [](int n) -> proto::Body { return proto::Move{n}; });
  }
  if (word == "r") {
    return one_number('R', -32768, 32767, "an angle in degrees, a whole number -32768..32767",
                      [](int n) -> proto::Body { return proto::Rotate{n}; });
  }
  if (glued) {
    return error_at(head.column, "a ':' goes only between V, M or R and its number");
  }
  if (word == "history") return no_args("history", HistoryCommand{});
  if (word == "reconnect") return no_args("reconnect", ReconnectCommand{});
  if (word == "quit" || word == "exit") return no_args(word, QuitCommand{});
  if (word == "save-log") {
    if (args.empty()) return error_at(line_end, "save-log needs a file path (.txt, .csv, .json)");
    // The path is the rest of the line, so it may contain spaces.
    const std::size_t from = args.front().column - 1;
    std::string path(line.substr(from, line_end - 1 - from));
    return command_line(SaveLogCommand{std::move(path)});
  }
  if (word == "wait") {
    const std::string need = "wait needs a duration such as 500ms or 1s";
    if (args.empty()) return error_at(line_end, need);
    const auto d = parse_wait(args.front().text);
    if (!d) {
      return error_at(args.front().column, need + ", not '" + std::string(args.front().text) + "'");
    }
    if (args.size() > 1) {
      return error_at(args[1].column, "unexpected '" + std::string(args[1].text) + "' after wait");
    }
    return command_line(WaitCommand{*d});
  }
  return error_at(head.column,
                  "unknown command '" + std::string(head.text) + "' (expected " + kExpected + ")");
}
}  // namespace

std::vector<OperatorCommand> Script::commands() const {
  std::vector<OperatorCommand> out;
  out.reserve(steps.size());
  for (const auto& s : steps)
    out.push_back(s.command);
  return out;
}

Script parse_script(std::string_view text, const std::string& file) {
  Script script;
  std::size_t number = 0;
  for (std::string_view line : split_lines(text)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    auto parsed = parse_operator_line(line);
    if (parsed.error) {
      script.errors.push_back({file, number, parsed.error->column, parsed.error->message});
    } else if (parsed.action) {
      script.steps.push_back({std::move(*parsed.action), number});
    }
  }
  return script;
}

Script load_script(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    Script script;
    script.errors.push_back({path, 0, 0, "cannot read the script"});
    return script;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parse_script(text.str(), path);
}

std::string describe_result(const Result& result) {
  switch (result.code) {
    case ResultCode::ok:
      return result.info.empty() ? "ACK" : "ACK " + result.info;
    case ResultCode::nack: {
      std::string code = "?";
      if (result.nack) {
        code = std::visit(
            [](const auto& e) -> std::string {
              if constexpr (std::is_same_v<std::decay_t<decltype(e)>, std::string>) {
                return e;
              } else {
                return std::string(proto::to_string(e));
              }
            },
            result.nack->error);
      }
      return "NACK " + code;
    }
    case ResultCode::timeout:
      return "TIMEOUT (no answer after " + std::to_string(result.attempts) + " attempt" +
             (result.attempts == 1 ? "" : "s") + ")";
    case ResultCode::link_down:
      return "LINK DOWN (" + result.detail + ")";
    case ResultCode::invalid_request:
      return "INVALID (" + result.detail + ")";
  }
  return "?";
}

std::string describe_outcome(const CommandOutcome& outcome) {
  if (std::holds_alternative<RobotRequest>(outcome.command)) {
    return to_text(outcome.command) + " -> " + outcome.text;
  }
  return outcome.text;
}

// ---- the runner ----

OperatorRunner::OperatorRunner(ArduinoSession& session, link::Executor& executor, Options options)
    : session_(session), executor_(executor), options_(options) {
  session_.set_event_handler([this, alive = alive_](const Event& e) {
    if (*alive) on_session_event(e);
  });
}

OperatorRunner::~OperatorRunner() {
  *alive_ = false;
  if (wait_timer_ != 0) executor_.cancel(wait_timer_);
  session_.set_event_handler({});
}

void OperatorRunner::add(OperatorCommand command) {
  if (halted_) return;
  queue_.push_back({next_index_++, std::move(command)});
  pump();
}

void OperatorRunner::add(const std::vector<OperatorCommand>& commands) {
  for (const auto& c : commands) {
    if (halted_) return;
    queue_.push_back({next_index_++, c});
  }
  pump();
}

void OperatorRunner::pump() {
  // A command may end inside start() (a refused request, a client command);
  // the loop then starts the next one instead of recursing.
  if (pumping_) return;
  pumping_ = true;
  while (!running_ && !halted_ && !queue_.empty()) {
    Queued next = std::move(queue_.front());
    queue_.pop_front();
    start(std::move(next));
  }
  pumping_ = false;
  if (idle() && on_idle_) on_idle_();
}

void OperatorRunner::start(Queued queued) {
  running_ = true;
  CommandOutcome outcome;
  outcome.index = queued.index;
  outcome.command = queued.command;
  outcome.started = executor_.now();
  current_ = outcome;

  if (auto* request = std::get_if<RobotRequest>(&queued.command)) {
    auto done_with = [this, alive = alive_](const Result& r) {
      if (!*alive || !current_) return;
      CommandOutcome done = std::move(*current_);
      done.ok = r.code == ResultCode::ok;
      done.result = r;
      done.text = describe_result(r);
      finish(std::move(done));
    };
    if (request->raw) {
      session_.raw(*request->raw, std::move(done_with));
    } else {
      session_.request(request->body, std::move(done_with));
    }
    return;
  }
  if (auto* wait = std::get_if<WaitCommand>(&queued.command)) {
    wait_timer_ = executor_.call_after(wait->duration, [this, alive = alive_] {
      if (!*alive) return;
      wait_timer_ = 0;
      finish(std::move(*current_));
    });
    return;
  }
  if (std::holds_alternative<HistoryCommand>(queued.command)) {
    std::string text = session_.log().to_string(LogFormat::txt);
    if (!text.empty() && text.back() == '\n') text.pop_back();
    if (text.empty()) text = "(no frames yet)";
    CommandOutcome done = std::move(*current_);
    done.text = std::move(text);
    finish(std::move(done));
    return;
  }
  if (auto* save = std::get_if<SaveLogCommand>(&queued.command)) {
    const auto format = log_format_for(save->path);
    const std::size_t frames = session_.log().size();
    CommandOutcome done = std::move(*current_);
    done.ok = session_.log().save(save->path, format);
    const char* name = format == LogFormat::csv      ? "csv"
                       : format == LogFormat::ndjson ? "ndjson"
                                                     : "txt";
    done.text = done.ok ? "saved " + std::to_string(frames) + " frame(s) to " + save->path + " (" +
                              name + ")"
                        : "cannot write " + save->path;
    finish(std::move(done));
    return;
  }
  if (std::holds_alternative<ReconnectCommand>(queued.command)) {
    awaiting_reconnect_ = true;
    session_.close();
    // The port stays closed as long as before an automatic reconnect, so the
    // board (and a pty or USB adapter) sees the hang-up and resets.
    wait_timer_ =
        executor_.call_after(session_.core().config().reconnect_base_delay, [this, alive = alive_] {
          if (!*alive) return;
          wait_timer_ = 0;
          session_.open();
          // The port may open (or fail) within open(); else a LinkChanged ends it.
          if (awaiting_reconnect_ && (session_.state() == ConnectionState::connected ||
                                      session_.state() == ConnectionState::down)) {
            finish_reconnect(session_.state() == ConnectionState::connected, "");
          }
        });
    return;
  }
  // quit
  quit_ = true;
  halted_ = true;
  finish(std::move(*current_));
}

void OperatorRunner::on_session_event(const Event& event) {
  if (awaiting_reconnect_ && current_) {
    if (auto* change = std::get_if<LinkChanged>(&event);
        change &&
        (change->to == ConnectionState::connected || change->to == ConnectionState::down)) {
      // The caller's handler sees the change before the outcome.
      if (on_event_) on_event_(event);
      finish_reconnect(change->to == ConnectionState::connected, change->reason);
      return;
    }
  }
  if (on_event_) on_event_(event);
}

void OperatorRunner::finish_reconnect(bool ok, const std::string& reason) {
  awaiting_reconnect_ = false;
  CommandOutcome done = std::move(*current_);
  done.ok = ok;
  done.text = ok ? "reconnected, link OPEN"
                 : "reconnect failed, link DOWN" + (reason.empty() ? "" : " (" + reason + ")");
  finish(std::move(done));
}

void OperatorRunner::finish(CommandOutcome outcome) {
  outcome.finished = executor_.now();
  current_.reset();
  running_ = false;
  ++completed_;
  if (!outcome.ok) {
    ++failures_;
    if (!options_.keep_going) halted_ = true;
  }
  if (halted_) queue_.clear();
  if (on_outcome_) on_outcome_(outcome);
  pump();
}

}  // namespace hil::client::arduino
