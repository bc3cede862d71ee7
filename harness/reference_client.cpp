#include "harness/reference_client.hpp"

#include "protocol/common/car_profile.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>
#include <variant>
#include <vector>

#include "client/arduino/operator.hpp"
#include "client/common/connection.hpp"
#include "client/leka/operator.hpp"
#include "client/logi/action_host.hpp"
#include "client/logi/operator.hpp"
#include "client/wr8/operator.hpp"
#include "client/wr8/svgui_operator.hpp"
#include "protocol/common/overloaded.hpp"

namespace hil::harness {
namespace {

// Connection states in the clients' shared vocabulary, so one matcher
// ({client: connected}) works whatever the car; "detail" is the client's
// own name of the state where it has one (Arduino's "OPEN"), else the same word.
nlohmann::json connection(client::ConnectionState state, int attempt,
                          std::string_view detail = {}) {
  const std::string word(client::to_string(state));
  return {{"state", word},
          {"detail", detail.empty() ? word : std::string(detail)},
          {"attempt", attempt}};
}

std::string decode_error_text(const protocol::DecodeError& e) {
  std::string text(protocol::to_string(e.kind));
  if (!e.detail.empty()) text += ": " + e.detail;
  return text;
}

std::string column_message(std::size_t column, const std::string& message) {
  return "column " + std::to_string(column) + ": " + message;
}

// Why an operator's parsed line is not one action, or nothing when it is.
template <class Action>
std::optional<std::string> line_problem(const client::ParseResult<Action>& parsed) {
  if (parsed.error) return column_message(parsed.error->column, parsed.error->message);
  if (!parsed.action) return "no action";
  return std::nullopt;
}

// Runs the action's completion on a later turn, so a runner never sees its
// owner react (and perhaps start the next action) inside its own callback.
void later(link::Executor& executor, std::shared_ptr<bool> alive, std::function<void()> f) {
  executor.post([alive = std::move(alive), f = std::move(f)] {
    if (*alive) f();
  });
}

// What every car's reference session keeps: the executor, the timeline it
// records to, and the flag that drops what is still due once it is gone.
class RecordingSession : public ScenarioClient {
 public:
  ~RecordingSession() override { *alive_ = false; }

 protected:
  RecordingSession(link::Executor& executor, RunTimeline& timeline)
      : executor_(executor), timeline_(timeline) {}

  /// Tells `done` how its action ended, on a later turn (later()).
  void done_later(const Done& done, bool ok, std::string reason) {
    later(executor_, alive_, [done, ok, reason = std::move(reason)] { done(ok, reason); });
  }
  /// Stamps the log of `session` (a serial client's) with the run's time
  /// in microseconds instead of the wall clock's.
  template <class Session>
  void log_in_run_time(Session& session) {
    session.set_wall_clock([this] { return executor_.now().count() / 1000; });
  }

  link::Executor& executor_;
  RunTimeline& timeline_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

// ------------------------------------------------------------------ LOGI

class LogiReference final : public RecordingSession {
 public:
  LogiReference(link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
                std::unique_ptr<client::logi::LogiClientCore> core)
      : RecordingSession(context.executor, timeline),
        session_(context, std::move(core), std::move(endpoint),
                 [this](Time now, const client::logi::Event& e) { on_event(now, e); }) {}

  void execute(const std::string& text, Done done) override {
    const auto parsed = client::logi::parse_operator_action(text);
    if (!parsed.ok() || !parsed.action) {
      const std::string why = parsed.error
                                  ? column_message(static_cast<std::size_t>(parsed.error->column),
                                                   parsed.error->message)
                                  : "no action";
      done_later(done, false, why);
      return;
    }
    // Each action has a runner of its own, so a scheduled one (an
    // emergency stop) goes out beside the action under way.
    actions_.run(
        {{1, text, *parsed.action}}, {}, {},
        [done](const client::logi::RunSummary&, const std::vector<client::logi::ActionResult>& r) {
          done(!r.empty() && r.back().ok, r.empty() ? std::string() : r.back().reason);
        });
  }

  bool concurrent() const override { return true; }

  void cancel() override { actions_.cancel(); }

  // What an operator quitting does (apps/logi-client): a car that may be
  // moving gets the emergency stop (MV:STOP, and ST:STOP outside MAN)
  // before the hang-up, as the firmware runs on when its client leaves.
  void stop() override {
    const bool may_be_moving = actions_.may_be_moving();
    cancel();
    if (may_be_moving) session_.emergency_stop();
    session_.disconnect();
  }

 private:
  void on_event(Time now, const client::logi::Event& event) {
    namespace cl = client::logi;
    std::visit(
        protocol::Overloaded{
            [&](const cl::ConnectionEvent& e) {
              timeline_.add(ClientKind::connection, connection(e.state, e.attempt));
            },
            [&](const cl::CommandEvent& e) {
              timeline_.add(ClientKind::command, {{"command", protocol::logi::kind_of(e.command)},
                                                  {"text", protocol::logi::encode_text(e.command)},
                                                  {"state", std::string(cl::to_string(e.state))},
                                                  {"request", e.request},
                                                  {"attempt", e.attempt}});
            },
            [&](const cl::StaleEvent& e) {
              timeline_.add(e.stale ? ClientKind::stale : ClientKind::fresh);
            },
            [&](const cl::NoticeEvent& e) {
              timeline_.add(ClientKind::notice, {{"text", e.text}});
            },
            [&](const cl::ParseErrorEvent& e) {
              timeline_.add(ClientKind::parse_error, {{"text", decode_error_text(e.error)}});
            },
            [&](const cl::MovementEvent& e) {
              timeline_.add(ClientKind::movement, {{"enabled", e.enabled}, {"reason", e.reason}});
            },
            [](const cl::StatusEvent&) {},    // the STAT frames are on the wire
            [](const cl::FeedbackEvent&) {},  // so are the FB frames
        },
        event);
    actions_.on_event(now, event);
  }

  client::logi::LogiSession session_;
  client::logi::ActionHost actions_{session_, executor_};
};

// ------------------------------------------------------------------- WR8

/// The document's dialect for Wr8Reference.
struct DocumentWr8 {
  using Session = client::wr8::Wr8Session;
  using Runner = client::wr8::OperatorRunner;
  using Event = client::wr8::Event;
  using Config = client::wr8::ClientConfig;

  auto parse(const std::string& text) const { return client::wr8::parse_operator_line(text); }
  static std::string command(const client::wr8::RequestEvent& e) {
    return e.kind == client::wr8::RequestKind::settings
               ? std::string("settings")
               : std::string(protocol::wr8::to_string(e.task));
  }
  static nlohmann::json stale_fields(const client::wr8::StaleEvent&) {
    return nlohmann::json::object();
  }
};

/// The real smart_vehicle_gui programs' dialects (svgui-2019, svgui-head).
struct ProgramWr8 {
  using Session = client::wr8::SvguiSession;
  using Runner = client::wr8::SvguiRunner;
  using Event = client::wr8::SvguiEvent;
  using Config = client::wr8::SvguiConfig;

  protocol::wr8::svgui::Version version;
  auto parse(const std::string& text) const { return client::wr8::parse_svgui_line(text, version); }
  static std::string command(const client::wr8::RequestEvent& e) {
    return client::wr8::svgui_request_name(e);
  }
  static nlohmann::json stale_fields(const client::wr8::StaleEvent& e) {
    return {{"stream", std::string(client::wr8::to_string(e.stream))}};
  }
};

/// The WR8 reference client in one of its dialects: the same client
/// records whichever it speaks, its requests named as the operator types
/// them.
template <class Dialect>
class Wr8Reference final : public RecordingSession {
 public:
  Wr8Reference(link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
               typename Dialect::Config config, Dialect dialect = {})
      : RecordingSession(context.executor, timeline),
        dialect_(dialect),
        session_(context, std::move(endpoint), std::move(config),
                 [this](Time now, const typename Dialect::Event& e) { on_event(now, e); }),
        runner_(std::make_unique<Runner>(executor_, session_)) {}
  /// The document's dialect on `core` (make_wr8_reference_client()); only
  /// DocumentWr8's session is made on a core, so only it compiles this.
  Wr8Reference(link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
               std::unique_ptr<client::wr8::Wr8ClientCore> core)
      : RecordingSession(context.executor, timeline),
        session_(context, std::move(core), std::move(endpoint),
                 [this](Time now, const typename Dialect::Event& e) { on_event(now, e); }),
        runner_(std::make_unique<Runner>(executor_, session_)) {}

  void execute(const std::string& text, Done done) override {
    auto parsed = dialect_.parse(text);
    if (const auto why = line_problem(parsed)) {
      done_later(done, false, *why);
      return;
    }
    retired_.clear();
    const std::uint64_t generation = ++generation_;
    runner_->execute(std::move(*parsed.action),
                     [this, generation, done](const typename Runner::Result& r) {
                       if (generation != generation_) return;
                       done_later(done, r.ok, r.ok ? std::string() : r.detail);
                     });
  }

  void cancel() override {
    ++generation_;
    if (runner_->busy()) {
      // The runner has no cancel; a fresh one takes over and the old one's
      // answer is ignored.
      retired_.push_back(std::move(runner_));
      runner_ = std::make_unique<Runner>(executor_, session_);
    }
  }

  void stop() override {
    cancel();
    session_.disconnect();
  }

 private:
  using Runner = typename Dialect::Runner;

  void on_event(Time now, const typename Dialect::Event& event) {
    namespace cw = client::wr8;
    std::visit(protocol::Overloaded{
                   [&](const cw::ConnectionEvent& e) {
                     timeline_.add(ClientKind::connection, connection(e.state, e.attempt));
                   },
                   [&](const cw::LoginEvent&) {
                     timeline_.add(ClientKind::login, {{"ok", true}});
                   },
                   [&](const cw::LoginFailedEvent& e) {
                     timeline_.add(ClientKind::login, {{"ok", false}, {"reason", e.reason}});
                   },
                   [&](const cw::StaleEvent& e) {
                     timeline_.add(e.stale ? ClientKind::stale : ClientKind::fresh,
                                   Dialect::stale_fields(e));
                   },
                   [&](const cw::RequestEvent& e) {
                     timeline_.add(ClientKind::command,
                                   {{"command", Dialect::command(e)},
                                    {"state", std::string(cw::to_string(e.state))},
                                    {"request", e.coi}});
                   },
                   [&](const cw::ParseErrorEvent& e) {
                     timeline_.add(ClientKind::parse_error, {{"text", decode_error_text(e.error)}});
                   },
                   [](const auto&) {},  // DATA, MAP, settings read back: the wire shows them
               },
               event);
    if (runner_) runner_->on_event(now, event);
  }

  Dialect dialect_;
  typename Dialect::Session session_;
  std::unique_ptr<Runner> runner_;
  std::vector<std::unique_ptr<Runner>> retired_;
  std::uint64_t generation_ = 0;
};

// --------------------------------------------------------------- Arduino

class ArduinoReference final : public RecordingSession {
 public:
  ArduinoReference(link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
                   std::unique_ptr<client::arduino::ArduinoClientCore> core)
      : RecordingSession(context.executor, timeline),
        session_(context, std::move(endpoint), std::move(core)) {
    log_in_run_time(session_);
    make_runner();
  }
  ~ArduinoReference() override { runner_.reset(); }

  void start() override { session_.open(); }

  void execute(const std::string& text, Done done) override {
    auto parsed = client::arduino::parse_operator_line(text);
    if (const auto why = line_problem(parsed)) {
      done_later(done, false, *why);
      return;
    }
    // Quitting means nothing in a scenario: the run decides when it ends.
    if (std::holds_alternative<client::arduino::QuitCommand>(*parsed.action)) {
      done_later(done, true, "");
      return;
    }
    pending_[next_index_++] = std::move(done);
    runner_->add(std::move(*parsed.action));
  }

  void cancel() override {
    pending_.clear();
    if (!runner_->idle()) make_runner();
  }

  // What an operator quitting does: a last S (stop) to a robot that may
  // still be moving, then the port closes.
  void stop() override {
    cancel();
    if (session_.state() == client::ConnectionState::connected) session_.stop();
    session_.close();
  }

 private:
  void make_runner() {
    runner_.reset();  // its destructor clears the session's handler
    runner_ = std::make_unique<client::arduino::OperatorRunner>(
        session_, executor_, client::arduino::OperatorRunner::Options{true});
    next_index_ = 0;
    runner_->set_event_handler([this](const client::arduino::Event& e) { on_event(e); });
    runner_->set_outcome_handler([this](const client::arduino::CommandOutcome& o) {
      const auto it = pending_.find(o.index);
      if (it == pending_.end()) return;
      Done done = std::move(it->second);
      pending_.erase(it);
      done_later(done, o.ok, o.ok ? std::string() : client::arduino::describe_outcome(o));
    });
  }

  void on_event(const client::arduino::Event& event) {
    namespace ca = client::arduino;
    std::visit(protocol::Overloaded{
                   [&](const ca::LinkChanged& e) {
                     auto data = connection(e.to, 0, ca::link_name(e.to));
                     data["reason"] = e.reason;
                     timeline_.add(ClientKind::connection, std::move(data));
                   },
                   [&](const ca::RequestDone& e) {
                     timeline_.add(ClientKind::command,
                                   {{"request", e.id},
                                    {"state", std::string(ca::to_string(e.result.code))},
                                    {"detail", ca::describe_result(e.result)}});
                   },
                   [](const ca::FrameReceived&) {},  // on the wire already
               },
               event);
  }

  client::arduino::ArduinoSession session_;
  std::unique_ptr<client::arduino::OperatorRunner> runner_;
  std::map<std::size_t, Done> pending_;
  std::size_t next_index_ = 0;
};

// ------------------------------------------------------------------ Leka

class LekaReference final : public RecordingSession {
 public:
  LekaReference(link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
                client::leka::ClientConfig config)
      : RecordingSession(context.executor, timeline),
        session_(context, std::move(endpoint), std::move(config)),
        runner_(executor_, session_) {
    log_in_run_time(session_);
    // The port has no events of its own: look again whenever the wire opens
    // or closes, so the record comes at the moment it happened.
    listener_ = timeline_.listen([this](const Record& r) {
      if (r.source() == Source::wire && (r.kind == WireKind::open || r.kind == WireKind::close))
        later(executor_, alive_, [this] { poll(); });
    });
  }
  ~LekaReference() override { timeline_.unlisten(listener_); }

  void start() override { session_.open(); }

  void execute(const std::string& text, Done done) override {
    auto parsed = client::leka::parse_script(text, "scenario");
    if (!parsed.ok()) {
      const auto& e = parsed.errors.front();
      done_later(done, false, column_message(e.column, e.message));
      return;
    }
    if (!session_.is_open()) {
      done_later(
          done, false,
          "the port is not open" +
              (session_.open_error().empty() ? std::string() : ": " + session_.open_error()));
      return;
    }
    const std::uint64_t generation = ++generation_;
    auto failure = std::make_shared<std::string>();
    runner_.run(
        std::move(parsed),
        [failure](const client::leka::LineResult& r) {
          if (!r.ok) *failure = r.error;
        },
        [this, generation, failure, done](bool ok) {
          if (generation != generation_) return;
          done_later(done, ok, *failure);
        });
  }

  void cancel() override {
    ++generation_;
    runner_.cancel();
  }

  // What leka-client does when it is stopped: "stop robot" (motors and
  // behaviour) before the port closes, as the robot runs on without it.
  void stop() override {
    cancel();
    if (session_.is_open()) session_.send(client::leka::GroupBuilder{}.stop_robot());
    session_.close();
    poll();
  }

  void poll() override {
    const auto state = session_.state();
    if (state == state_) return;
    state_ = state;
    const bool open = state == client::ConnectionState::connected;
    timeline_.add(ClientKind::connection, connection(state, 0, open ? "open" : "closed"));
  }

 private:
  client::leka::LekaSession session_;
  client::leka::OperatorRunner runner_;
  client::ConnectionState state_ = client::ConnectionState::disconnected;
  std::uint64_t generation_ = 0;
  RunTimeline::ListenerId listener_ = 0;
};

}  // namespace

std::unique_ptr<ScenarioClient> make_logi_reference_client(
    link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
    std::unique_ptr<client::logi::LogiClientCore> core) {
  return std::make_unique<LogiReference>(context, std::move(endpoint), timeline, std::move(core));
}

std::unique_ptr<ScenarioClient> make_arduino_reference_client(
    link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
    std::unique_ptr<client::arduino::ArduinoClientCore> core) {
  return std::make_unique<ArduinoReference>(context, std::move(endpoint), timeline,
                                            std::move(core));
}

std::unique_ptr<ScenarioClient> make_wr8_reference_client(
    link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
    std::unique_ptr<client::wr8::Wr8ClientCore> core) {
  return std::make_unique<Wr8Reference<DocumentWr8>>(context, std::move(endpoint), timeline,
                                                     std::move(core));
}

std::unique_ptr<ScenarioClient> make_reference_client(
    mocks::CarKind car, link::TransportContext& context, link::Endpoint endpoint,
    RunTimeline& timeline, const nlohmann::json& settings, std::string_view profile) {
  const protocol::CarProfile& named = protocol::find_car_profile(mocks::to_string(car), profile);
  switch (car) {
    case mocks::CarKind::logi:
      return make_logi_reference_client(
          context, std::move(endpoint), timeline,
          std::make_unique<client::logi::LogiClientCore>(logi_client_config(settings)));
    case mocks::CarKind::wr8: {
      if (const auto version = svgui_version(car, named.name)) {
        auto config = svgui_client_config(settings);
        config.version = *version;
        return std::make_unique<Wr8Reference<ProgramWr8>>(context, std::move(endpoint), timeline,
                                                          config, ProgramWr8{*version});
      }
      return make_wr8_reference_client(
          context, std::move(endpoint), timeline,
          std::make_unique<client::wr8::Wr8ClientCore>(wr8_client_config(settings)));
    }
    case mocks::CarKind::arduino: {
      return make_arduino_reference_client(context, std::move(endpoint), timeline,
                                           std::make_unique<client::arduino::ArduinoClientCore>(
                                               arduino_client_config(settings, named.name)));
    }
    case mocks::CarKind::leka: {
      auto config = leka_client_config(settings);
      config.dialect = protocol::leka::dialect_named(named.name);
      return std::make_unique<LekaReference>(context, std::move(endpoint), timeline, config);
    }
  }
  return nullptr;
}

}  // namespace hil::harness
