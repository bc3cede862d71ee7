#include "apps/leka-client/app.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <map>
#include <memory>

#include "apps/common/log_file.hpp"
#include "apps/common/version.hpp"
#include "client/leka/session.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/leka/message.hpp"

namespace hil::apps::leka_client {

namespace leka = client::leka;

namespace {

std::string hex_of(protocol::ByteView bytes) {
  static const char* digits = "0123456789ABCDEF";
  std::string out;
  for (std::uint8_t b : bytes) {
    if (!out.empty()) out += ' ';
    out += digits[b >> 4];
    out += digits[b & 0xF];
  }
  return out;
}

std::string info_text(const leka::InfoReply& reply) {
  std::string out = "info";
  // The well-known fields first, in the robot's order, then any others.
  for (const char* key : {"name", "firmware", "buffer", "state"}) {
    auto it = reply.fields.find(key);
    if (it != reply.fields.end()) out += " " + it->first + "=" + it->second;
  }
  for (const auto& [key, value] : reply.fields) {
    if (key != "name" && key != "firmware" && key != "buffer" && key != "state")
      out += " " + key + "=" + value;
  }
  return out;
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace

ParsedArguments parse_arguments(int argc, const char* const* argv) {
  AppOptions o;
  CLI::App app{"leka-client: send command groups to the Leka robot, one line per group"};
  app.set_version_flag("--version", version_line("leka-client"));
  add_serial_options(app, o.port, o.baud,
                     "Serial device of the robot (/dev/ttyUSB0, /tmp/hil-leka0) or a hil "
                     "endpoint (pty://PATH, tcp://HOST:PORT); not needed with --dry-run",
                     "Line rate of the serial port (default 115200; 0 leaves it)");
  add_log_and_script_options(
      app, o.log_path,
      "Write every frame sent and line received to FILE at exit (.txt, .csv or .ndjson)", o.script,
      "Run the groups of this file, one per line ('-' = stdin)");
  app.add_flag("--dry-run", o.dry_run,
               "Print each group's frames in hex and exit, without opening a port");
  app.add_option("--info-timeout-ms", o.info_timeout_ms,
                 "How long an info waits for the robot's answer (default 200)")
      ->check(CLI::Range(1, 60000));
  app.add_option("--frame-bytes", o.frame_bytes,
                 "Largest frame, and the most bytes sent per 10 ms (default 64, half the "
                 "robot's 128-byte buffer; more risks lost bytes)")
      ->check(CLI::Range(12, 128));
  add_profile_option(
      app, o.profile, "leka",
      "The robot's convention: readme (the default: the README's ids and checksum) or "
      "comspecs-v3 (the spec's YAML ids, the 8-bit checksum over length and group)");
  app.add_option("groups", o.groups,
                 "Command groups, one per argument, e.g. \"ear all 255 0 0; motor all 0 120\"");
  app.footer(
      "Commands (';' between commands of one group):\n"
      "  info | stop led|motor|robot | ear all R G B | ear single LED(0..1) R G B\n"
      "  belt all R G B | belt range FIRST LAST R G B | belt single LED(0..19) R G B\n"
      "  motor all DIR SPEED | motor duo LSPIN LSPEED RSPIN RSPEED | motor left|right SPIN SPEED\n"
      "  motivator ID(0x51..0x55) | guidance ID(0x41..0x4F) | wait 500ms|1s (alone on a line)\n"
      "  Values are decimal or 0x hex; spins 0/forward or 1/backward; '#' starts a comment.\n"
      "Exit status: 0 every group went out (and every info was answered), 1 a group failed\n"
      "  (info unanswered, port gone or not opened), 2 bad usage or a script error\n"
      "  (file:line:col), 130 interrupted (stop robot is sent first).\n"
      "Examples:\n"
      "  leka-client --port /tmp/hil-leka0 \"ear all 255 0 0; motor all 0 120\" info\n"
      "  leka-client --port /tmp/hil-leka0 --script show.leka --log run.csv\n"
      "  leka-client --dry-run \"belt single 0 255 0 0\"\n"
      "  leka-client --dry-run --profile comspecs-v3 \"belt single 0x12 100 150 200\"\n");
  return parse_options<AppOptions>(
      app, argc, argv, o, [](const AppOptions& given) -> std::optional<std::string> {
        if (!given.script.empty() && !given.groups.empty())
          return "leka-client: give either --script or groups, not both";
        if (given.script.empty() && given.groups.empty())
          return "leka-client: nothing to send: give groups or --script FILE (see --help)";
        if (given.port.empty() && !given.dry_run)
          return "leka-client: --port is required (or --dry-run)";
        if (!given.log_path.empty() && !log_format_for(given.log_path))
          return "leka-client: --log " + given.log_path +
                 ": the name must end in .txt, .csv or .ndjson";
        return std::nullopt;
      });
}

leka::ClientConfig config_for(const AppOptions& options) {
  leka::ClientConfig config;
  config.info_timeout = link::milliseconds(options.info_timeout_ms);
  config.max_frame_bytes = static_cast<std::size_t>(options.frame_bytes);
  config.bytes_per_period = static_cast<std::size_t>(options.frame_bytes);
  config.dialect = protocol::leka::dialect_named(options.profile);
  return config;
}

std::optional<leka::LogFormat> log_format_for(const std::string& path) {
  if (!has_log_extension(path)) return std::nullopt;
  return client::log_format_for(path);
}

leka::Script load_script(const AppOptions& options, std::istream& in) {
  if (options.script.empty()) return leka::parse_lines(options.groups, "arg");
  const auto text = read_script_text(options.script, in);
  if (!text) {
    leka::Script unread;
    unread.source = options.script;
    unread.errors.push_back(
        {options.script, 0, 0, std::string("cannot read the script: ") + std::strerror(errno)});
    return unread;
  }
  return leka::parse_script(*text, options.script == "-" ? "stdin" : options.script);
}

std::string format_result(const std::string& source, const leka::LineResult& result,
                          const leka::OperatorLine& line) {
  std::string out = source + ":" + std::to_string(result.number) + ": ";
  if (!result.ok) return out + "FAILED: " + result.error;
  if (line.kind == leka::OperatorLine::Kind::wait) {
    return out + "ok, waited " +
           std::to_string(std::chrono::duration_cast<link::milliseconds>(line.wait).count()) +
           " ms";
  }
  out += "ok, " + plural(line.commands, "command", "commands") + ", " +
         plural(result.frames, "frame", "frames") + ", " + plural(result.bytes, "byte", "bytes") +
         " sent";
  for (const auto& info : result.infos)
    out += "; " + info_text(info);
  return out;
}

std::string dry_run_text(const leka::Script& script, const leka::ClientConfig& config) {
  std::string out;
  for (const auto& line : script.lines) {
    out += script.source + ":" + std::to_string(line.number) + ": " + line.text + "\n";
    for (const auto& frame : leka::frames_of(line.line, config))
      out += "  " + hex_of(frame) + "\n";
  }
  return out;
}

// ------------------------------------------------------------------- run

namespace {

// The whole run on the real-time driver: open, play the script, and close
// after the last frame has left (or on a signal, after stop robot).
class Run {
 public:
  Run(const AppOptions& options, leka::Script script, link::Endpoint endpoint)
      : options_(options),
        script_(std::move(script)),
        session_(program_.context(), std::move(endpoint), config_for(options)),
        runner_(program_.executor(), session_) {
    for (const auto& line : script_.lines)
      lines_[line.number] = &line.line;
  }

  int go() {
    program_.on_stop_signal([this](int) {
      if (finishing_) return;
      runner_.cancel();
      if (session_.is_open()) {
        session_.send(leka::GroupBuilder{}.stop_robot());
        warn("leka-client: interrupted; stop robot sent");
      } else {
        warn("leka-client: interrupted");
      }
      finish(kExitInterrupted);
    });
    session_.open();
    wait_for_open(link::Time(0));
    return program_.run();
  }

 private:
  void wait_for_open(link::Duration waited) {
    if (finishing_) return;
    if (session_.is_open()) return start();
    if (!session_.open_error().empty()) {
      warn("leka-client: cannot open " + options_.port + ": " + session_.open_error());
      return finish(1);
    }
    if (waited >= link::seconds(5)) {
      warn("leka-client: cannot open " + options_.port + " (not open after 5 s)");
      return finish(1);
    }
    program_.executor().call_after(
        link::milliseconds(10), [this, waited] { wait_for_open(waited + link::milliseconds(10)); });
  }

  void start() {
    runner_.run(
        script_,
        [this](const leka::LineResult& r) {
          const std::string text = format_result(script_.source, r, *lines_.at(r.number));
          if (r.ok)
            std::cout << text << std::endl;
          else
            warn(text);
        },
        [this](bool ok) { finish(ok ? 0 : 1); });
  }

  // Lets the queued frames leave (a stop robot included), then closes.
  void finish(int code) {
    if (!finishing_) {
      finishing_ = true;
      program_.set_exit_code(code);
    }
    drain(link::Duration{0});
  }

  void drain(link::Duration waited) {
    if (session_.is_open() && session_.core().queued_frames() > 0 && waited < link::seconds(1)) {
      program_.executor().call_after(link::milliseconds(10),
                                     [this, waited] { drain(waited + link::milliseconds(10)); });
      return;
    }
    // A short grace so the last write reaches the port before it closes.
    program_.executor().call_after(link::milliseconds(50), [this] { close(); });
  }

  void close() {
    session_.close();
    if (!options_.log_path.empty() && !save_log(session_.log(), options_.log_path))
      program_.fail("leka-client: cannot write the log to " + options_.log_path);
    program_.stop(/*at_once=*/true);
  }

  const AppOptions& options_;
  leka::Script script_;
  std::map<std::size_t, const leka::OperatorLine*> lines_;
  ProgramLoop program_;
  leka::LekaSession session_;
  leka::OperatorRunner runner_;
  bool finishing_ = false;
};

}  // namespace

int run(const AppOptions& options) {
  auto script = load_script(options, std::cin);
  // Every line that does not parse, then nothing is sent.
  for (const auto& e : script.errors)
    warn(e.line == 0 ? "leka-client: " + e.to_string() : e.to_string());
  if (!script.ok()) return 2;
  if (options.dry_run) {
    std::cout << dry_run_text(script, config_for(options)) << std::flush;
    return 0;
  }
  auto endpoint = port_endpoint("leka-client", options.port, options.baud);
  if (!endpoint) return kExitUsage;
  Run run_state(options, std::move(script), std::move(*endpoint));
  return run_state.go();
}

}  // namespace hil::apps::leka_client
