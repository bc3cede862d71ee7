#include "apps/common/program.hpp"

#include <pthread.h>
#include <signal.h>

#include "base/enum_names.hpp"
#include "protocol/common/car_profile.hpp"

#include <CLI/CLI.hpp>

#include <asio/post.hpp>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <istream>
#include <iterator>

namespace hil::apps {

std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return std::nullopt;
}

CLI::Option* add_serial_options(CLI::App& app, std::string& port, unsigned& baud,
                                const std::string& port_help, const std::string& baud_help) {
  CLI::Option* port_option = app.add_option("-p,--port", port, port_help);
  app.add_option("--baud", baud, baud_help)->check(CLI::Range(0u, 4000000u));
  return port_option;
}

void add_log_and_script_options(CLI::App& app, std::string& log_path, const std::string& log_help,
                                std::string& script, const std::string& script_help) {
  app.add_option("--log", log_path, log_help);
  app.add_option("--script", script, script_help);
}

CLI::Option* add_profile_option(CLI::App& app, std::string& profile, const std::string& car,
                                const std::string& help) {
  return app.add_option("--profile", profile, help)->check([car](const std::string& name) {
    return protocol::car_profile_problem(car, name);
  });
}

link::Endpoint endpoint_for_port(const std::string& port, unsigned baud) {
  if (port.find("://") != std::string::npos) {
    link::Endpoint e = link::parse_endpoint(port);
    if (auto* pty = std::get_if<link::PtyEndpoint>(&e); pty && pty->baud == 0) pty->baud = baud;
    return e;
  }
  if (port.empty()) throw link::EndpointError("--port needs a device path");
  return link::PtyEndpoint{port, baud, link::Duration{0}};
}

std::optional<link::Endpoint> port_endpoint(const std::string& program, const std::string& port,
                                            unsigned baud) {
  try {
    return endpoint_for_port(port, baud);
  } catch (const link::EndpointError& e) {
    warn(program + ": --port: " + e.what());
    return std::nullopt;
  }
}

void warn(const std::string& text) {
  std::cerr << text << '\n' << std::flush;
}

std::optional<std::string> read_script_text(const std::string& path, std::istream& standard_input) {
  if (path == "-") {
    return std::string(std::istreambuf_iterator<char>(standard_input),
                       std::istreambuf_iterator<char>());
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string seconds_stamp(link::Time at, int width) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%*.3f s", width, std::chrono::duration<double>(at).count());
  return buf;
}

constexpr auto kStopSignalNames =
    base::enum_names<int>({SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"});

std::string signal_name(int signal) {
  if (const auto name = kStopSignalNames.find(signal)) return std::string(*name);
  return "signal " + std::to_string(signal);
}

void unblock_signals(std::initializer_list<int> signals) {
  sigset_t set;
  sigemptyset(&set);
  for (const int signal : signals)
    sigaddset(&set, signal);
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

ProgramLoop::ProgramLoop(std::initializer_list<int> stop_signals) : signals_(io_) {
  unblock_signals(stop_signals);
  for (const int signal : stop_signals)
    signals_.add(signal);
}

void ProgramLoop::on_stop_signal(std::function<void(int)> handler) {
  on_signal_ = std::move(handler);
  wait_for_signal();
}

void ProgramLoop::wait_for_signal() {
  signals_.async_wait([this](const std::error_code& ec, int signal) {
    if (ec || stopped_) return;
    wait_for_signal();  // armed again first: the handler may stop()
    if (on_signal_) on_signal_(signal);
  });
}

void ProgramLoop::fail(const std::string& message) {
  warn(message);
  if (exit_code_ == kExitOk) exit_code_ = kExitFailed;
}

int ProgramLoop::run() {
  io_.run();
  return exit_code_;
}

bool ProgramLoop::finish(int code, bool at_once) {
  if (finished_) return false;
  finished_ = true;
  exit_code_ = code;
  stop(at_once);
  return true;
}

void ProgramLoop::stop(bool at_once) {
  stopped_ = true;
  std::error_code ignored;
  signals_.cancel(ignored);
  if (at_once) {
    io_.stop();
  } else {
    asio::post(io_, [this] { io_.stop(); });
  }
}

}  // namespace hil::apps
