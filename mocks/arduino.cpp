#include "mocks/arduino.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <utility>
#include <variant>

#include "base/enum_names.hpp"
#include "protocol/common/overloaded.hpp"

namespace hil::mocks {
namespace {

namespace arduino = protocol::arduino;

// Longest configurable answer text: keeps every answer inside the board's
// 96-byte frame (12 bytes of framing around it).
constexpr std::size_t kMaxConfigText = 32;

bool field_text(std::string_view text) {
  for (const char c : text) {
    if (!arduino::is_field_char(c)) return false;
  }
  return text.size() <= kMaxConfigText;
}

ArduinoConfig validated(ArduinoConfig config) {
  require_config("ArduinoConfig", config.base_pwm >= 0 && config.base_pwm <= arduino::kMaxPwm,
                 "base_pwm " + std::to_string(config.base_pwm) + " is outside 0..255");
  require_config("ArduinoConfig", config.ms_per_cm > 0 && config.ms_per_cm <= 1000,
                 "ms_per_cm must be in (0, 1000]");
  require_config("ArduinoConfig", config.ms_per_deg > 0 && config.ms_per_deg <= 1000,
                 "ms_per_deg must be in (0, 1000]");
  require_config("ArduinoConfig",
                 config.no_echo_cm >= 0 && config.no_echo_cm <= arduino::kMaxSignedArg,
                 "no_echo_cm must be in 0..32767");
  require_config("ArduinoConfig", field_text(config.ping_reply),
                 "ping_reply must be at most 32 printable characters without ^ $ * |");
  require_config("ArduinoConfig", !config.fault_code.empty() && field_text(config.fault_code),
                 "fault_code must be 1..32 printable characters without ^ $ * |");
  require_config("ArduinoConfig", !config.reject_code.empty() && field_text(config.reject_code),
                 "reject_code must be 1..32 printable characters without ^ $ * |");
  require_config("ArduinoConfig", config.max_frame_bytes >= arduino::kMinFrameBytes,
                 "max_frame_bytes must be at least 10");
  require_config("ArduinoConfig", config.control_period > Duration::zero(),
                 "control_period must be positive");
  return config;
}

arduino::DecoderOptions decoder_options(const ArduinoConfig& config) {
  return arduino::DecoderOptions{.max_frame_bytes = config.max_frame_bytes,
                                 .accept_lowercase_checksum = config.accept_lowercase_checksum};
}

// An idle car reports no motion word.
constexpr auto kArduinoMotionWords =
    base::enum_names<ArduinoMotion>({ArduinoMotion::move, "M"}, {ArduinoMotion::rotate, "R"});

std::string_view motion_word(ArduinoMotion motion) {
  return kArduinoMotionWords.name(motion, "");
}

}  // namespace

ArduinoFirmware::ArduinoFirmware(sim::World& world, sim::Vehicle& vehicle, ArduinoConfig config)
    : FirmwareWith(world, vehicle, "arduino", arduino::to_string(config.dialect),
                   validated(config)),
      chassis_(differential_chassis_of(vehicle, "ArduinoFirmware")),
      decoder_(decoder_options(config_)) {
  boot(world.time());
}

void ArduinoFirmware::boot(Time now) {
  stop_motion();
  state_.pwm = config_.base_pwm;
  ++state_.boots;
  state_.booted_at = now;
  state_.last_seq.reset();
  last_request_.clear();
  last_answer_.clear();
  // The receive buffer does not survive a reset.
  decoder_ = arduino::Decoder(decoder_options(config_));
  sketch_.reset();
}

void ArduinoFirmware::on_connect(Time now) {
  if (config_.reset_on_connect) boot(now);
}

void ArduinoFirmware::on_fault(Time /*now*/, bool entered) {
  if (entered) stop_motion();
}

void ArduinoFirmware::end_due_motion(Time now) {
  if (moving() && now >= state_.motion_ends) stop_motion();
}

void ArduinoFirmware::on_tick(Time now) {
  last_tick_ = now;
  end_due_motion(now);
}

std::optional<Time> ArduinoFirmware::next_tick() const {
  const bool wheels_turning = chassis_.left_pwm() != 0 || chassis_.right_pwm() != 0 ||
                              chassis_.left_speed_mps() != 0 || chassis_.right_speed_mps() != 0;
  if (!moving() && !wheels_turning) return std::nullopt;
  const Duration period = config_.control_period;
  Time next = (last_tick_ / period + 1) * period;
  if (moving() && state_.motion_ends < next) next = state_.motion_ends;
  return next;
}

void ArduinoFirmware::on_bytes(Time now, ByteView bytes) {
  // A request that arrives as the move ends sees it ended, whichever of the
  // two the driver runs first.
  end_due_motion(now);
  if (config_.dialect == arduino::Dialect::firmware) {
    receive_as_sketch(now, bytes);
    return;
  }
  items_.clear();
  decoder_.feed(bytes, items_);
  for (const auto& item : items_) {
    if (const auto* frame = std::get_if<protocol::Frame<Message>>(&item)) {
      count_frame_in();
      handle_frame(now, *frame);
    } else {
      handle_error(std::get<protocol::DecodeError>(item));
    }
  }
  items_.clear();
}

void ArduinoFirmware::handle_frame(Time now, const protocol::Frame<Message>& frame) {
  const Message& request = frame.message;
  const std::string kind(arduino::command_of(request.body));
  take_command(
      now, kind,
      [&] {
        if (config_.repeat_answer_for_repeated_request && !last_request_.empty() &&
            frame.raw == last_request_) {
          send(last_answer_);
          state_.last_seq = request.seq;
        } else {
          answer(Message{request.seq, execute(now, request)});
          last_request_ = frame.raw;
        }
      },
      [&] { answer(Message{request.seq, arduino::nack_from_text(config_.reject_code)}); });
}

void ArduinoFirmware::handle_error(const protocol::DecodeError& error) {
  count_bad_frame();
  // Oversized, cut-short and garbage input never reached the parser as a
  // frame: the board drops it without a word.
  if (const auto nack = arduino::nack_response(error)) answer(*nack);
}

void ArduinoFirmware::answer(const Message& message) {
  last_answer_ = arduino::encode_text(message);
  last_request_.clear();
  state_.last_seq = message.seq;
  send(last_answer_);
}

arduino::Body ArduinoFirmware::execute(Time now, const Message& request) {
  const auto refused = [&]() -> std::optional<arduino::Body> {
    if (in_fault()) return arduino::Body{arduino::nack_from_text(config_.fault_code)};
    return std::nullopt;
  };
  const arduino::Body ok = arduino::Ack{"OK"};
  return std::visit(
      protocol::Overloaded{
          [&](const arduino::Ping&) -> arduino::Body { return arduino::Ack{config_.ping_reply}; },
          [&](const arduino::StatusRequest&) -> arduino::Body {
            return arduino::Ack{status_text(now)};
          },
          [&](const arduino::SetSpeed& v) -> arduino::Body {
            if (auto no = refused()) return *no;
            state_.pwm = v.pwm;
            return arduino::Ack{std::to_string(v.pwm)};
          },
          [&](const arduino::Move& v) -> arduino::Body {
            if (auto no = refused()) return *no;
            start_motion(now, ArduinoMotion::move, v.distance_cm);
            return ok;
          },
          [&](const arduino::Rotate& v) -> arduino::Body {
            if (auto no = refused()) return *no;
            start_motion(now, ArduinoMotion::rotate, v.angle_deg);
            return ok;
          },
          [&](const arduino::Stop&) -> arduino::Body {
            stop_motion();
            return ok;
          },
          [&](const arduino::SonarRead&) -> arduino::Body {
            const sim::SonarReading reading = vehicle_.sonar();
            return arduino::Ack{
                std::to_string(reading.echo ? reading.distance_cm() : config_.no_echo_cm)};
          },
          [&](const arduino::IrRead&) -> arduino::Body { return arduino::Ack{ir_text()}; },
          [&](const arduino::Help&) -> arduino::Body {
            return arduino::Ack{std::string(help_text(config_.dialect))};
          },
          // ACK and NACK are the board's own answers, not requests it knows.
          [&](const arduino::Ack&) -> arduino::Body {
            return arduino::Nack{arduino::NackCode::bad_cmd};
          },
          [&](const arduino::Nack&) -> arduino::Body {
            return arduino::Nack{arduino::NackCode::bad_cmd};
          },
      },
      request.body);
}

void ArduinoFirmware::start_motion(Time now, ArduinoMotion motion, int arg) {
  const double ms_per_unit = motion == ArduinoMotion::move ? config_.ms_per_cm : config_.ms_per_deg;
  // In double: the sketch takes any 32-bit argument, INT_MIN included.
  double ms = std::abs(static_cast<double>(arg)) * ms_per_unit;
  if (config_.scale_duration_with_pwm && state_.pwm > 0) {
    ms = ms * config_.base_pwm / state_.pwm;
  }
  // The sketch keeps the end time in whole milliseconds.
  if (config_.dialect == arduino::Dialect::firmware) ms = std::floor(ms);
  state_.last_dir = motion == ArduinoMotion::move ? (arg >= 0 ? 1 : -1) : 0;
  const Duration duration{std::llround(ms * 1e6)};
  if (duration <= Duration::zero()) {
    // A move of nothing is over as it starts; it still replaces a running one.
    stop_motion();
    return;
  }
  state_.motion = motion;
  state_.motion_arg = arg;
  state_.motion_pwm = state_.pwm;
  state_.motion_started = now;
  state_.motion_ends = now + duration;
  const int duty = arg < 0 ? -state_.pwm : state_.pwm;
  if (motion == ArduinoMotion::move) {
    chassis_.set_pwm(duty, duty);
  } else {
    // Positive turns right (clockwise): the left side drives forward.
    chassis_.set_pwm(duty, -duty);
  }
}

void ArduinoFirmware::stop_motion() {
  chassis_.set_pwm(0, 0);
  state_.last_dir = 0;
  state_.motion = ArduinoMotion::idle;
  state_.motion_arg = 0;
  state_.motion_pwm = 0;
}

std::string ArduinoFirmware::status_text(Time now) const {
  if (config_.dialect == arduino::Dialect::firmware) return sketch_status(now);
  std::string text = activity() + " PWM=" + std::to_string(state_.pwm);
  if (moving()) {
    // Rounded up, so a running move never shows 0 ms left.
    const auto left = state_.motion_ends - now;
    const auto left_ms = (left + link::milliseconds(1) - Duration(1)) / link::milliseconds(1);
    text += " REM_MS=" + std::to_string(left_ms);
  }
  // millis() on the board: milliseconds since the boot, wrapping at 2^32.
  const auto up_ms = static_cast<std::uint32_t>((now - state_.booted_at) / link::milliseconds(1));
  text += " UP_MS=" + std::to_string(up_ms);
  text += " BAT_MV=" + std::to_string(std::lround(vehicle_.battery().voltage_v * 1000));
  return text;
}

std::string_view ArduinoFirmware::help_text(arduino::Dialect dialect) {
  if (dialect == arduino::Dialect::firmware) return "CMDS:PING,HELP,STATUS,V,M,R,S,B,I";
  return "PING STATUS V<pwm> M<cm> R<deg> S B I HELP";
}

std::string ArduinoFirmware::ir_text() const {
  const sim::IrReading ir = vehicle_.ir();
  return "L=" + std::to_string(ir.left_analog) + "," + (ir.left_obstacle ? "1" : "0") +
         " R=" + std::to_string(ir.right_analog) + "," + (ir.right_obstacle ? "1" : "0");
}

std::string ArduinoFirmware::activity() const {
  if (in_fault()) return "FAULT";
  if (moving()) {
    return "MOVING " + std::string(motion_word(state_.motion)) + ":" +
           std::to_string(state_.motion_arg);
  }
  return "IDLE";
}

std::string ArduinoFirmware::summary() const {
  return activity() + " PWM " + std::to_string(state_.pwm);
}

}  // namespace hil::mocks
