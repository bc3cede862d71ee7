#include "apps/logi-client/batch.hpp"

#include <cstdio>
#include <iostream>
#include <string_view>

#include "apps/common/log_file.hpp"
#include "apps/logi-client/actions_program.hpp"
#include "client/common/operator_text.hpp"
#include "client/logi/session.hpp"

namespace hil::apps::logi_client {

namespace proto = hil::protocol::logi;
using logi::ConnectionState;

// ---- input ----

LoadedScript load_script_file(const std::string& path) {
  LoadedScript loaded;
  const auto text = read_script_text(path, std::cin);
  if (!text) {
    loaded.errors.push_back({path, 0, 0, "cannot read the script"});
    return loaded;
  }
  auto script = logi::parse_operator_script(*text, path == "-" ? "<stdin>" : path);
  loaded.errors = std::move(script.errors);
  if (loaded.ok()) loaded.steps = std::move(script.steps);
  return loaded;
}

LoadedScript load_script_arguments(const std::vector<std::string>& actions) {
  LoadedScript loaded;
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const int number = static_cast<int>(i) + 1;
    if (actions[i].find('\n') != std::string::npos) {
      loaded.errors.push_back(
          {"<command line>", i + 1, 1, "one action per argument (this one has a line break)"});
      continue;
    }
    const auto parsed = logi::parse_operator_action(actions[i]);
    if (parsed.error) {
      loaded.errors.push_back(
          {"<command line>", i + 1, parsed.error->column, parsed.error->message});
      continue;
    }
    if (!parsed.action) continue;  // an empty or comment-only argument
    const std::string text(
        client::trim(std::string_view(actions[i]).substr(0, actions[i].find('#')), " \t\r"));
    loaded.steps.push_back(logi::OperatorStep{number, text, *parsed.action});
  }
  return loaded;
}

// ---- log ----

std::optional<std::string> check_log_path(const std::string& path) {
  if (has_log_extension(path)) return std::nullopt;
  return "--log " + path + ": the format comes from the extension: .txt, .csv or .ndjson";
}

bool write_log(const logi::CommLog& log, const std::string& path, std::string& error) {
  if (save_log(log, path)) return true;
  error = "cannot write the log to " + path;
  return false;
}

// ---- reporting ----

std::string stamp(logi::Time at) {
  return "[" + seconds_stamp(at, 7) + "]";
}

std::string BatchReporter::result_line(const logi::ActionResult& result) {
  std::string line = stamp(result.ended) + (result.ok ? " ok   " : " FAIL ") + result.text;
  if (!result.ok) line += ": " + result.reason;
  return line;
}

namespace {

std::string status_text(const proto::Status& s) {
  char station[8];
  std::snprintf(station, sizeof station, "%03d", s.station);
  std::string text =
      "MODE " + std::string(proto::to_string(s.mode)) + "  RUN " + (s.running ? "1" : "0") +
      "  STA " + station + "  SP " + std::to_string(s.speed_percent) + "  MAN " +
      std::string(proto::to_string(s.manual)) + "  DIS " + std::to_string(s.distance_cm) + " cm";
  if (s.obstacle) text += "  OBSTACLE";
  return text;
}

bool operator_fields_differ(const proto::Status& a, const proto::Status& b) {
  return a.mode != b.mode || a.running != b.running || a.station != b.station ||
         a.speed_percent != b.speed_percent || a.manual != b.manual || a.obstacle != b.obstacle;
}

}  // namespace

std::optional<std::string> BatchReporter::event_line(logi::Time now, const logi::Event& event) {
  const std::string at = stamp(now);
  if (const auto* c = std::get_if<logi::ConnectionEvent>(&event)) {
    switch (c->state) {
      case ConnectionState::connecting:
        if (c->attempt == 0) return std::nullopt;
        return at + " link reconnect attempt " + std::to_string(c->attempt);
      case ConnectionState::connected:
        return at + " link connected";
      case ConnectionState::reconnecting:
        shown_.reset();
        return at + " WARN not connected (lost or refused); reconnecting, attempt " +
               std::to_string(c->attempt) + " pending";
      case ConnectionState::disconnected:
        shown_.reset();
        return at + " link disconnected";
      default:  // authenticating, degraded, down: LOGI never reaches them
        break;
    }
    return std::nullopt;
  }
  if (const auto* s = std::get_if<logi::StatusEvent>(&event)) {
    if (shown_ && !operator_fields_differ(*shown_, s->status)) return std::nullopt;
    shown_ = s->status;
    return at + " car  " + status_text(s->status);
  }
  if (const auto* s = std::get_if<logi::StaleEvent>(&event)) {
    return at + (s->stale ? " WARN telemetry stale: no STAT for more than 2 s"
                          : " car  telemetry fresh again");
  }
  if (const auto* n = std::get_if<logi::NoticeEvent>(&event)) {
    return at + " note " + n->text;
  }
  if (const auto* p = std::get_if<logi::ParseErrorEvent>(&event)) {
    std::string raw;
    for (auto b : p->error.raw) {
      if (b >= 0x20 && b < 0x7f) {
        raw += static_cast<char>(b);
      } else {
        char hex[8];
        std::snprintf(hex, sizeof hex, "\\x%02X", b);
        raw += hex;
      }
    }
    return at + " WARN dropped a bad frame from the car (" +
           std::string(protocol::to_string(p->error.kind)) + "): " + raw;
  }
  if (const auto* f = std::get_if<logi::FeedbackEvent>(&event)) {
    if (f->request != 0) return std::nullopt;
    return at + " WARN feedback that answers nothing sent: FB:" +
           std::string(proto::to_string(f->feedback.command)) + ":" +
           (f->feedback.accepted ? "1" : "0");
  }
  if (const auto* c = std::get_if<logi::CommandEvent>(&event)) {
    if (c->state == logi::CommandState::sent && c->attempt > 1) {
      return at + " note no feedback yet: " + proto::kind_of(c->command) + " sent again (attempt " +
             std::to_string(c->attempt) + ")";
    }
  }
  return std::nullopt;
}

// ---- the run ----

namespace {

/// The run of a list of steps: the run ends with them; on a failure the
/// car is stopped if it may be moving.
class BatchRun final : public ActionsProgram {
 public:
  BatchRun(const BatchOptions& options, std::vector<logi::OperatorStep> steps, std::ostream& out,
           std::ostream& err)
      : ActionsProgram(options, out, err), steps_(std::move(steps)) {}

 private:
  void begin() override {
    actions_->run(
        std::move(steps_), options_.runner,
        [this](const logi::ActionResult& r) { print(BatchReporter::result_line(r)); },
        [this](const logi::RunSummary& s, const auto&) {
          shut_down(s.ok ? kExitOk : kExitActionFailed, !s.ok);
        });
  }

  std::vector<logi::OperatorStep> steps_;
};

}  // namespace

int run_batch(const BatchOptions& options, std::vector<logi::OperatorStep> steps, std::ostream& out,
              std::ostream& err) {
  BatchRun run(options, std::move(steps), out, err);
  return run.run();
}

}  // namespace hil::apps::logi_client
