#include "apps/wr8-client/console.hpp"

#include <cstdio>
#include <utility>

#include "apps/common/log_file.hpp"
#include "client/common/operator_text.hpp"

namespace hil::apps::wr8_client {

namespace {

using client::Overloaded;

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string optional_value(const std::optional<double>& v, int decimals, std::string_view unit) {
  if (!v) return "-";
  return fixed(*v, decimals) + " " + std::string(unit);
}

std::string trim(std::string_view s) {
  return std::string(client::trim(s));
}

constexpr std::string_view kDocumentHelp =
    "actions (run in order; each waits for its answer):\n"
    "  connect                 open the connection and log in\n"
    "  disconnect              close the connection\n"
    "  drive CM                drive forward CM centimetres; waits for completed\n"
    "  turn DEG                turn the wheels to DEG degrees (+ left); waits for completed\n"
    "  task CODE [VALUE...]    any task (check, drive, turn, blink, get-settings or 0..4)\n"
    "  get-settings            read P, I, D and servo zero\n"
    "  set NAME=VALUE...       change settings (p, i, d, servo-zero)\n"
    "  wait DURATION           pause (500ms, 1s, 1.5s)\n"
    "  wait-data               wait for the next DATA packet\n"
    "(profile document; svgui-2019 and svgui-head have their own words)\n";

}  // namespace

const std::string_view kConsoleCommands =
    "commands:\n"
    "  state                   the live state from DATA\n"
    "  log [N]                 the last N (20) lines of the communication log\n"
    "  history                 the actions run so far and their results\n"
    "  save-log PATH           write the communication log (.txt, .csv or .ndjson)\n"
    "  help                    this text\n"
    "  quit                    disconnect and leave (end of input does the same)\n";

std::string underscores_to_spaces(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c == '_') c = ' ';
  return out;
}

std::optional<std::string> connection_text(const wr8::ConnectionEvent& e) {
  if (e.state == wr8::ConnectionState::reconnecting)
    return "connection lost; reconnecting (attempt " + std::to_string(e.attempt + 1) + ")";
  if (e.state == wr8::ConnectionState::connecting && e.attempt > 0)
    return "reconnect attempt " + std::to_string(e.attempt);
  return std::nullopt;
}

std::string format_live(const wr8::LiveState& live) {
  return std::string(wr8::proto::to_string(live.state)) + "  odometry " +
         optional_value(live.odometry_cm, 0, "cm") + "  speed " +
         optional_value(live.speed_mps, 2, "m/s") + "  wheel angle " +
         optional_value(live.wheel_angle_deg, 1, "deg") + "  battery " +
         optional_value(live.battery_percent, 0, "%");
}

std::string format_state(const wr8::Wr8ClientCore& core, link::Time now) {
  std::string out = "connection: " + underscores_to_spaces(wr8::to_string(core.state())) + "\n";
  const auto& live = core.live();
  if (!live) return out + "no DATA received yet\n";
  out += "vehicle:    " + std::string(wr8::proto::to_string(live->state)) + ", timestamp " +
         std::to_string(live->timestamp_ms) + " ms\n";
  out += "odometry:   " + optional_value(live->odometry_cm, 0, "cm") + "\n";
  out += "speed:      " + optional_value(live->speed_mps, 2, "m/s") + "\n";
  out += "wheels:     " + optional_value(live->wheel_angle_deg, 1, "deg") + "\n";
  out += "battery:    " + optional_value(live->battery_percent, 0, "%") + "\n";
  out += "data age:   " + fixed(link::to_ms(now - live->received), 0) + " ms" +
         (core.stale() ? " (stale)" : "") + "\n";
  return out;
}

// ---- the document dialect ----

wr8::ParsedLine parse_line(const wr8::Wr8Session& session, std::string_view line) {
  return wr8::parse_operator_line(line, session.core().config().profile);
}

std::string action_text(const wr8::Wr8Session& session, const wr8::OperatorAction& action) {
  return wr8::to_text(action, session.core().config().profile);
}

std::string state_text(const wr8::Wr8Session& session, link::Time now) {
  return format_state(session.core(), now);
}

std::string help_text(const wr8::Wr8Session&) {
  return std::string(kDocumentHelp) + std::string(kConsoleCommands);
}

std::optional<DataLine> data_line(const wr8::Event& event) {
  const auto* t = std::get_if<wr8::TelemetryEvent>(&event);
  if (t == nullptr) return std::nullopt;
  return DataLine{0, static_cast<int>(t->live.state), format_live(t->live)};
}

std::optional<std::string> event_text(const wr8::Wr8Session& session, const wr8::Event& event) {
  return std::visit(
      Overloaded{
          [&](const wr8::ConnectionEvent& e) -> std::optional<std::string> {
            return connection_text(e);
          },
          [&](const wr8::LoginFailedEvent& e) -> std::optional<std::string> {
            return "login failed: " + e.reason;
          },
          [&](const wr8::StaleEvent& e) -> std::optional<std::string> {
            return e.stale ? "DATA stale: none for " +
                                 client::duration_text(session.core().config().stale_after)
                           : std::string("DATA flowing again");
          },
          [&](const wr8::RequestEvent& e) -> std::optional<std::string> {
            if (e.state == wr8::RequestState::sent) return std::nullopt;
            const std::string what = e.kind == wr8::RequestKind::task
                                         ? "task " + std::string(wr8::proto::to_string(e.task))
                                         : std::string("settings");
            return what + " (COI " + std::to_string(e.coi) + ") " +
                   underscores_to_spaces(wr8::to_string(e.state));
          },
          [&](const wr8::IgnoredEvent& e) -> std::optional<std::string> {
            return "ignored (late or unknown COI): " +
                   wr8::proto::describe(e.message, session.core().config().profile);
          },
          [&](const wr8::ParseErrorEvent& e) -> std::optional<std::string> {
            return "bad bytes received: " + e.error.detail;
          },
          [](const auto&) -> std::optional<std::string> { return std::nullopt; },
      },
      event);
}

// ---- the console ----

template <class Kit>
BasicConsole<Kit>::BasicConsole(link::Executor& executor, Session& session, Runner& runner,
                                std::ostream& out, ConsoleOptions options, Exit exit)
    : executor_(executor),
      session_(session),
      runner_(runner),
      out_(out),
      options_(std::move(options)),
      exit_(std::move(exit)) {}

template <class Kit>
std::string BasicConsole<Kit>::stamp(link::Time t) const {
  return seconds_stamp(t, 8);
}

template <class Kit>
void BasicConsole<Kit>::print(const std::string& text) {
  if (prompted_) out_ << '\n';  // the prompt was waiting on its own line
  prompted_ = false;
  out_ << text << '\n' << std::flush;
}

template <class Kit>
void BasicConsole<Kit>::prompt() {
  if (!options_.prompt || exited_ || running_ || !pending_.empty() || prompted_) return;
  out_ << "wr8> " << std::flush;
  prompted_ = true;
}

template <class Kit>
void BasicConsole<Kit>::on_event(link::Time now, const typename Kit::Event& event) {
  if (exited_) return;
  if (!options_.interactive) {
    if (!options_.print_data) return;
    const auto line = data_line(event);
    if (!line) return;
    // On a change of state code, else at most once a second, per stream.
    auto it = data_printed_.find(line->stream);
    if (it != data_printed_.end() && it->second.state == line->state &&
        now - it->second.at < link::seconds(1))
      return;
    data_printed_[line->stream] = Printed{now, line->state};
    print(stamp(now) + "  data  " + line->text);
    return;
  }
  if (const auto text = event_text(session_, event)) print(stamp(now) + "  " + *text);
  prompt();
}

template <class Kit>
void BasicConsole<Kit>::result(const typename Kit::Result& r) {
  const std::string text = action_text(session_, r.action);
  char head[64];
  std::snprintf(head, sizeof head, "%-24s %-4s", text.c_str(), r.ok ? "ok" : "FAIL");
  std::string line = stamp(r.finished) + "  " + head;
  if (!r.detail.empty()) line += "  " + r.detail;
  history_.push_back(line);
  print(line);
}

template <class Kit>
void BasicConsole<Kit>::run_batch(std::vector<Action> actions) {
  runner_.run(
      std::move(actions), options_.keep_going, [this](const typename Kit::Result& r) { result(r); },
      [this](bool all_ok) { exit(all_ok ? kExitOk : kExitFailed); });
}

template <class Kit>
void BasicConsole<Kit>::start() {
  prompt();
}

template <class Kit>
void BasicConsole<Kit>::line(std::string text) {
  if (exited_) return;
  prompted_ = false;  // the user's newline ended the prompt's line
  pending_.push_back(std::move(text));
  process();
}

template <class Kit>
void BasicConsole<Kit>::end_of_input() {
  input_ended_ = true;
  process();
}

template <class Kit>
void BasicConsole<Kit>::interrupt() {
  if (exited_) return;
  print("interrupted; disconnecting");
  exit(kExitInterrupted);
}

template <class Kit>
void BasicConsole<Kit>::process() {
  while (!exited_ && !running_ && !pending_.empty()) {
    const std::string text = std::move(pending_.front());
    pending_.pop_front();
    if (builtin(text)) continue;
    auto parsed = parse_line(session_, text);
    if (parsed.error) {
      print("error: column " + std::to_string(parsed.error->column) + ": " + parsed.error->message);
      continue;
    }
    if (!parsed.action) continue;
    running_ = true;
    runner_.execute(std::move(*parsed.action), [this](const typename Kit::Result& r) {
      running_ = false;
      result(r);
      process();
    });
  }
  if (exited_) return;
  if (input_ended_ && !running_ && pending_.empty()) {
    exit(kExitOk);
    return;
  }
  prompt();
}

template <class Kit>
bool BasicConsole<Kit>::builtin(const std::string& raw) {
  const std::string text = trim(raw);
  const std::string word = wr8::first_word(text);
  const std::string rest = trim(text.substr(std::min(text.size(), word.size())));
  const auto& core = session_.core();
  if (word == "state") {
    std::string s = state_text(session_, executor_.now());
    s.pop_back();
    print(s);
  } else if (word == "log") {
    std::size_t n = 20;
    if (!rest.empty()) {
      try {
        n = std::stoul(rest);
      } catch (...) {
        print("error: log takes a number of lines, got '" + rest + "'");
        return true;
      }
    }
    const auto entries = core.log()->entries();
    wr8::CommLog tail;
    for (std::size_t i = entries.size() > n ? entries.size() - n : 0; i < entries.size(); ++i)
      tail.add(entries[i]);
    std::string s = tail.to_string(client::LogFormat::txt);
    if (!s.empty()) s.pop_back();
    print(s.empty() ? "(the log is empty)" : s);
  } else if (word == "history") {
    if (history_.empty()) print("(no actions yet)");
    for (const auto& h : history_)
      print(h);
  } else if (word == "save-log") {
    if (rest.empty()) {
      print("error: save-log needs a path (.txt, .csv or .ndjson)");
      return true;
    }
    if (save_log(*core.log(), rest))
      print("saved " + std::to_string(core.log()->size()) + " log entries to " + rest);
    else
      print("error: cannot write " + rest);
  } else if (word == "help" || word == "?") {
    std::string s = help_text(session_);
    s.pop_back();
    print(s);
  } else if (word == "quit" || word == "exit") {
    exit(kExitOk);
  } else {
    return false;
  }
  return true;
}

template <class Kit>
void BasicConsole<Kit>::exit(int code) {
  if (exited_) return;
  exited_ = true;
  if (session_.core().state() != wr8::ConnectionState::disconnected) session_.disconnect();
  if (!options_.log_path.empty() && !save_log(*session_.core().log(), options_.log_path))
    print("error: cannot write " + options_.log_path);
  if (exit_) exit_(code);
}

template class BasicConsole<DocumentKit>;
template class BasicConsole<SvguiKit>;

}  // namespace hil::apps::wr8_client
