#include "mocks/wr8.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "base/duration.hpp"
#include "base/enum_names.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::mocks {

namespace wr8 = protocol::wr8;

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

wr8::DecoderOptions decoder_options(const Wr8Config& config) {
  wr8::DecoderOptions options;
  options.profile = config.profile;
  options.sender = wr8::Sender::gui;
  options.max_packet_bytes = config.max_packet_bytes;
  return options;
}

/// A parameter's bits as the number the profile says they carry.
double value_of(wr8::Word w, wr8::ValueType type) {
  switch (type) {
    case wr8::ValueType::signed_int:
      return w.as_i32();
    case wr8::ValueType::unsigned_int:
      return w.bits;
    case wr8::ValueType::float32:
      return static_cast<double>(w.as_f32());
  }
  return std::numeric_limits<double>::quiet_NaN();
}

/// A number as bits of `size_bytes` presented as `type`; whole-number types
/// round and saturate, as a firmware's integer conversion of a reading would.
wr8::Word word_of(double value, wr8::ValueType type, std::size_t size_bytes = 4) {
  if (type == wr8::ValueType::float32) return wr8::Word::from_f32(static_cast<float>(value));
  const int bits = static_cast<int>(size_bytes) * 8;
  const double rounded = std::round(value);
  if (type == wr8::ValueType::unsigned_int) {
    const double top = std::ldexp(1.0, bits) - 1;
    return wr8::Word::from_u32(static_cast<std::uint32_t>(std::clamp(rounded, 0.0, top)));
  }
  const double top = std::ldexp(1.0, bits - 1) - 1;
  const auto v = static_cast<std::int64_t>(std::clamp(rounded, -top - 1, top));
  const std::uint32_t mask = bits >= 32 ? 0xFFFFFFFFu : ((1u << bits) - 1u);
  return wr8::Word{static_cast<std::uint32_t>(v) & mask};
}

}  // namespace

Duration wrong_auth_delay(const Wr8Config& config, std::uint64_t failures_in_a_row) {
  Duration delay = config.wrong_auth_close_delay;
  for (std::uint64_t n = 1; n < failures_in_a_row && delay < config.wrong_auth_max_delay; ++n)
    delay *= 2;
  return std::min(delay, config.wrong_auth_max_delay);
}

constexpr auto kWr8SessionNames = base::enum_names<Wr8Session>(
    {Wr8Session::unauthenticated, "unauthenticated"}, {Wr8Session::authenticated, "authenticated"},
    {Wr8Session::refused, "refused"});

std::string_view to_string(Wr8Session session) {
  return kWr8SessionNames.name(session);
}

Wr8Firmware::Wr8Firmware(sim::World& world, sim::Vehicle& vehicle, Wr8Config config)
    : FirmwareWith(world, vehicle, "wr8", {}, std::move(config)),
      chassis_(ackermann_chassis_of(vehicle, "Wr8Firmware", "use sim::wr8_vehicle()")),
      decoder_(decoder_options(config_)) {
  require_config("Wr8Config", config_.data_period > Duration::zero(),
                 "data_period must be positive");
  require_config("Wr8Config", config_.control_period > Duration::zero(),
                 "control_period must be positive");
  require_config("Wr8Config", config_.wrong_auth_close_delay >= Duration::zero(),
                 "wrong_auth_close_delay must not be negative");
  require_config("Wr8Config", config_.wrong_auth_max_delay >= config_.wrong_auth_close_delay,
                 "wrong_auth_max_delay must not be below wrong_auth_close_delay");
  require_config("Wr8Config", config_.stall_timeout > Duration::zero(),
                 "stall_timeout must be positive");
  require_config("Wr8Config", config_.blink_duration >= Duration::zero(),
                 "blink_duration must not be negative");
  require_config("Wr8Config", config_.drive_max_speed_mps > 0,
                 "drive_max_speed_mps must be positive");
  require_config("Wr8Config",
                 config_.drive_min_speed_mps >= 0 &&
                     config_.drive_min_speed_mps <= config_.drive_max_speed_mps,
                 "drive_min_speed_mps must be within 0..drive_max_speed_mps");
  require_config("Wr8Config", config_.max_drive_cm > 0, "max_drive_cm must be positive");
  require_config("Wr8Config", config_.stall_progress_m > 0, "stall_progress_m must be positive");
  require_config("Wr8Config", config_.servo_min_deg <= config_.servo_max_deg,
                 "servo_min_deg above servo_max_deg");
  require_config("Wr8Config", config_.max_gain >= 0, "max_gain must not be negative");
  const auto gain_ok = [&](double g) {
    return std::isfinite(g) && g >= 0 && g <= config_.max_gain;
  };
  require_config("Wr8Config", gain_ok(config_.p) && gain_ok(config_.i) && gain_ok(config_.d),
                 "p, i and d must be within 0..max_gain");
  require_config("Wr8Config",
                 config_.servo_zero_deg >= config_.servo_min_deg &&
                     config_.servo_zero_deg <= config_.servo_max_deg,
                 "servo_zero_deg must be within servo_min_deg..servo_max_deg");

  const auto& types = config_.profile.setting_value_type;
  const double initial[wr8::kSettingCount] = {config_.p, config_.i, config_.d,
                                              config_.servo_zero_deg};
  for (const wr8::SettingCode code : wr8::kAllSettingCodes) {
    const auto at = static_cast<std::size_t>(code);
    state_.settings.push_back(wr8::Setting{code, word_of(initial[at], types[at])});
  }
  // The numbers in force are what the bits say, so get-settings and the
  // controller never disagree (an int32 servo zero drops a fraction).
  state_.p = value_of(state_.settings[0].value, types[0]);
  state_.i = value_of(state_.settings[1].value, types[1]);
  state_.d = value_of(state_.settings[2].value, types[2]);
  state_.servo_zero_deg = value_of(state_.settings[3].value, types[3]);
  apply_steering();
}

// ---------------------------------------------------------------- state

wr8::State Wr8Firmware::state_code() const {
  if (in_fault()) return wr8::State::fault;
  if (state_.drive || state_.turn) return wr8::State::run;
  if (state_.blink) return wr8::State::wait;
  return wr8::State::stop;
}

wr8::Data Wr8Firmware::data_at(Time now) const {
  wr8::Data data;
  data.state = state_code();
  data.timestamp_ms = static_cast<std::uint32_t>(
      static_cast<std::uint64_t>(std::chrono::duration_cast<link::milliseconds>(now).count()));
  for (const wr8::DataParameter& row : config_.profile.data_parameters) {
    double value = 0;
    switch (row.code) {
      case wr8::data_code::odometry:
        value = vehicle_.odometry().distance_m * 100;
        break;
      case wr8::data_code::speed:
        value = chassis_.speed_mps();
        break;
      case wr8::data_code::wheel_angle:
        value = chassis_.steering_rad() * kDegPerRad;
        break;
      case wr8::data_code::battery:
        value = std::clamp(vehicle_.battery().percent(), 0, 100);
        break;
      default:
        continue;  // a parameter this vehicle does not measure
    }
    data.values.push_back(wr8::DataValue{row.code, word_of(value, row.type, row.size_bytes)});
  }
  return data;
}

std::string Wr8Firmware::summary() const {
  std::string s(wr8::to_string(state_code()));
  if (state_.session != Wr8Session::authenticated)
    s += " " + std::string(to_string(state_.session));
  if (state_.auth_failures > 0) s += " AUTH FAILED " + std::to_string(state_.auth_failures);
  s += " ODO " + std::to_string(std::lround(vehicle_.odometry().distance_m * 100)) + "cm";
  s += " SP " + protocol::fixed_decimals(chassis_.speed_mps(), 2);
  s += " ANG " + protocol::fixed_decimals(chassis_.steering_rad() * kDegPerRad, 1);
  s += " BAT " + std::to_string(vehicle_.battery().percent()) + "%";
  if (state_.drive) {
    s += " DRIVE " + std::to_string(std::lround(state_.drive->covered_m * 100)) + "/" +
         std::to_string(std::lround(state_.drive->target_m * 100)) + "cm";
  }
  if (state_.turn) s += " TURN " + protocol::fixed_decimals(state_.turn->angle_deg, 0);
  if (state_.blink) s += " BLINK";
  return s;
}

// ---------------------------------------------------------------- connection

void Wr8Firmware::on_connect(Time /*now*/) {
  state_.session = Wr8Session::unauthenticated;
  state_.dropped_this_connection = 0;
  state_.close_at.reset();
  state_.next_data.reset();
  decoder_ = wr8::Decoder(decoder_options(config_));
}

void Wr8Firmware::on_disconnect(Time /*now*/) {
  // A packet cut off by the hang-up is still a bad packet.
  items_.clear();
  decoder_.finish(items_);
  for (std::size_t n = 0; n < items_.size(); ++n)
    count_bad_frame();
  decoder_ = wr8::Decoder(decoder_options(config_));
  if (state_.dropped_this_connection > 0) {
    say("wr8: " + std::to_string(state_.dropped_this_connection) +
        " packet(s) from this client dropped unanswered before a login (" +
        std::to_string(state_.dropped_unauthenticated) + " in all)");
  }
  state_.dropped_this_connection = 0;
  // Nobody is left to watch the car: a safe firmware stops it.
  if (config_.stop_on_disconnect) {
    abort_tasks(false);
    stop_motion();
  }
  state_.session = Wr8Session::unauthenticated;
  state_.close_at.reset();
  state_.next_data.reset();
}

void Wr8Firmware::on_fault(Time /*now*/, bool entered) {
  if (!entered) return;
  abort_tasks(true);
  stop_motion();
}

// ---------------------------------------------------------------- input

void Wr8Firmware::on_bytes(Time now, ByteView bytes) {
  items_.clear();
  decoder_.feed(bytes, items_);
  // Handling may send, so work on a copy of the list the decoder filled.
  const std::vector<wr8::Item> items = std::move(items_);
  items_.clear();
  for (const wr8::Item& item : items)
    handle_item(now, item);
}

void Wr8Firmware::handle_item(Time now, const wr8::Item& item) {
  if (const auto* error = std::get_if<protocol::DecodeError>(&item)) {
    handle_bad(now, *error);
    return;
  }
  const Message& message = std::get<protocol::Frame<Message>>(item).message;
  count_frame_in();
  const bool is_auth = std::holds_alternative<wr8::Auth>(message);
  if (state_.session == Wr8Session::refused ||
      (state_.session == Wr8Session::unauthenticated && !is_auth)) {
    ++state_.dropped_unauthenticated;
    ++state_.dropped_this_connection;
    return;
  }
  const std::string kind(wr8::to_string(wr8::code_of(message)));
  take_command(
      now, kind, [&] { handle(now, message); }, [&] { reject(now, message); });
}

void Wr8Firmware::handle_bad(Time now, const protocol::DecodeError& error) {
  count_bad_frame();
  if (state_.session != Wr8Session::authenticated) return;
  // A whole TASK or SETTINGS whose fields the vehicle cannot use (a wrong
  // parameter count, an unknown task or setting type) still names its COI:
  // answer it with error, as for a bad value. Runs of stray bytes and
  // pieces of oversized packets carry no request to answer.
  const bool whole = error.kind == protocol::ErrorKind::bad_format ||
                     error.kind == protocol::ErrorKind::unknown_code ||
                     error.kind == protocol::ErrorKind::bad_value;
  if (!whole || error.raw.size() < 2) return;
  const auto code = static_cast<wr8::PacketCode>(error.raw[0]);
  if (code != wr8::PacketCode::task && code != wr8::PacketCode::settings) return;
  const std::string kind(wr8::to_string(code));
  if (dispose(now, kind) != Disposition::ignore) {
    if (code == wr8::PacketCode::task) {
      task_failed(error.raw[1]);
    } else {
      respond(error.raw[1], wr8::ResponseCode::error);
    }
  }
  frame_handled(now, kind);
}

void Wr8Firmware::handle(Time now, const Message& message) {
  std::visit(protocol::Overloaded{
                 [](const wr8::Empty&) {},  // keepalive
                 [&](const wr8::Auth& a) { handle_auth(now, a); },
                 [&](const wr8::Task& t) { handle_task(now, t); },
                 [&](const wr8::Settings& s) { handle_settings(now, s); },
                 [](const auto&) {},  // vehicle-side packets never get past the decoder
             },
             message);
}

void Wr8Firmware::reject(Time now, const Message& message) {
  std::visit(protocol::Overloaded{
                 [](const wr8::Empty&) {},
                 // AUTH has no negative answer: a refused login is a wrong one.
                 [&](const wr8::Auth&) { refuse(now); },
                 [&](const wr8::Task& t) { task_failed(t.coi); },
                 [&](const wr8::Settings& s) { respond(s.coi, wr8::ResponseCode::error); },
                 [](const auto&) {},
             },
             message);
}

void Wr8Firmware::handle_auth(Time now, const wr8::Auth& auth) {
  if (auth.text != config_.profile.auth_text) {
    refuse(now);
    return;
  }
  if (state_.session != Wr8Session::authenticated) {
    state_.session = Wr8Session::authenticated;
    state_.next_data = next_grid_point(now, config_.data_period);
    if (state_.auth_failures_in_a_row > 0) {
      say("wr8: login accepted after " + std::to_string(state_.auth_failures_in_a_row) +
          " failed login(s) in a row");
    }
    state_.auth_failures_in_a_row = 0;
  }
  answer(wr8::AuthReply{config_.device_code, config_.device_id, state_code()});
}

void Wr8Firmware::refuse(Time now) {
  ++state_.auth_failures;
  ++state_.auth_failures_in_a_row;
  state_.session = Wr8Session::refused;
  state_.next_data.reset();
  if (state_.close_at) return;  // a refusal already runs its delay
  const Duration delay = wrong_auth_delay(config_, state_.auth_failures_in_a_row);
  state_.close_at = now + delay;
  // The string tried is never written anywhere a person reads: it may be
  // the real one with a typo.
  say("wr8: login refused (AUTH **********): failed login " +
      std::to_string(state_.auth_failures_in_a_row) + " in a row, " +
      std::to_string(state_.auth_failures) + " in all; closing the connection in " +
      hil::seconds_text(delay, 3) + ", nothing answered until then");
}

void Wr8Firmware::say(const std::string& line) const {
  if (config_.log) config_.log(line);
}

void Wr8Firmware::handle_task(Time now, const wr8::Task& task) {
  const auto t = static_cast<std::size_t>(task.task);
  static constexpr std::size_t kParams[wr8::kTaskCount] = {0, 1, 1, 0, 0};
  if (in_fault() || task.params.size() != kParams[t]) {
    task_failed(task.coi);
    return;
  }
  const double value =
      task.params.empty() ? 0.0 : value_of(task.params[0], config_.profile.task_value_type[t]);
  const bool moving = state_.drive || state_.turn;
  switch (task.task) {
    case wr8::TaskCode::check:
      task_completed(task.coi);
      return;
    case wr8::TaskCode::drive: {
      if (moving || !std::isfinite(value) || value <= 0 || value > config_.max_drive_cm) {
        task_failed(task.coi);
        return;
      }
      Wr8State::Drive drive;
      drive.coi = task.coi;
      drive.target_m = value / 100;
      drive.start_odometer_m = vehicle_.odometry().distance_m;
      drive.started = now;
      drive.last_progress = now;
      state_.drive = drive;
      respond(task.coi, wr8::ResponseCode::started);
      return;
    }
    case wr8::TaskCode::turn: {
      const double limit_deg = chassis_.def().max_steering_rad * kDegPerRad;
      if (moving || !std::isfinite(value) || std::abs(value) > limit_deg + 1e-9) {
        task_failed(task.coi);
        return;
      }
      state_.commanded_wheel_angle_deg = value;
      state_.turn = Wr8State::Turn{task.coi, value};
      apply_steering();
      respond(task.coi, wr8::ResponseCode::started);
      return;
    }
    case wr8::TaskCode::blink:
      if (state_.blink) {
        task_failed(task.coi);
        return;
      }
      state_.blink = Wr8State::Blink{task.coi, now + config_.blink_duration};
      respond(task.coi, wr8::ResponseCode::started);
      return;
    case wr8::TaskCode::get_settings:
      answer(wr8::Settings{task.coi, state_.settings});
      task_completed(task.coi);
      return;
  }
  task_failed(task.coi);
}

void Wr8Firmware::handle_settings(Time /*now*/, const wr8::Settings& settings) {
  // All or nothing: one bad entry leaves every setting as it was.
  std::vector<wr8::Setting> next = state_.settings;
  double values[wr8::kSettingCount] = {state_.p, state_.i, state_.d, state_.servo_zero_deg};
  for (const wr8::Setting& s : settings.params) {
    const auto at = static_cast<std::size_t>(s.code);
    const double v = value_of(s.value, config_.profile.setting_value_type[at]);
    const bool ok =
        s.code == wr8::SettingCode::servo_zero
            ? std::isfinite(v) && v >= config_.servo_min_deg && v <= config_.servo_max_deg
            : std::isfinite(v) && v >= 0 && v <= config_.max_gain;
    if (!ok) {
      respond(settings.coi, wr8::ResponseCode::error);
      return;
    }
    next[at] = s;
    values[at] = v;
  }
  state_.settings = std::move(next);
  state_.p = values[0];
  state_.i = values[1];
  state_.d = values[2];
  state_.servo_zero_deg = values[3];
  apply_steering();
  respond(settings.coi, wr8::ResponseCode::completed);
}

// ---------------------------------------------------------------- control

void Wr8Firmware::apply_steering() {
  // The servo goes to servo zero + the commanded angle; the wheels sit
  // straight at the mechanical centre, so any difference turns them.
  const double wheel_deg = state_.commanded_wheel_angle_deg + servo_offset_deg();
  chassis_.set_steering_target(wheel_deg / kDegPerRad);
}

void Wr8Firmware::stop_motion() {
  chassis_.set_speed_target(0);
}

void Wr8Firmware::abort_tasks(bool answer_error) {
  if (answer_error) {
    if (state_.drive) task_failed(state_.drive->coi);
    if (state_.turn) task_failed(state_.turn->coi);
    if (state_.blink) task_failed(state_.blink->coi);
  }
  state_.drive.reset();
  state_.turn.reset();
  state_.blink.reset();
}

bool Wr8Firmware::control_needed() const {
  return state_.drive || state_.turn || chassis_.speed_mps() != 0 ||
         chassis_.steering_rad() != chassis_.steering_target_rad();
}

void Wr8Firmware::control_step(Time now) {
  if (state_.drive) drive_step(now);
  if (state_.turn && std::abs(chassis_.steering_rad() - chassis_.steering_target_rad()) <= 1e-9) {
    const std::uint8_t coi = state_.turn->coi;
    state_.turn.reset();
    task_completed(coi);
  }
}

void Wr8Firmware::drive_step(Time now) {
  Wr8State::Drive& drive = *state_.drive;
  drive.covered_m = vehicle_.odometry().distance_m - drive.start_odometer_m;
  if (drive.covered_m >= drive.target_m) {
    const std::uint8_t coi = drive.coi;
    state_.drive.reset();
    stop_motion();
    task_completed(coi);
    return;
  }
  if (drive.covered_m - drive.progress_mark_m >= config_.stall_progress_m) {
    drive.progress_mark_m = drive.covered_m;
    drive.last_progress = now;
  }
  if (now - drive.last_progress >= config_.stall_timeout) {
    const std::uint8_t coi = drive.coi;
    state_.drive.reset();
    stop_motion();
    task_failed(coi);
    return;
  }
  // PID on the distance still to go, at the loop's fixed rate as a
  // microcontroller runs it.
  const double dt_s = sim::to_seconds(config_.control_period);
  const double error_m = drive.target_m - drive.covered_m;
  const double derivative = drive.has_last_error ? (error_m - drive.last_error_m) / dt_s : 0.0;
  const double integral = drive.integral_m_s + error_m * dt_s;
  double command = state_.p * error_m + state_.i * integral + state_.d * derivative;
  // Integrate only while the output is not saturated, so a long drive does
  // not wind the integral up and overshoot at the end.
  if (command <= config_.drive_max_speed_mps) drive.integral_m_s = integral;
  drive.last_error_m = error_m;
  drive.has_last_error = true;
  command = std::clamp(command, 0.0, config_.drive_max_speed_mps);
  if (command > 0) command = std::max(command, config_.drive_min_speed_mps);
  drive.speed_command_mps = command;
  chassis_.set_speed_target(command);
}

void Wr8Firmware::on_tick(Time now) {
  if (state_.close_at && now >= *state_.close_at) {
    state_.close_at.reset();
    request_close(link::CloseMode::graceful);
  }

  if (control_needed()) {
    if (!state_.next_control) {
      state_.next_control = next_grid_point(now, config_.control_period);
    } else if (now >= *state_.next_control) {
      control_step(now);
      state_.next_control = next_grid_point(now, config_.control_period);
    }
  }
  if (!control_needed()) state_.next_control.reset();

  if (state_.blink && now >= state_.blink->until) {
    const std::uint8_t coi = state_.blink->coi;
    state_.blink.reset();
    task_completed(coi);
  }

  if (state_.session == Wr8Session::authenticated && state_.next_data && now >= *state_.next_data) {
    if (!telemetry_muted(now)) {
      answer(data_at(now));
      ++state_.data_sent;
    }
    state_.next_data = next_grid_point(now, config_.data_period);
  }
}

std::optional<Time> Wr8Firmware::next_tick() const {
  link::Earliest next;
  next.consider(state_.close_at);
  next.consider(state_.next_control);
  if (state_.blink) next.consider(state_.blink->until);
  if (state_.session == Wr8Session::authenticated) next.consider(state_.next_data);
  return next.time();
}

// ---------------------------------------------------------------- output

void Wr8Firmware::answer(const Message& message) {
  if (state_.session != Wr8Session::authenticated) return;
  send(ByteView(wr8::encode(message, config_.profile)));
}

void Wr8Firmware::respond(std::uint8_t coi, wr8::ResponseCode code) {
  answer(wr8::Response{coi, code});
}

void Wr8Firmware::task_failed(std::uint8_t coi) {
  ++state_.tasks_failed;
  respond(coi, wr8::ResponseCode::error);
}

void Wr8Firmware::task_completed(std::uint8_t coi) {
  ++state_.tasks_completed;
  respond(coi, wr8::ResponseCode::completed);
}

}  // namespace hil::mocks
