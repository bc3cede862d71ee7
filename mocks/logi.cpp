#include "mocks/logi.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "base/enum_names.hpp"
#include "protocol/common/overloaded.hpp"

namespace hil::mocks {

namespace logi = protocol::logi;
using logi::Direction;
using logi::Mode;

namespace {

const LogiConfig& checked(const LogiConfig& c) {
  for (const int s : c.stations)
    require_config("LogiConfig", s >= 0 && s <= 999, "stations must be 0..999");
  require_config("LogiConfig", c.boot_speed_percent >= 0 && c.boot_speed_percent <= 100,
                 "boot_speed_percent must be 0..100");
  require_config("LogiConfig", c.stat_period > Duration::zero(), "stat_period must be positive");
  require_config("LogiConfig", c.control_period > Duration::zero(),
                 "control_period must be positive");
  require_config("LogiConfig", c.boot_offset >= Duration::zero() && c.boot_offset <= c.stat_period,
                 "boot_offset must be 0..stat_period");
  require_config("LogiConfig", c.obstacle_stop_cm >= 0, "obstacle_stop_cm must be >= 0");
  require_config("LogiConfig", c.obstacle_clear_hysteresis_cm >= 0,
                 "obstacle_clear_hysteresis_cm must be >= 0");
  require_config("LogiConfig", c.line_lost_timeout >= Duration::zero(),
                 "line_lost_timeout must be >= 0");
  require_config("LogiConfig", c.steer_gain_radps_per_mps >= 0,
                 "steer_gain_radps_per_mps must be >= 0");
  require_config("LogiConfig", c.strafe_gain >= 0, "strafe_gain must be >= 0");
  return c;
}

std::string three_digits(int value) {
  char text[8];
  std::snprintf(text, sizeof text, "%03d", value);
  return text;
}

bool has_forward_part(Direction d) {
  return d == Direction::fwd || d == Direction::lf || d == Direction::rf;
}

/// Wheel pattern of a manual direction, each wheel -1, 0 or +1 times the
/// wheel speed SP gives, as the firmware drives its four motor PWMs.
sim::MecanumWheels wheel_pattern(Direction d, double w) {
  switch (d) {
    case Direction::stop:
      return {};
    case Direction::fwd:
      return {w, w, w, w};
    case Direction::bwd:
      return {-w, -w, -w, -w};
    case Direction::left:
      return {-w, w, w, -w};
    case Direction::right:
      return {w, -w, -w, w};
    case Direction::lf:
      return {0, w, w, 0};
    case Direction::rf:
      return {w, 0, 0, w};
    case Direction::lb:
      return {-w, 0, 0, -w};
    case Direction::rb:
      return {0, -w, -w, 0};
    case Direction::cw:
      return {w, -w, w, -w};
    case Direction::ccw:
      return {-w, w, -w, w};
  }
  return {};
}

}  // namespace

constexpr auto kLogiRunEndNames = base::enum_names<LogiRunEnd>(
    {LogiRunEnd::none, "none"}, {LogiRunEnd::arrived, "arrived"}, {LogiRunEnd::stopped, "stopped"},
    {LogiRunEnd::line_lost, "line_lost"}, {LogiRunEnd::mode_change, "mode_change"},
    {LogiRunEnd::fault, "fault"}, {LogiRunEnd::disconnect, "disconnect"});

std::string_view to_string(LogiRunEnd end) {
  return kLogiRunEndNames.name(end);
}

LogiFirmware::LogiFirmware(sim::World& world, sim::Vehicle& vehicle, LogiConfig config)
    : FirmwareWith(world, vehicle, "logi", logi::to_string(config.dialect), checked(config)),
      chassis_(mecanum_chassis_of(vehicle, "LogiFirmware")),
      decoder_(
          logi::DecoderOptions{logi::kDefaultMaxFrameBytes, config_.accept_lowercase_checksum}) {
  state_.speed_percent = config_.boot_speed_percent;
  state_.mode = config_.boot_mode;
  read_sensors();
}

std::string LogiFirmware::summary() const {
  std::string s(logi::to_string(state_.mode));
  if (in_fault()) s += " FAULT";
  if (state_.mode == Mode::automatic) {
    s += state_.running ? " RUN STA " : " IDLE STA ";
    s += three_digits(state_.station);
  } else {
    s += ' ';
    s += logi::to_string(state_.manual);
  }
  s += " SP " + std::to_string(state_.speed_percent) + " DIS " + std::to_string(state_.distance_cm);
  if (state_.obstacle) s += " OBS";
  return s;
}

logi::Status LogiFirmware::status() const {
  logi::Status s;
  s.speed_percent = state_.speed_percent;
  s.station = state_.station;
  s.running = state_.running;
  s.mode = state_.mode;
  s.manual = state_.manual;
  s.distance_cm = state_.distance_cm;
  s.track_mask = state_.track_mask;
  s.deviation = state_.deviation;
  s.obstacle = state_.obstacle;
  const auto rpm = chassis_.motor_rpm();
  for (std::size_t i = 0; i < rpm.size(); ++i)
    s.rpm[i] = static_cast<int>(std::lround(rpm[i]));
  return s;
}

// ---------------------------------------------------------------- connection

void LogiFirmware::on_connect(Time now) {
  decoder_ = logi::Decoder(
      logi::DecoderOptions{logi::kDefaultMaxFrameBytes, config_.accept_lowercase_checksum});
  if (config_.grid_from_first_connection && !grid_start_) grid_start_ = now;
  next_stat_ = grid_after(now, config_.stat_period);
}

void LogiFirmware::set_clock_origin(Time at) {
  if (config_.grid_from_first_connection && !grid_start_) grid_start_ = at;
}

void LogiFirmware::on_disconnect(Time) {
  if (!config_.stop_on_disconnect) return;
  if (state_.running) end_run(LogiRunEnd::disconnect);
  state_.manual = Direction::stop;
  state_.obstacle = false;
  apply_motion();
}

// ---------------------------------------------------------------- input

void LogiFirmware::on_bytes(Time now, ByteView bytes) {
  if (bytes.empty()) return;
  items_.clear();
  if (config_.dialect == logi::Dialect::firmware) {
    // The STM32 takes what the Wi-Fi module hands it in one piece as one
    // message: here, one delivery from the link.
    items_.push_back(logi::decode_handover(
        bytes,
        logi::DecoderOptions{logi::kDefaultMaxFrameBytes, config_.accept_lowercase_checksum}));
  } else {
    decoder_.feed(bytes, items_);
  }
  for (const auto& item : items_) {
    if (const auto* frame = std::get_if<protocol::Frame<Message>>(&item)) {
      handle_frame(now, *frame);
    } else {
      handle_error(now, std::get<protocol::DecodeError>(item));
    }
  }
}

void LogiFirmware::handle_frame(Time now, const protocol::Frame<Message>& frame) {
  const auto command = logi::command_of(frame.message);
  if (!command) {
    // STAT and FB are the car's own frames; a client sending them is not
    // speaking the command set.
    count_bad_frame();
    return;
  }
  count_frame_in();
  const std::string kind = logi::kind_of(frame.message);
  take_command(
      now, kind, [&] { answer(*command, execute(now, frame.message)); },
      [&] { answer(*command, false); });
}

void LogiFirmware::handle_error(Time now, const protocol::DecodeError& error) {
  count_bad_frame();
  using protocol::ErrorKind;
  if (error.kind != ErrorKind::bad_format && error.kind != ErrorKind::bad_value) return;
  const auto command = logi::parse_command(error.context);
  if (!command) return;
  // Only a frame that arrived intact (its checksum right, in uppercase) has a
  // payload the car read; anything else is line noise and gets no answer.
  const std::string raw(error.raw.begin(), error.raw.end());
  const std::size_t last_colon = raw.rfind(':');
  if (last_colon == std::string::npos || last_colon < logi::kHeader.size()) return;
  const std::string payload = raw.substr(logi::kHeader.size(), last_colon - logi::kHeader.size());
  if (logi::frame_text(payload) != raw) return;
  const std::string kind(error.context);
  if (dispose(now, kind) != Disposition::ignore) answer(*command, false);
  frame_handled(now, kind);
}

void LogiFirmware::answer(Command command, bool accepted) {
  send(logi::encode_text(logi::Feedback{command, accepted}));
}

bool LogiFirmware::execute(Time now, const Message& command) {
  const bool accepted =
      std::visit(protocol::Overloaded{
                     [&](const logi::SetSpeed& v) {
                       state_.speed_percent = v.percent;
                       return true;
                     },
                     [&](const logi::SetRun& v) {
                       if (v.run) return start_run(now);
                       if (state_.running) end_run(LogiRunEnd::stopped);
                       state_.manual = Direction::stop;
                       return true;
                     },
                     [&](const logi::SetStation& v) { return set_station(v.station); },
                     [&](const logi::SetMode& v) { return set_mode(v.mode); },
                     [&](const logi::Move& v) { return move(v.direction); },
                     [](const auto&) { return false; },
                 },
                 command);
  update_obstacle();
  apply_motion();
  return accepted;
}

bool LogiFirmware::set_station(int station) {
  if (state_.running) return false;
  if (std::find(config_.stations.begin(), config_.stations.end(), station) ==
      config_.stations.end()) {
    return false;
  }
  state_.station = station;
  state_.station_armed = true;
  return true;
}

bool LogiFirmware::start_run(Time now) {
  if (in_fault() || state_.mode != Mode::automatic) return false;
  if (state_.running) return true;
  if (!state_.station_armed) return false;
  state_.running = true;
  state_.line_lost_since.reset();
  read_sensors();
  run_tag_ = state_.tag;
  state_.steer_deviation = state_.deviation;
  if (state_.track_mask == 0) state_.line_lost_since = now;
  return true;
}

bool LogiFirmware::set_mode(Mode mode) {
  if (mode == state_.mode) return true;
  // Switching to manual takes the car over from an auto run; switching to
  // auto stops the manual motion. Either way the car halts first.
  if (state_.running) end_run(LogiRunEnd::mode_change);
  state_.manual = Direction::stop;
  state_.mode = mode;
  return true;
}

bool LogiFirmware::move(Direction direction) {
  if (state_.mode != Mode::manual) return false;
  if (direction != Direction::stop && in_fault()) return false;
  state_.manual = direction;
  return true;
}

void LogiFirmware::end_run(LogiRunEnd why) {
  state_.running = false;
  state_.line_lost_since.reset();
  state_.last_run_end = why;
  if (why == LogiRunEnd::arrived) {
    ++state_.arrivals;
    state_.station_armed = false;
  }
}

void LogiFirmware::on_fault(Time, bool entered) {
  if (!entered) return;
  if (state_.running) end_run(LogiRunEnd::fault);
  state_.manual = Direction::stop;
  state_.obstacle = false;
  apply_motion();
}

// ---------------------------------------------------------------- control

void LogiFirmware::read_sensors() {
  state_.distance_cm = vehicle_.sonar().distance_cm();
  const sim::LineReading line = vehicle_.line_tracker();
  state_.track_mask = line.mask;
  state_.deviation = line.deviation;
  state_.tag = vehicle_.rfid();
}

bool LogiFirmware::lock_applies() const {
  if (in_fault()) return false;
  if (state_.mode == Mode::automatic) return state_.running;
  return has_forward_part(state_.manual);
}

void LogiFirmware::update_obstacle() {
  if (!lock_applies()) {
    state_.obstacle = false;
    return;
  }
  state_.distance_cm = vehicle_.sonar().distance_cm();
  if (state_.obstacle) {
    if (state_.distance_cm >= config_.obstacle_stop_cm + config_.obstacle_clear_hysteresis_cm) {
      state_.obstacle = false;
    }
  } else if (state_.distance_cm < config_.obstacle_stop_cm) {
    state_.obstacle = true;
  }
}

void LogiFirmware::apply_motion() {
  const double w = chassis_.max_wheel_radps() * state_.speed_percent / 100.0;
  if (in_fault() || state_.obstacle) {
    chassis_.stop();
  } else if (state_.mode == Mode::manual) {
    chassis_.set_wheel_targets(wheel_pattern(state_.manual, w));
  } else if (state_.running) {
    // Tape to the right (positive DEV): turn clockwise and slide right.
    const double v = chassis_.speed_for_percent_mps(state_.speed_percent);
    const double dev = state_.steer_deviation;
    chassis_.set_target(
        {v, -config_.strafe_gain * v * dev, -config_.steer_gain_radps_per_mps * v * dev});
  } else {
    chassis_.stop();
  }
}

void LogiFirmware::control(Time now) {
  read_sensors();
  update_obstacle();
  if (state_.running) {
    if (state_.track_mask != 0) {
      state_.steer_deviation = state_.deviation;
      state_.line_lost_since.reset();
    } else if (state_.obstacle || state_.speed_percent == 0) {
      // The timeout counts driving without tape; a car held still is not searching.
      state_.line_lost_since.reset();
    } else {
      if (!state_.line_lost_since) state_.line_lost_since = now;
      if (now - *state_.line_lost_since >= config_.line_lost_timeout) {
        end_run(LogiRunEnd::line_lost);
      }
    }
  }
  // A station counts when the reader comes onto its tag, so a run that
  // starts on the target's tag leaves it and goes round to it again.
  const bool onto_tag = state_.tag && state_.tag != run_tag_;
  run_tag_ = state_.tag;
  if (state_.running && onto_tag && *state_.tag == three_digits(state_.station)) {
    end_run(LogiRunEnd::arrived);
  }
  apply_motion();
}

bool LogiFirmware::active() const {
  if (state_.running) return true;
  if (state_.mode == Mode::manual && state_.manual != Direction::stop) return true;
  const sim::Twist t = chassis_.wheel_twist();
  return t.vx_mps != 0 || t.vy_mps != 0 || t.wz_radps != 0 || chassis_.target() != sim::Twist{};
}

Time LogiFirmware::grid_after(Time now, Duration period) const {
  // Floor division: before the offset, the first grid point is the offset.
  const Time start = grid_start_.value_or(Time(0)) + config_.boot_offset;
  const Duration since = now - start;
  auto ticks = since / period;
  if (since < Duration::zero() && since % period != Duration::zero()) --ticks;
  return start + (ticks + 1) * period;
}

void LogiFirmware::on_tick(Time now) {
  if (now >= next_control_) {
    if (control_scheduled_) control(now);
    next_control_ = grid_after(now, config_.control_period);
  }
  if (connected() && now >= next_stat_) {
    if (!telemetry_muted(next_stat_)) {
      read_sensors();
      send(logi::encode_text(status()));
    }
    next_stat_ = grid_after(now, config_.stat_period);
  }
  control_scheduled_ = active();
}

std::optional<Time> LogiFirmware::next_tick() const {
  std::optional<Time> next;
  if (control_scheduled_) next = next_control_;
  if (connected() && (!next || next_stat_ < *next)) next = next_stat_;
  return next;
}

}  // namespace hil::mocks
