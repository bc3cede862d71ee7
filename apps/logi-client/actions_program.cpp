#include "apps/logi-client/actions_program.hpp"

#include <ostream>
#include <utility>

#include "link/endpoint.hpp"

namespace hil::apps::logi_client {

void stop_car_then(logi::LogiSession& session, link::Executor& executor, bool stop_car,
                   const std::function<void(const std::string&)>& print,
                   std::function<void()> done) {
  if (!stop_car || session.core().state() != logi::ConnectionState::connected) {
    done();
    return;
  }
  print(stamp(executor.now()) + " emergency stop: MV:STOP" +
        (session.core().known_mode() == logi::proto::Mode::manual ? "" : " and ST:STOP"));
  session.emergency_stop();
  // The answers (or their timeouts), within a bound that keeps a program
  // driven by hil run inside the 5 s it has to exit.
  const logi::Time deadline = executor.now() + link::seconds(3);
  auto poll = std::make_shared<std::function<void()>>();
  *poll = [&session, &executor, deadline, done = std::move(done),
           self = std::weak_ptr<std::function<void()>>(poll)] {
    const auto& core = session.core();
    const bool settled = core.in_flight() == 0 && core.queued() == 0;
    if (settled || core.state() != logi::ConnectionState::connected || executor.now() >= deadline) {
      done();
      return;
    }
    if (auto again = self.lock())
      executor.call_after(link::milliseconds(10), [again] { (*again)(); });
  };
  (*poll)();
}

ActionsProgram::ActionsProgram(const BatchOptions& options, std::ostream& out, std::ostream& err)
    : options_(options), out_(out), err_(err) {
  logi::ClientConfig config;
  config.keepalive = options.keepalive;
  session_ = std::make_unique<logi::LogiSession>(
      program_.context(), link::TcpEndpoint{options.host, options.port}, config,
      [this](logi::Time now, const logi::Event& e) { on_event(now, e); });
  actions_ = std::make_unique<logi::ActionHost>(*session_, program_.executor());
}

ActionsProgram::~ActionsProgram() = default;

int ActionsProgram::run() {
  program_.on_stop_signal([this](int signal) { on_signal(signal); });
  begin();
  const int code = program_.run();
  after_loop();
  if (!options_.log_path.empty()) {
    std::string error;
    if (!write_log(*session_->log(), options_.log_path, error)) {
      err_ << "logi-client: " << error << '\n';
    }
  }
  out_.flush();
  return code;
}

void ActionsProgram::print(const std::string& line) {
  out_ << line << std::endl;
}

void ActionsProgram::on_event(logi::Time now, const logi::Event& event) {
  if (auto line = reporter_.event_line(now, event)) print(*line);
  event_lines(event);
  if (actions_) actions_->on_event(now, event);
}

void ActionsProgram::on_signal(int signal) {
  if (stopping_) {
    // A signal while shutting down: out now, without waiting for the car.
    print(stamp(time_now()) + " interrupted again: leaving at once");
    program_.set_exit_code(kExitInterrupted);
    program_.stop(/*at_once=*/true);
    return;
  }
  print(stamp(time_now()) + " interrupted (" + signal_name(signal) + "): stopping");
  shut_down(kExitInterrupted, true);
}

void ActionsProgram::shut_down(int code, bool stop_car) {
  if (stopping_) return;
  stopping_ = true;
  program_.set_exit_code(code);
  abandon();
  stop_car_then(
      *session_, program_.executor(), stop_car && actions_->may_be_moving(),
      [this](const std::string& line) { print(line); },
      [this] {
        session_->disconnect();
        program_.stop();
      });
}

}  // namespace hil::apps::logi_client
