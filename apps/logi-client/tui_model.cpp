#include "apps/logi-client/tui_model.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <iterator>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

#include "base/duration.hpp"
#include "base/enum_names.hpp"
#include "protocol/logi/codec.hpp"

namespace hil::apps::logi_client {

namespace {

using logi::CommandState;
using logi::ConnectionState;
using proto::Direction;
using proto::Mode;

constexpr std::size_t kLogPage = 10;

std::string pad(std::string text, std::size_t width) {
  if (text.size() < width) text.append(width - text.size(), ' ');
  return text;
}

std::string payload(const proto::Message& m) {
  return proto::payload_of(m);
}

// LOGI never reaches authenticating, degraded or down.
constexpr auto kLogiConnectionTexts = base::enum_names<ConnectionState>(
    {ConnectionState::disconnected, "Disconnected"}, {ConnectionState::connecting, "Connecting"},
    {ConnectionState::connected, "Connected"},
    {ConnectionState::reconnecting, "Connection lost, reconnecting"});

constexpr auto kLogiRefusalShortTexts = base::enum_names<logi::Refusal>(
    {logi::Refusal::none, ""}, {logi::Refusal::not_connected, "not connected"},
    {logi::Refusal::mode_speed_unconfirmed, "needs MD (m) + SP (Enter) on this connection"},
    {logi::Refusal::not_held, "no direction held"},
    {logi::Refusal::unknown_request, "nothing awaits confirmation"},
    {logi::Refusal::not_a_command, "not a command"});

std::string connection_text(ConnectionState s, int attempt) {
  if (s == ConnectionState::connecting && attempt > 0)
    return "Connecting (attempt " + std::to_string(attempt) + ")";
  return std::string(kLogiConnectionTexts.name(s));
}

std::string refusal_text(logi::Refusal r) {
  return std::string(kLogiRefusalShortTexts.name(r));
}

std::string track_text(std::uint8_t mask) {
  std::string s;
  for (int bit = 3; bit >= 0; --bit)
    s += ((mask >> bit) & 1) != 0 ? '1' : '0';
  return s;
}

}  // namespace

std::optional<Direction> direction_for_key(int code) {
  // Direction i has the keys kPlain[i] and kShifted[i] (a letter in either
  // case, a bracket with or without shift), and the first four an arrow.
  static constexpr Direction kDirections[] = {Direction::fwd,   Direction::bwd, Direction::left,
                                              Direction::right, Direction::lf,  Direction::rf,
                                              Direction::lb,    Direction::rb,  Direction::ccw,
                                              Direction::cw,    Direction::stop};
  static constexpr std::string_view kPlain = "wxadqezc[]s";
  static constexpr std::string_view kShifted = "WXADQEZC{}S";
  static constexpr int kArrows[] = {key::kUp, key::kDown, key::kLeft, key::kRight};
  for (std::size_t i = 0; i < std::size(kDirections); ++i) {
    if (code == kPlain[i] || code == kShifted[i] || (i < std::size(kArrows) && code == kArrows[i]))
      return kDirections[i];
  }
  return std::nullopt;
}

std::string format_log_line(const logi::LogEntry& entry) {
  char at[32];
  std::snprintf(at, sizeof at, "%9.3f", link::to_ms(entry.at) / 1000.0);
  std::string line = std::string(at) + " " + pad(std::string(logi::to_string(entry.kind)), 5);
  if (!entry.raw.empty()) line += entry.raw + "  ";
  line += entry.description;
  return line;
}

TuiModel::TuiModel(SessionControl& control, TuiModelConfig config)
    : control_(control),
      config_(std::move(config)),
      host_(config_.host),
      port_(config_.port),
      latched_(config_.latched) {}

void TuiModel::start(Time) {
  if (config_.connect_at_start) control_.connect(host_, port_);
}

void TuiModel::say(std::string text, Style style) {
  message_ = TextLine{std::move(text), style};
}

bool TuiModel::refused(const logi::SubmitResult& result, std::string_view what) {
  if (result) return false;
  say(std::string(what) + " not sent: " + refusal_text(result.refusal), Style::warning);
  return true;
}

void TuiModel::on_key(Time now, int code) {
  // The emergency stop comes before everything else, editing included.
  if (code == ' ' || code == key::kEscape) {
    if (field_ != Field::none) {
      field_ = Field::none;
      edit_text_.clear();
    }
    emergency_stop(now);
    return;
  }
  if (code == key::kCtrlC || code == key::kCtrlQ || code == key::kF10) {
    quit(now);
    return;
  }
  if (quitting_) return;
  if (field_ != Field::none) {
    edit_key(now, code);
    return;
  }
  if (const auto direction = direction_for_key(code)) {
    if (*direction == Direction::stop) {
      stop_key(now);
    } else {
      direction_key(now, *direction);
    }
    return;
  }
  if (code >= '0' && code <= '9') {
    field_ = Field::speed;
    edit_text_.assign(1, static_cast<char>(code));
    return;
  }
  switch (code) {
    case '+':
    case '=':
      speed_percent_ = std::min(100, speed_percent_ + 10);
      say("speed set to " + std::to_string(speed_percent_) + " %, Enter sends it");
      break;
    case '-':
    case '_':
      speed_percent_ = std::max(0, speed_percent_ - 10);
      say("speed set to " + std::to_string(speed_percent_) + " %, Enter sends it");
      break;
    case key::kEnter:
    case '\r':
      send_speed(now);
      break;
    case 'm':
    case 'M':
      toggle_mode(now);
      break;
    case 't':
    case 'T':
      station_ = station_ == 1 ? 2 : 1;
      say("station " + std::string(station_ == 1 ? "001" : "002") + " selected, g sends it");
      break;
    case 'g':
    case 'G': {
      const auto r = control_.submit(proto::SetStation{station_});
      if (!refused(r, "GS")) say("GS:00" + std::to_string(station_) + " sent");
      break;
    }
    case 'r':
    case 'R': {
      const auto r = control_.submit(proto::SetRun{true});
      if (!refused(r, "ST:RUN")) say("ST:RUN sent");
      break;
    }
    case 'f':
    case 'F': {
      const auto r = control_.submit(proto::SetRun{false});
      if (!refused(r, "ST:STOP")) say("ST:STOP sent");
      break;
    }
    case 'l':
    case 'L':
      release_held(now);
      latched_ = !latched_;
      say(latched_ ? "latched driving: a key starts a direction, the same key or s stops it"
                   : "hold driving: a direction lasts while its key is held");
      break;
    case 'y':
    case 'Y':
      confirm(now);
      break;
    case 'o':
    case 'O':
      toggle_connection(now);
      break;
    case 'h':
    case 'H':
      field_ = Field::host;
      edit_text_ = host_;
      break;
    case 'p':
    case 'P':
      field_ = Field::port;
      edit_text_ = std::to_string(port_);
      break;
    case 'v':
    case 'V':
      field_ = Field::save;
      edit_text_.clear();
      break;
    case key::kPageUp:
      scroll_log(static_cast<long>(kLogPage));
      break;
    case key::kPageDown:
      scroll_log(-static_cast<long>(kLogPage));
      break;
    case key::kHome:
      log_scroll_ = log_.empty() ? 0 : log_.size() - 1;
      break;
    case key::kEnd:
      log_scroll_ = 0;
      break;
    default:
      break;
  }
}

void TuiModel::emergency_stop(Time) {
  held_.reset();
  if (connection_ != ConnectionState::connected) {
    // Nothing can reach the car now; the stop goes out the moment it can.
    estop_pending_ = true;
    say("EMERGENCY STOP: not connected; it is sent as soon as the car is reachable", Style::alert);
    return;
  }
  const auto r = control_.emergency_stop();
  if (r) {
    estop_pending_ = false;
    say("EMERGENCY STOP sent", Style::alert);
  } else {
    estop_pending_ = true;
    say("EMERGENCY STOP not sent (" + refusal_text(r.refusal) + "); retried on connect",
        Style::alert);
  }
}

void TuiModel::direction_key(Time now, Direction direction) {
  if (held_ == direction) {
    if (latched_) {
      release_held(now);
      return;
    }
    // An auto-repeat of the held key: it is still down.
    repeats_seen_ = true;
    release_at_ = now + config_.repeat_window;
    return;
  }
  const auto r = control_.press(direction);
  if (refused(r, "MV:" + std::string(proto::to_string(direction)))) {
    held_.reset();
    return;
  }
  held_ = direction;
  repeats_seen_ = false;
  release_at_ = now + config_.first_repeat_window;
  say("MV:" + std::string(proto::to_string(direction)) + (latched_ ? " (latched)" : " (held)"));
}

void TuiModel::stop_key(Time now) {
  if (held_) {
    release_held(now);
    return;
  }
  const auto r = control_.submit(proto::Move{Direction::stop});
  if (!refused(r, "MV:STOP")) say("MV:STOP sent");
}

void TuiModel::release_held(Time) {
  if (!held_) return;
  held_.reset();
  const auto r = control_.release();
  if (!refused(r, "MV:STOP")) say("released: MV:STOP sent");
}

void TuiModel::edit_key(Time now, int code) {
  if (field_ == Field::save) {
    field_ = Field::none;
    switch (code) {
      case 't':
      case 'T':
        say(control_.save_log(LogFormat::txt));
        break;
      case 'c':
      case 'C':
        say(control_.save_log(LogFormat::csv));
        break;
      case 'n':
      case 'N':
      case 'j':
      case 'J':
        say(control_.save_log(LogFormat::ndjson));
        break;
      default:
        say("log not saved");
        break;
    }
    return;
  }
  if (code == key::kEnter || code == '\r') {
    commit_edit(now);
    return;
  }
  if (code == key::kBackspace || code == 8) {
    if (!edit_text_.empty()) edit_text_.pop_back();
    return;
  }
  if (code < 32 || code > 126) return;
  const char c = static_cast<char>(code);
  switch (field_) {
    case Field::host:
      if (edit_text_.size() < 253) edit_text_ += c;
      break;
    case Field::port:
      if (std::isdigit(static_cast<unsigned char>(c)) != 0 && edit_text_.size() < 5)
        edit_text_ += c;
      break;
    case Field::speed:
      if (std::isdigit(static_cast<unsigned char>(c)) != 0 && edit_text_.size() < 3)
        edit_text_ += c;
      break;
    default:
      break;
  }
}

void TuiModel::commit_edit(Time now) {
  const Field field = std::exchange(field_, Field::none);
  const std::string text = std::exchange(edit_text_, {});
  switch (field) {
    case Field::host:
      if (text.empty()) {
        say("host unchanged: it cannot be empty", Style::warning);
      } else {
        host_ = text;
        say("host " + host_ + " (o connects)");
      }
      break;
    case Field::port: {
      const long value = text.empty() ? 0 : std::stol(text);
      if (value < 1 || value > 65535) {
        say("port unchanged: 1..65535 expected", Style::warning);
      } else {
        port_ = static_cast<std::uint16_t>(value);
        say("port " + std::to_string(port_) + " (o connects)");
      }
      break;
    }
    case Field::speed:
      if (!text.empty()) speed_percent_ = std::clamp(std::stoi(text), 0, 100);
      send_speed(now);
      break;
    default:
      break;
  }
}

void TuiModel::send_speed(Time) {
  const auto r = control_.submit(proto::SetSpeed{speed_percent_});
  if (!refused(r, "SP")) say(payload(proto::SetSpeed{speed_percent_}) + " sent");
}

void TuiModel::toggle_mode(Time now) {
  const Mode target = mode_shown_ == Mode::manual ? Mode::automatic : Mode::manual;
  // Leaving MAN with a direction held would leave the car rolling.
  if (target == Mode::automatic) release_held(now);
  const auto r = control_.submit(proto::SetMode{target});
  if (refused(r, payload(proto::SetMode{target}))) return;
  mode_shown_ = target;
  say(payload(proto::SetMode{target}) + " sent");
}

void TuiModel::toggle_connection(Time now) {
  if (connection_ == ConnectionState::disconnected) {
    control_.connect(host_, port_);
    say("connecting to " + host_ + ":" + std::to_string(port_));
  } else {
    release_held(now);
    control_.disconnect();
    say("disconnected");
  }
}

void TuiModel::confirm(Time) {
  if (confirmable_.empty()) {
    say("nothing awaits confirmation");
    return;
  }
  const Confirmable c = confirmable_.back();
  const auto r = control_.confirm_resend(c.request);
  if (refused(r, c.command)) {
    confirmable_.pop_back();
    return;
  }
  confirmable_.pop_back();
  say(c.command + " sent again");
}

void TuiModel::scroll_log(long delta) {
  const long max_scroll = log_.empty() ? 0 : static_cast<long>(log_.size()) - 1;
  const long next = std::clamp(static_cast<long>(log_scroll_) + delta, 0L, max_scroll);
  log_scroll_ = static_cast<std::size_t>(next);
}

void TuiModel::on_event(Time now, const logi::Event& event) {
  std::visit(
      [&](const auto& e) {
        using E = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<E, logi::ConnectionEvent>) {
          connection_ = e.state;
          reconnect_attempt_ = e.attempt;
          if (e.state != ConnectionState::connected) {
            // The session released it and forgot what awaited confirmation.
            held_.reset();
            confirmable_.clear();
            mode_shown_.reset();
            movement_enabled_ = false;
            movement_reason_ = "not connected";
          } else {
            // Until the session says otherwise (MovementEvent).
            if (!movement_enabled_)
              movement_reason_ = refusal_text(logi::Refusal::mode_speed_unconfirmed);
            if (estop_pending_) emergency_stop(now);
          }
        } else if constexpr (std::is_same_v<E, logi::StatusEvent>) {
          status_ = e.status;
          status_at_ = now;
          stale_ = false;  // a fresh STAT is the end of the stale warning
          mode_shown_ = e.status.mode;
        } else if constexpr (std::is_same_v<E, logi::FeedbackEvent>) {
          // The command's own CommandEvent says more; nothing to add here.
        } else if constexpr (std::is_same_v<E, logi::CommandEvent>) {
          last_command_ = payload(e.command) + " " + std::string(logi::to_string(e.state));
          if (e.state == CommandState::sent && e.attempt > 1)
            last_command_ += " (attempt " + std::to_string(e.attempt) + ")";
          std::erase_if(confirmable_, [&](const Confirmable& c) { return c.request == e.request; });
          if (e.state == CommandState::uncertain) {
            if (e.resend_on_confirm) {
              confirmable_.push_back({e.request, payload(e.command)});
              say(payload(e.command) + " is uncertain (no feedback): y sends it again",
                  Style::warning);
            } else {
              say(payload(e.command) + " is uncertain (no feedback)", Style::warning);
            }
          } else if (e.state == CommandState::rejected) {
            // In AUTO the car refuses the emergency stop's MV:STOP (its ST:STOP
            // stops the run): the emergency stop's message stays.
            const bool estop_mv = e.command == proto::Message{proto::Move{Direction::stop}} &&
                                  message_.style == Style::alert;
            if (!estop_mv) say(payload(e.command) + " rejected by the car", Style::warning);
          }
          // The MD just sent is the mode shown until the next STAT, whether
          // the operator asked for it or the client did (FB:MV:0).
          const auto* md = std::get_if<proto::SetMode>(&e.command);
          if (md != nullptr && e.state == CommandState::sent) mode_shown_ = md->mode;
        } else if constexpr (std::is_same_v<E, logi::StaleEvent>) {
          stale_ = e.stale;
        } else if constexpr (std::is_same_v<E, logi::NoticeEvent>) {
          say(e.text, Style::alert);
        } else if constexpr (std::is_same_v<E, logi::ParseErrorEvent>) {
          say("invalid frame from the car dropped (see the log)", Style::warning);
        } else if constexpr (std::is_same_v<E, logi::MovementEvent>) {
          movement_enabled_ = e.enabled;
          movement_reason_ = connection_ == ConnectionState::connected
                                 ? refusal_text(logi::Refusal::mode_speed_unconfirmed)
                                 : "not connected";
        }
      },
      event);
  finish_quit_if_ready(now);
}

void TuiModel::on_log(const std::vector<logi::LogEntry>& entries) {
  for (const auto& entry : entries) {
    Style style = Style::normal;
    if (entry.kind == logi::LogKind::parse_error) style = Style::warning;
    if (entry.kind == logi::LogKind::note) style = Style::dim;
    log_.push_back({format_log_line(entry), style});
    ++log_total_;
    // A scrolled-back view stays on the lines it shows.
    if (log_scroll_ > 0) ++log_scroll_;
  }
  if (log_.size() > config_.log_lines_kept) {
    const std::size_t drop = log_.size() - config_.log_lines_kept;
    log_.erase(log_.begin(), log_.begin() + static_cast<long>(drop));
  }
  if (!log_.empty()) log_scroll_ = std::min(log_scroll_, log_.size() - 1);
}

void TuiModel::on_time(Time now) {
  if (held_ && !latched_ && now >= release_at_) release_held(now);
  finish_quit_if_ready(now);
}

std::optional<Time> TuiModel::next_wakeup() const {
  std::optional<Time> next;
  if (held_ && !latched_) next = release_at_;
  if (quitting_ && !done_ && (!next || quit_deadline_ < *next)) next = quit_deadline_;
  return next;
}

void TuiModel::quit(Time now) {
  if (quitting_) return;
  quitting_ = true;
  field_ = Field::none;
  held_.reset();
  quit_deadline_ = now + config_.quit_grace;
  if (connection_ == ConnectionState::connected) {
    control_.emergency_stop();
    say("quitting: emergency stop sent, closing", Style::alert);
  } else {
    say("quitting");
  }
  finish_quit_if_ready(now);
}

void TuiModel::finish_quit_if_ready(Time now) {
  if (!quitting_ || done_) return;
  if (connection_ == ConnectionState::connected && control_.busy() && now < quit_deadline_) return;
  control_.disconnect();
  done_ = true;
}

Render TuiModel::render(Time now, std::size_t log_rows) const {
  Render r;
  r.header.text = "LOGI " + host_ + ":" + std::to_string(port_) + "  " +
                  connection_text(connection_, reconnect_attempt_);
  r.header.style = connection_ == ConnectionState::connected ? Style::good : Style::warning;
  if (stale_) {
    r.stale = "STALE: no status from the car for over 2 s";
    if (status_) r.stale->append(" (last " + hil::seconds_text(now - status_at_, 1) + " ago)");
  }

  r.status.title = "Status";
  if (!status_) {
    r.status.lines.push_back({"no STAT received yet", Style::dim});
  } else {
    const proto::Status& s = *status_;
    const Style age = stale_ ? Style::alert : Style::normal;
    char buf[96];
    std::snprintf(buf, sizeof buf, "SP   %3d %%      STA  %03d", s.speed_percent, s.station);
    r.status.lines.push_back({buf, age});
    std::snprintf(buf, sizeof buf, "RUN  %-9s  MODE %s", s.running ? "1 running" : "0 stopped",
                  std::string(proto::to_string(s.mode)).c_str());
    r.status.lines.push_back({buf, age});
    std::snprintf(buf, sizeof buf, "MAN  %-9s  DIS  %d cm",
                  std::string(proto::to_string(s.manual)).c_str(), s.distance_cm);
    r.status.lines.push_back({buf, age});
    std::snprintf(buf, sizeof buf, "TRK  %-9s  DEV  %d", track_text(s.track_mask).c_str(),
                  s.deviation);
    r.status.lines.push_back({buf, age});
    std::snprintf(buf, sizeof buf, "OBS  %s", s.obstacle ? "1 BLOCKED" : "0 clear");
    r.status.lines.push_back({buf, s.obstacle ? Style::alert : age});
    std::snprintf(buf, sizeof buf, "RPM  LR %d LF %d RF %d RR %d", s.rpm[0], s.rpm[1], s.rpm[2],
                  s.rpm[3]);
    r.status.lines.push_back({buf, age});
    for (const auto& [k, v] : s.extra)
      r.status.lines.push_back({pad(k, 5) + v, age});
    r.status.lines.push_back(
        {"updated " + hil::seconds_text(now - status_at_, 1) + " ago", Style::dim});
  }

  r.controls.title = "Controls";
  const std::string mode = mode_shown_ ? std::string(proto::to_string(*mode_shown_)) : "?";
  r.controls.lines.push_back(
      {"Mode    " + pad(mode, 6) + "(m: " + (mode_shown_ == Mode::manual ? "AUTO" : "MAN") + ")",
       Style::bold});
  const int filled = speed_percent_ / 10;
  r.controls.lines.push_back({"Speed   [" + std::string(static_cast<std::size_t>(filled), '#') +
                                  std::string(static_cast<std::size_t>(10 - filled), '.') + "] " +
                                  std::to_string(speed_percent_) + " % Enter sends",
                              Style::normal});
  r.controls.lines.push_back(
      {"Station " + std::string(station_ == 1 ? "001" : "002") + "   (t other, g send)",
       Style::normal});
  std::string drive = std::string("Drive   ") + (latched_ ? "latched" : "hold") + "  ";
  if (held_) {
    drive += "moving " + std::string(proto::to_string(*held_));
  } else {
    drive += "stopped";
  }
  r.controls.lines.push_back({drive, held_ ? Style::good : Style::normal});
  r.controls.lines.push_back(
      {std::string("Motion  ") + (movement_enabled_ ? "enabled" : "off: " + movement_reason_),
       movement_enabled_ ? Style::good : Style::warning});
  if (!last_command_.empty())
    r.controls.lines.push_back({"Last    " + last_command_, Style::normal});
  for (const auto& c : confirmable_)
    r.controls.lines.push_back({"UNCERTAIN " + c.command + ": y sends it again", Style::warning});
  if (estop_pending_)
    r.controls.lines.push_back({"EMERGENCY STOP pending until connected", Style::alert});

  r.log.title = "Log";
  if (log_scroll_ > 0) r.log.title += " (scrolled back " + std::to_string(log_scroll_) + ", End)";
  if (log_rows > 0 && !log_.empty()) {
    const std::size_t end = log_.size() - std::min(log_scroll_, log_.size() - 1);
    const std::size_t begin = end > log_rows ? end - log_rows : 0;
    r.log.lines.assign(log_.begin() + static_cast<long>(begin),
                       log_.begin() + static_cast<long>(end));
  }

  r.message = message_;
  switch (field_) {
    case Field::host:
      r.edit = "Host: " + edit_text_ + "_   (Enter: keep, Esc/Space: cancel + STOP)";
      break;
    case Field::port:
      r.edit = "Port: " + edit_text_ + "_   (Enter: keep, Esc/Space: cancel + STOP)";
      break;
    case Field::speed:
      r.edit = "Speed: " + edit_text_ + "_ %   (Enter: send SP, Esc/Space: cancel + STOP)";
      break;
    case Field::save:
      r.edit = "Save log as: t text, c csv, n ndjson (other key: cancel)";
      break;
    case Field::none:
      break;
  }
  r.help = {
      "Space/Esc EMERGENCY STOP  q w e/a s d/z x c, arrows: drive  [ ] rotate  s stop",
      "l latch  m mode  +/- 0-9 Enter speed  t g station  r run  f stop-run  y resend",
      "o connect  h host  p port  v save log  PgUp/PgDn log  Ctrl-C/F10 quit",
  };
  return r;
}

}  // namespace hil::apps::logi_client
