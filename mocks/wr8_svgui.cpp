#include "mocks/wr8_svgui.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <variant>

#include "base/enum_names.hpp"
#include "protocol/common/text.hpp"

namespace hil::mocks {

namespace {

constexpr std::uint8_t kAuthCode = 1;
constexpr std::uint8_t kTaskCode = 3;
constexpr std::uint8_t kSettingsCode = 4;  // v2019 SETTINGS, head SET
constexpr std::uint8_t kSetRequestCode = 6;
constexpr std::uint8_t kControlCode = 10;
/// v2019 checks an AUTH's length byte against this (code and 10 letters).
constexpr std::uint8_t kV2019AuthLength = 11;
/// The loop that follows tasks and the CONTROL watchdog runs this often.
constexpr Duration kLoopPeriod = link::milliseconds(10);
/// A forward task's wheels must gain this much in stall_timeout.
constexpr double kStallProgressM = 0.001;
constexpr Duration kDay = std::chrono::hours(24);

std::int32_t le32_at(ByteView p, std::size_t at) {
  // Bytes past the packet read as 0 (the real v2019 program reads past its
  // buffer there; docs/mocks/wr8.md).
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    const std::uint8_t b = at + k < p.size() ? p[at + k] : 0;
    v |= static_cast<std::uint32_t>(b) << (8 * k);
  }
  return static_cast<std::int32_t>(v);
}

std::string hex_byte(std::uint8_t b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", b);
  return buf;
}

/// The cells of a MAP over the arena: a wall ring when the arena has walls,
/// square cells as small as one MAP packet (127 bytes) allows.
struct MapGrid {
  double cell_m = 1;
  int ring = 0;
  int cols = 0;
  int rows = 0;
};

MapGrid map_grid(const sim::Arena& arena) {
  static constexpr double kCellSizesM[] = {0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5, 10, 20, 50, 100};
  MapGrid grid;
  grid.ring = arena.walls ? 1 : 0;
  for (const double cell : kCellSizesM) {
    const int nx = std::max(1, static_cast<int>(std::ceil(arena.width_m / cell - 1e-9)));
    const int ny = std::max(1, static_cast<int>(std::ceil(arena.height_m / cell - 1e-9)));
    const int cols = nx + 2 * grid.ring;
    const int rows = ny + 2 * grid.ring;
    // code, width, height, the row count, then each row's count and cells
    const int packet = 3 + 4 + rows * (4 + cols);
    if (packet <= static_cast<int>(protocol::wr8::kLongestPrefixedPacket)) {
      grid.cell_m = cell;
      grid.cols = cols;
      grid.rows = rows;
      return grid;
    }
  }
  throw std::invalid_argument("SvguiFirmware: the arena is too large for one MAP packet");
}

bool covers(const sim::Obstacle& obstacle, sim::Vec2 p) {
  if (const auto* box = std::get_if<sim::BoxObstacle>(&obstacle)) {
    const sim::Vec2 local = sim::rotate(
        sim::Vec2{p.x_m - box->center_m.x_m, p.y_m - box->center_m.y_m}, -box->angle_rad);
    return std::abs(local.x_m) <= box->width_m / 2 && std::abs(local.y_m) <= box->height_m / 2;
  }
  const auto& circle = std::get<sim::CircleObstacle>(obstacle);
  return std::hypot(p.x_m - circle.center_m.x_m, p.y_m - circle.center_m.y_m) <= circle.radius_m;
}

/// The profile of the version `config` plays; empty without one (which
/// SvguiConfig::checked() refuses).
std::string_view profile_of_config(const SvguiConfig& config) {
  return config.version ? svgui::profile_of(*config.version) : std::string_view{};
}

}  // namespace

constexpr auto kSvguiTaskNames = base::enum_names<SvguiState::Task>(
    {SvguiState::Task::none, "none"}, {SvguiState::Task::forward, "forward"},
    {SvguiState::Task::wheels, "wheels"}, {SvguiState::Task::signals, "signals"});

std::string_view to_string(SvguiState::Task task) {
  return kSvguiTaskNames.name(task);
}

SvguiConfig SvguiConfig::checked() const {
  constexpr std::string_view kName = "SvguiConfig";
  require_config(kName, version.has_value(), "version must be set (v2019 or head)");
  require_config(kName, !auth_suffix.empty(), "auth_suffix must not be empty");
  require_config(kName, v2019_data_period >= Duration::zero(),
                 "v2019_data_period must not be negative");
  require_config(kName, high_freq_period > Duration::zero(), "high_freq_period must be positive");
  require_config(kName, low_freq_period > Duration::zero(), "low_freq_period must be positive");
  require_config(kName, time_of_day_at_start >= Duration::zero() && time_of_day_at_start < kDay,
                 "time_of_day_at_start must be within 0..24h");
  require_config(kName, std::isfinite(control_max_speed_mps) && control_max_speed_mps > 0,
                 "control_max_speed_mps must be positive");
  require_config(kName, control_timeout >= Duration::zero(),
                 "control_timeout must not be negative");
  require_config(kName, std::isfinite(forward_speed_mps) && forward_speed_mps > 0,
                 "forward_speed_mps must be positive");
  require_config(kName, stall_timeout > Duration::zero(), "stall_timeout must be positive");
  require_config(kName, signals_duration >= Duration::zero(),
                 "signals_duration must not be negative");
  require_config(kName, std::isfinite(servo_center_deg), "servo_center_deg must be finite");
  require_config(kName,
                 std::all_of(head_settings.begin(), head_settings.end(),
                             [](double v) { return std::isfinite(v); }),
                 "head_settings must be finite");
  require_config(kName, std::isfinite(temperature_c), "temperature_c must be finite");
  return *this;
}

SvguiFirmware::SvguiFirmware(sim::World& world, sim::Vehicle& vehicle, SvguiConfig config)
    : FirmwareWith(world, vehicle, "wr8", profile_of_config(config), config.checked()),
      version_(*config_.version),
      chassis_(ackermann_chassis_of(vehicle, "SvguiFirmware", "use sim::wr8_vehicle()")),
      receiver_(version_) {
  (void)map_grid(world.arena());  // an arena no MAP can describe is refused here
  state_.v2019_settings = config_.v2019_settings;
  state_.head_settings = config_.head_settings;
  apply_steering(0);
}

// ---------------------------------------------------------------- telemetry

std::uint32_t SvguiFirmware::timestamp_ms(Time now) const {
  const Duration of_day = (config_.time_of_day_at_start + now) % kDay;
  return static_cast<std::uint32_t>(
      std::chrono::duration_cast<std::chrono::milliseconds>(of_day).count());
}

svgui::Data SvguiFirmware::data_at(Time now) const {
  svgui::Data data;
  data.state = in_fault() ? protocol::wr8::State::fault
               : state_.task == SvguiState::Task::forward || chassis_.speed_mps() != 0
                   ? protocol::wr8::State::run
                   : protocol::wr8::State::wait;
  data.timestamp_ms = timestamp_ms(now);
  data.encoder = static_cast<std::int32_t>(std::lround(vehicle_.odometry().distance_m * 100));
  data.steering = sim::rad_to_deg(chassis_.steering_rad());
  data.motor_battery = static_cast<std::uint32_t>(std::clamp(vehicle_.battery().percent(), 0, 100));
  data.computer_battery = config_.computer_battery_percent;
  return data;
}

svgui::HighFreqData SvguiFirmware::high_freq_at(Time now) const {
  const MapGrid grid = map_grid(world_.arena());
  const sim::Pose pose = vehicle_.pose();
  svgui::HighFreqData data;
  data.timestamp_ms = timestamp_ms(now);
  data.encoder = vehicle_.odometry().distance_m;
  data.steering = sim::rad_to_deg(chassis_.steering_rad());
  // The GUI draws the car at (x, y) cells from the map's top-left corner
  // and turns its picture clockwise by `angle` degrees.
  data.x = grid.ring + pose.x_m / grid.cell_m;
  data.y = grid.ring + (world_.arena().height_m - pose.y_m) / grid.cell_m;
  data.angle = 0.0 - sim::rad_to_deg(pose.heading_rad);  // never -0
  return data;
}

svgui::LowFreqData SvguiFirmware::low_freq_at(Time now) const {
  const svgui::Data d = data_at(now);
  svgui::LowFreqData data;
  data.state = d.state;
  data.timestamp_ms = d.timestamp_ms;
  data.motor_battery = d.motor_battery;
  data.computer_battery = d.computer_battery;
  data.temperature = config_.temperature_c;
  return data;
}

svgui::Map SvguiFirmware::map() const {
  const sim::Arena& arena = world_.arena();
  const MapGrid grid = map_grid(arena);
  svgui::Map map;
  map.width = static_cast<std::int8_t>(grid.cols);
  map.height = static_cast<std::int8_t>(grid.rows);
  constexpr int kSamples = 5;  // per cell side
  for (int row = 0; row < grid.rows; ++row) {
    std::vector<std::int8_t> cells;
    for (int col = 0; col < grid.cols; ++col) {
      const int i = col - grid.ring;
      const int j = row - grid.ring;
      const int nx = grid.cols - 2 * grid.ring;
      const int ny = grid.rows - 2 * grid.ring;
      bool wall = i < 0 || j < 0 || i >= nx || j >= ny;
      for (int s = 0; !wall && s < kSamples * kSamples; ++s) {
        const sim::Vec2 p{(i + (s % kSamples + 0.5) / kSamples) * grid.cell_m,
                          arena.height_m - (j + (s / kSamples + 0.5) / kSamples) * grid.cell_m};
        for (std::size_t o = 0; !wall && o < arena.obstacles.size(); ++o)
          wall = world_.obstacle_present(o) && covers(arena.obstacles[o], p);
      }
      cells.push_back(wall ? 1 : 0);
    }
    map.rows.push_back(std::move(cells));
  }
  return map;
}

std::string SvguiFirmware::summary() const {
  std::string s(svgui::profile_of(version_));
  if (in_fault()) s += " FAULT";
  s += " ODO " + std::to_string(std::lround(vehicle_.odometry().distance_m * 100)) + "cm";
  s += " SP " + protocol::fixed_decimals(chassis_.speed_mps(), 2);
  s += " ANG " + protocol::fixed_decimals(sim::rad_to_deg(chassis_.steering_rad()), 1);
  s += " BAT " + std::to_string(vehicle_.battery().percent()) + "%";
  if (version_ == svgui::Version::v2019) {
    if (state_.current_coi != 0) s += " BUSY COI " + std::to_string(state_.current_coi);
    if (state_.task != SvguiState::Task::none) s += " " + std::string(to_string(state_.task));
  } else if (state_.control) {
    s += " CONTROL " + protocol::fixed_decimals(state_.control->x_axis, 2) + " " +
         protocol::fixed_decimals(state_.control->y_axis, 2);
  }
  return s;
}

// ---------------------------------------------------------------- connection

void SvguiFirmware::on_connect(Time now) {
  receiver_.reset();
  if (version_ == svgui::Version::v2019) {
    if (config_.v2019_data_period > Duration::zero())
      state_.next_data = next_grid_point(now, config_.v2019_data_period);
  } else {
    state_.next_high_freq = next_grid_point(now, config_.high_freq_period);
    state_.next_low_freq = next_grid_point(now, config_.low_freq_period);
  }
}

void SvguiFirmware::on_disconnect(Time /*now*/) {
  // The program keeps no per-connection state but the socket's unread
  // bytes; tasks run on, and the CONTROL watchdog stops a driven car.
  if (receiver_.unread() > 0)
    say("wr8 " + std::string(profile()) + ": " + std::to_string(receiver_.unread()) +
        " byte(s) were never read before the client went away");
  receiver_.reset();
  state_.next_data.reset();
  state_.next_high_freq.reset();
  state_.next_low_freq.reset();
}

void SvguiFirmware::on_fault(Time /*now*/, bool entered) {
  if (!entered) return;
  chassis_.set_speed_target(0);
  state_.control.reset();
  if (state_.task == SvguiState::Task::forward || state_.task == SvguiState::Task::wheels)
    finish_task(0);
}

// ---------------------------------------------------------------- input

void SvguiFirmware::on_bytes(Time now, ByteView bytes) {
  svgui::ReadEvent read;
  if (receiver_.on_arrival(bytes, read)) handle_read(now, read);
}

bool SvguiFirmware::unusable(const std::string& why) {
  ++state_.unusable_reads;
  count_bad_frame();
  say("wr8 " + std::string(profile()) + ": " + why + "; nothing answered");
  return false;
}

void SvguiFirmware::handle_read(Time now, const svgui::ReadEvent& read) {
  if (read.length_mismatch) ++state_.length_mismatches;
  if (read.unreadable_length) {
    unusable("length byte " + hex_byte(read.length_byte) + " cannot be read (0, or 128 and more)");
    return;
  }
  if (read.packet.empty()) {
    unusable("a length byte with no packet after it");
    return;
  }
  const std::uint8_t code = read.packet[0];
  if (code == kAuthCode) {
    handle_auth(now, read);
  } else if (version_ == svgui::Version::v2019) {
    handle_v2019(now, read.packet);
  } else {
    handle_head(now, read.packet);
  }
}

bool SvguiFirmware::handle_auth(Time now, const svgui::ReadEvent& read) {
  if (version_ == svgui::Version::v2019 && read.length_byte != kV2019AuthLength) {
    // v2019 takes a code 1 with another length byte for no packet at all.
    return unusable("AUTH with length byte " + std::to_string(read.length_byte) +
                    " (the v2019 program reads only 11)");
  }
  // The program compares the packet as text: up to its first NUL, a CR LF
  // at the end cut off.
  std::string text(read.packet.begin(), std::find(read.packet.begin(), read.packet.end(), 0));
  if (text.size() >= 2 && text.ends_with("\r\n")) text.resize(text.size() - 2);
  count_frame_in();
  if (!text.ends_with(config_.auth_suffix)) {
    ++state_.refused_logins;
    say("wr8 " + std::string(profile()) +
        ": login not answered (wrong text); the connection stays open");
    frame_handled(now, "AUTH");
    return false;
  }
  take_command(now, "AUTH", [&] {
    ++state_.logins;
    send_message(svgui::kProgramAuthReply);
    if (version_ == svgui::Version::head) {
      send_message(map());
      ++state_.maps_sent;
    }
  });
  return true;
}

void SvguiFirmware::handle_v2019(Time now, ByteView packet) {
  if (packet[0] == kTaskCode) {
    handle_task(now, packet);
  } else if (packet[0] == kSettingsCode) {
    handle_settings(now, packet);
  } else {
    unusable("code " + std::to_string(packet[0]) + " is no packet the v2019 vehicle reads");
  }
}

void SvguiFirmware::handle_task(Time now, ByteView packet) {
  if (packet.size() < 4) {
    unusable("TASK of " + std::to_string(packet.size()) +
             " byte(s): the real program reads past its buffer");
    return;
  }
  const std::uint8_t coi = packet[1];
  const std::uint8_t type = packet[2];
  const std::size_t count = packet[3];
  if (packet.size() < 4 + 4 * count) {
    unusable("TASK declares " + std::to_string(count) + " parameter(s) in " +
             std::to_string(packet.size()) + " bytes: the real program reads past its buffer");
    return;
  }
  std::vector<std::int32_t> params;
  for (std::size_t k = 0; k < count; ++k)
    params.push_back(le32_at(packet, 4 + 4 * k));
  if ((type == 1 || type == 2) && params.empty()) {
    unusable("TASK type " + std::to_string(type) +
             " without a parameter: the real program takes the first of none");
    return;
  }
  count_frame_in();
  // The program takes the COI before it looks at the type: a type it has
  // no action for leaves the car busy with no answer to come.
  run_with_coi(now, "TASK", coi, [&] { start_task(now, type, params); });
}

template <class Run>
void SvguiFirmware::run_with_coi(Time now, std::string_view kind, std::uint8_t coi, Run run) {
  if (state_.current_coi != 0) {
    ++state_.dropped_busy;
    say("wr8 svgui-2019: " + std::string(kind) + " COI " + std::to_string(coi) +
        " dropped: busy with COI " + std::to_string(state_.current_coi));
    return;
  }
  take_command(
      now, kind,
      [&] {
        state_.current_coi = coi;
        run();
      },
      [&] { send_message(svgui::Answer{coi, 0}); });
}

void SvguiFirmware::start_task(Time now, std::uint8_t type,
                               const std::vector<std::int32_t>& params) {
  switch (type) {
    case 1:
      state_.task = SvguiState::Task::forward;
      state_.last_progress = now;
      state_.progress_mark_m = vehicle_.odometry().distance_m;
      chassis_.drive_distance(params[0] / 100.0, config_.forward_speed_mps);
      break;
    case 2:
      state_.task = SvguiState::Task::wheels;
      commanded_wheel_deg_ = params[0];
      apply_steering(commanded_wheel_deg_);
      break;
    case 3:
      state_.task = SvguiState::Task::signals;
      state_.task_until = now + config_.signals_duration;
      break;
    default:
      say("wr8 svgui-2019: TASK type " + std::to_string(type) +
          " has no action; the car stays busy with COI " + std::to_string(state_.current_coi));
      break;
  }
}

void SvguiFirmware::handle_settings(Time now, ByteView packet) {
  if (packet.size() < 2) {
    unusable("SETTINGS of 1 byte: the real program reads past its buffer");
    return;
  }
  count_frame_in();
  const std::uint8_t coi = packet[1];
  if (packet.size() < 21) {
    say("wr8 svgui-2019: SETTINGS of " + std::to_string(packet.size()) +
        " bytes: the program reads its values at bytes 2, 7, 12 and 17, the last past the "
        "packet (read here as 0)");
  }
  // Busy from now on: nothing in the program ends a SETTINGS.
  run_with_coi(now, "SETTINGS", coi, [&] {
    for (std::size_t k = 0; k < 4; ++k)
      state_.v2019_settings[k] = le32_at(packet, 2 + 5 * k);
    apply_steering(commanded_wheel_deg_);
  });
}

void SvguiFirmware::handle_head(Time now, ByteView packet) {
  // The head program acts on SET, SET-REQUEST and CONTROL alone.
  const std::uint8_t code = packet[0];
  const std::string kind = svgui::kind_name(code, version_);
  if (code != kSettingsCode && code != kSetRequestCode && code != kControlCode) {
    unusable("code " + std::to_string(packet[0]) + " is no packet the head vehicle reads");
    return;
  }
  const svgui::Item item = svgui::decode_packet(packet, version_);
  const auto* frame = std::get_if<protocol::Frame<svgui::Message>>(&item);
  if (frame == nullptr) {
    unusable(std::string(kind) + ": " + std::get<protocol::DecodeError>(item).detail);
    return;
  }
  const auto* control = std::get_if<svgui::Control>(&frame->message);
  if (control && (!std::isfinite(control->x_axis) || !std::isfinite(control->y_axis))) {
    unusable("CONTROL with an axis that is not a number");
    return;
  }
  const auto* set = std::get_if<svgui::Set>(&frame->message);
  if (set && !std::all_of(set->values.begin(), set->values.end(),
                          [](double v) { return std::isfinite(v); })) {
    unusable("SET with a value that is not a number");
    return;
  }
  count_frame_in();
  take_command(now, kind, [&] {
    if (set != nullptr) {
      state_.head_settings = set->values;
      apply_steering(commanded_wheel_deg_);
    } else if (std::holds_alternative<svgui::SetRequest>(frame->message)) {
      send_message(svgui::Set{state_.head_settings});
    } else if (control != nullptr) {
      state_.control = *control;
      state_.control_at = now;
      const double limit_deg = sim::rad_to_deg(chassis_.def().max_steering_rad);
      chassis_.set_speed_target(std::clamp(control->y_axis, -1.0, 1.0) *
                                config_.control_max_speed_mps);
      // The GUI's dial turns clockwise for a positive x: a right turn.
      commanded_wheel_deg_ = -std::clamp(control->x_axis, -1.0, 1.0) * limit_deg;
      apply_steering(commanded_wheel_deg_);
    }
  });
}

// ---------------------------------------------------------------- control

double SvguiFirmware::servo_zero_deg() const {
  return version_ == svgui::Version::v2019 ? state_.v2019_settings[3] : state_.head_settings[3];
}

void SvguiFirmware::apply_steering(double wheel_deg) {
  chassis_.set_steering_target(
      sim::deg_to_rad(wheel_deg + servo_zero_deg() - config_.servo_center_deg));
}

void SvguiFirmware::finish_task(std::uint8_t code) {
  send_message(svgui::Answer{state_.current_coi, code});
  state_.current_coi = 0;
  state_.task = SvguiState::Task::none;
}

void SvguiFirmware::task_step(Time now) {
  switch (state_.task) {
    case SvguiState::Task::none:
      return;
    case SvguiState::Task::forward: {
      if (!chassis_.driving_distance()) {
        finish_task(2);
        return;
      }
      const double odometer_m = vehicle_.odometry().distance_m;
      if (std::abs(odometer_m - state_.progress_mark_m) >= kStallProgressM) {
        state_.progress_mark_m = odometer_m;
        state_.last_progress = now;
      } else if (now - state_.last_progress >= config_.stall_timeout) {
        chassis_.set_speed_target(0);
        finish_task(0);
      }
      return;
    }
    case SvguiState::Task::wheels:
      if (std::abs(chassis_.steering_rad() - chassis_.steering_target_rad()) <= 1e-9)
        finish_task(2);
      return;
    case SvguiState::Task::signals:
      if (now >= state_.task_until) finish_task(2);
      return;
  }
}

void SvguiFirmware::control_step(Time now) {
  if (!state_.control || config_.control_timeout == Duration::zero()) return;
  if (now - state_.control_at < config_.control_timeout) return;
  state_.control.reset();
  chassis_.set_speed_target(0);
  say("wr8 svgui-head: no CONTROL for " +
      protocol::fixed_decimals(sim::to_seconds(config_.control_timeout), 3) + " s: the car stops");
}

bool SvguiFirmware::looping() const {
  return state_.task != SvguiState::Task::none || state_.control.has_value();
}

void SvguiFirmware::on_tick(Time now) {
  // Tasks and the watchdog are looked at on the loop's grid, as a car's
  // control loop would.
  if (looping()) {
    if (!state_.next_loop) {
      state_.next_loop = next_grid_point(now, kLoopPeriod);
    } else if (now >= *state_.next_loop) {
      task_step(now);
      control_step(now);
      state_.next_loop = next_grid_point(now, kLoopPeriod);
    }
  }
  if (!looping()) state_.next_loop.reset();

  const auto due = [&](std::optional<Time>& next, Duration period) {
    if (!next || now < *next) return false;
    next = next_grid_point(now, period);
    return !telemetry_muted(now);
  };
  if (due(state_.next_data, config_.v2019_data_period)) {
    send_message(data_at(now));
    ++state_.data_sent;
  }
  if (due(state_.next_high_freq, config_.high_freq_period)) {
    send_message(high_freq_at(now));
    ++state_.data_sent;
  }
  if (due(state_.next_low_freq, config_.low_freq_period)) {
    send_message(low_freq_at(now));
    ++state_.data_sent;
  }
}

std::optional<Time> SvguiFirmware::next_tick() const {
  link::Earliest next;
  for (const auto& due :
       {state_.next_loop, state_.next_data, state_.next_high_freq, state_.next_low_freq})
    next.consider(due);
  return next.time();
}

// ---------------------------------------------------------------- output

void SvguiFirmware::send_message(const svgui::Message& message) {
  // The program writes to every connection; without one nothing goes out.
  if (!connected()) return;
  send(ByteView(svgui::encode_prefixed(message, version_)));
}

void SvguiFirmware::say(const std::string& line) const {
  if (config_.log) config_.log(line);
}

}  // namespace hil::mocks
