// What wr8-client prints for the real programs' dialects (profiles
// svgui-2019 and svgui-head): help, the state command, interactive event
// lines and the --data lines.

#include <cstdio>
#include <string>

#include "apps/wr8-client/console.hpp"

namespace hil::apps::wr8_client {

namespace {

using client::Overloaded;
namespace svgui = wr8::svgui;

constexpr std::string_view kHelp2019 =
    "actions of profile svgui-2019 (run in order; each waits for its answer):\n"
    "  connect                 open the connection and log in (AUTH konnichiwa)\n"
    "  disconnect              close the connection\n"
    "  forward CM              TASK 1: drive forward; waits for ANSWER done\n"
    "  wheels DEG              TASK 2: turn the wheels; waits for ANSWER done\n"
    "  signals                 TASK 3: flash the turn signals; waits for ANSWER done\n"
    "  settings p=P i=I d=D servo-zero=Z\n"
    "                          SETTINGS, all four whole numbers; never answered\n"
    "  wait DURATION           pause (500ms, 1s, 1.5s)\n"
    "  wait-data               wait for the next DATA packet\n"
    "  (the vehicle sends no 'started', and drops a task while busy: a timeout is the sign)\n";

constexpr std::string_view kHelpHead =
    "actions of profile svgui-head (run in order; each waits for its answer):\n"
    "  connect                 open the connection and log in (AUTH konnichiwa and a NUL)\n"
    "  disconnect              close the connection\n"
    "  control X Y             hold CONTROL: X steering, Y engine, -1..1, sent every 100 ms\n"
    "  control off             CONTROL 0 0 once, then no more\n"
    "  set NAME=VALUE...       SET; waits for ANSWER (names steering-p, -i, -d, -zero,\n"
    "                          forward-p, -i, -d, -int, backward-p, -i, -d, -int); names\n"
    "                          left out keep the values of the last set-request\n"
    "  set-request             read the settings back (the vehicle answers with SET)\n"
    "  wait DURATION           pause (500ms, 1s, 1.5s)\n"
    "  wait-data               wait for the next HIGH-FREQ or LOW-FREQ DATA\n";

std::string real(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string age(link::Time now, link::Time at) {
  return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(now - at).count()) +
         " ms";
}

std::string data_text(const svgui::Data& d) {
  return std::string(wr8::proto::to_string(d.state)) + "  encoder " + std::to_string(d.encoder) +
         "  steering " + real(d.steering) + "  motor battery " + std::to_string(d.motor_battery) +
         " %  computer battery " + std::to_string(d.computer_battery) + " %";
}

std::string high_freq_text(const svgui::HighFreqData& d) {
  return "encoder " + real(d.encoder) + "  steering " + real(d.steering) + "  x " + real(d.x) +
         "  y " + real(d.y) + "  angle " + real(d.angle);
}

std::string low_freq_text(const svgui::LowFreqData& d) {
  return std::string(wr8::proto::to_string(d.state)) + "  motor battery " +
         std::to_string(d.motor_battery) + " %  computer battery " +
         std::to_string(d.computer_battery) + " %  temperature " + real(d.temperature);
}

std::string request_text(const wr8::RequestEvent& e) {
  std::string what = wr8::svgui_request_name(e);
  if (e.coi != 0) what += " (COI " + std::to_string(e.coi) + ")";
  what += " " + underscores_to_spaces(wr8::to_string(e.state));
  if (!e.note.empty()) what += ": " + e.note;
  return what;
}

}  // namespace

std::string format_svgui_state(const wr8::SvguiClientCore& core, link::Time now) {
  std::string out = "connection: " + underscores_to_spaces(wr8::to_string(core.state())) + "\n";
  out += "profile:    " + std::string(svgui::profile_of(core.version())) + "\n";
  const auto stale = [&](wr8::DataStream s) {
    return core.stale(s) ? std::string(" (stale)") : std::string();
  };
  if (core.version() == svgui::Version::v2019) {
    const auto& d = core.data();
    if (!d) return out + "no DATA received yet\n";
    out += "vehicle:    " + std::string(wr8::proto::to_string(d->value.state)) + ", timestamp " +
           std::to_string(d->value.timestamp_ms) + " ms\n";
    out += "data:       " + data_text(d->value) + "\n";
    out += "data age:   " + age(now, d->at) + stale(wr8::DataStream::data) + "\n";
    out += "open tasks: " + std::to_string(core.open_requests()) + "\n";
    return out;
  }
  // A stream's last packet with its age, or that none came yet.
  const auto stream = [&](std::string label, const auto& last, wr8::DataStream s, auto text) {
    if (!last) return label + "none received yet\n";
    return label + text(last->value) + "  (age " + age(now, last->at) + ")" + stale(s) + "\n";
  };
  out += stream("high-freq:  ", core.high_freq(), wr8::DataStream::high_freq, high_freq_text);
  out += stream("low-freq:   ", core.low_freq(), wr8::DataStream::low_freq, low_freq_text);
  if (const auto& m = core.map())
    out += "map:        " + std::to_string(m->width) + " x " + std::to_string(m->height) + "\n";
  else
    out += "map:        none received yet\n";
  if (const auto& c = core.held_control())
    out += "control:    held, x " + real(c->x_axis) + " y " + real(c->y_axis) + "\n";
  else
    out += "control:    off\n";
  if (const auto& s = core.read_settings()) out += "settings:   " + wr8::format_set(*s) + "\n";
  return out;
}

wr8::ParsedSvguiLine parse_line(const wr8::SvguiSession& session, std::string_view line) {
  return wr8::parse_svgui_line(line, session.core().version());
}

std::string action_text(const wr8::SvguiSession&, const wr8::SvguiAction& action) {
  return wr8::to_text(action);
}

std::string state_text(const wr8::SvguiSession& session, link::Time now) {
  return format_svgui_state(session.core(), now);
}

std::string help_text(const wr8::SvguiSession& session) {
  const bool v2019 = session.core().version() == svgui::Version::v2019;
  return std::string(v2019 ? kHelp2019 : kHelpHead) + std::string(kConsoleCommands);
}

std::optional<DataLine> data_line(const wr8::SvguiEvent& event) {
  if (const auto* d = std::get_if<wr8::DataEvent>(&event))
    return DataLine{0, static_cast<int>(d->data.state), data_text(d->data)};
  if (const auto* h = std::get_if<wr8::HighFreqEvent>(&event))
    return DataLine{1, -1, "high-freq  " + high_freq_text(h->data)};
  if (const auto* l = std::get_if<wr8::LowFreqEvent>(&event))
    return DataLine{2, static_cast<int>(l->data.state), "low-freq  " + low_freq_text(l->data)};
  return std::nullopt;
}

std::optional<std::string> event_text(const wr8::SvguiSession& session,
                                      const wr8::SvguiEvent& event) {
  const auto& core = session.core();
  return std::visit(Overloaded{
                        [&](const wr8::ConnectionEvent& e) -> std::optional<std::string> {
                          return connection_text(e);
                        },
                        [&](const wr8::LoginFailedEvent& e) -> std::optional<std::string> {
                          return "login failed: " + e.reason;
                        },
                        [&](const wr8::StaleEvent& e) -> std::optional<std::string> {
                          const std::string name(wr8::to_string(e.stream));
                          if (!e.stale) return name + " flowing again";
                          const auto& c = core.config();
                          const auto after =
                              e.stream == wr8::DataStream::high_freq  ? c.high_freq_stale_after
                              : e.stream == wr8::DataStream::low_freq ? c.low_freq_stale_after
                                                                      : c.data_stale_after;
                          return name + " stale: none for " + client::duration_text(after);
                        },
                        [&](const wr8::RequestEvent& e) -> std::optional<std::string> {
                          // A sent request says something only when no answer will come.
                          if (e.state == wr8::RequestState::sent && e.note.empty())
                            return std::nullopt;
                          return request_text(e);
                        },
                        [&](const wr8::MapEvent& e) -> std::optional<std::string> {
                          return "map received: " + std::to_string(e.map.width) + " x " +
                                 std::to_string(e.map.height);
                        },
                        [&](const wr8::PacketIgnoredEvent& e) -> std::optional<std::string> {
                          // The head vehicle streams DATA before login; that is not news.
                          if (core.state() != wr8::ConnectionState::connected) return std::nullopt;
                          return "ignored " + svgui::describe(e.message) + " (" + e.why + ")";
                        },
                        [&](const wr8::ParseErrorEvent& e) -> std::optional<std::string> {
                          return "bad bytes received: " + e.error.detail;
                        },
                        [](const auto&) -> std::optional<std::string> { return std::nullopt; },
                    },
                    event);
}

}  // namespace hil::apps::wr8_client
