#include "mocks/leka.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <variant>

#include "protocol/common/overloaded.hpp"

namespace hil::mocks {
namespace {

namespace leka = protocol::leka;
using leka::Rgb;

constexpr Rgb kOff{};
constexpr Rgb kWhite{255, 255, 255};

bool printable_word(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c > 0x20 && c < 0x7F; });
}

const LekaConfig& checked(const LekaConfig& c) {
  const auto positive = [](Duration d) { return d > Duration::zero(); };
  require_config("LekaConfig", positive(c.loop_period), "loop_period must be > 0");
  require_config(
      "LekaConfig",
      c.serial_buffer_bytes >= leka::kOverheadBytes + 1 && c.serial_buffer_bytes <= 261,
      "serial_buffer_bytes must be 7..261, got " + std::to_string(c.serial_buffer_bytes));
  require_config("LekaConfig", printable_word(c.robot_name),
                 "robot_name must be printable ASCII without spaces");
  require_config("LekaConfig", printable_word(c.firmware_version),
                 "firmware_version must be printable ASCII without spaces");
  require_config("LekaConfig", positive(c.motivator_duration), "motivator_duration must be > 0");
  require_config("LekaConfig", positive(c.guidance_duration), "guidance_duration must be > 0");
  require_config("LekaConfig", positive(c.chaser_step), "chaser_step must be > 0");
  require_config("LekaConfig", positive(c.motivator_turn), "motivator_turn must be > 0");
  require_config("LekaConfig", positive(c.guidance_blink), "guidance_blink must be > 0");
  return c;
}

leka::DecoderOptions decoder_options(const LekaConfig& c) {
  leka::DecoderOptions options;
  options.max_frame_bytes = c.serial_buffer_bytes;
  options.limits.max_belt_led_id = c.max_belt_led_id;
  options.accept_out_of_range = c.accept_out_of_range;
  options.dialect = c.dialect;
  return options;
}

// The motivators' colours, in id order; an id outside the table (only
// reachable with accept_out_of_range) shows white.
Rgb motivator_colour(std::uint8_t id) {
  switch (id) {
    case 0x51:
      return {255, 0, 0};
    case 0x52:
      return {0, 255, 0};
    case 0x53:
      return {0, 0, 255};
    case 0x54:
      return {255, 255, 0};
    case 0x55:
      return {255, 0, 255};
    default:
      return kWhite;
  }
}

// Commands that make the wheels turn: the ones the fault state refuses.
bool moves(const leka::Command& c) {
  return std::holds_alternative<leka::MotorAll>(c) || std::holds_alternative<leka::MotorDuo>(c) ||
         std::holds_alternative<leka::MotorLeft>(c) ||
         std::holds_alternative<leka::MotorRight>(c) || std::holds_alternative<leka::Motivator>(c);
}

std::string hex_rgb(const Rgb& c) {
  char text[8];
  std::snprintf(text, sizeof text, "%02X%02X%02X", c.red, c.green, c.blue);
  return text;
}

}  // namespace

LekaFirmware::LekaFirmware(sim::World& world, sim::Vehicle& vehicle, LekaConfig config)
    : FirmwareWith(world, vehicle, "leka", leka::to_string(config.dialect), checked(config)),
      chassis_(differential_chassis_of(vehicle, "LekaFirmware", "use sim::leka_robot()")),
      decoder_(decoder_options(config_)) {
  state_.belt.assign(std::size_t{config_.max_belt_led_id} + 1, kOff);
  base_belt_ = state_.belt;
  chassis_.set_pwm(0, 0);
}

int LekaFirmware::pwm_of(const LekaMotor& motor) const {
  const int max_pwm = chassis_.def().max_pwm;
  const int magnitude = (motor.speed * max_pwm + 127) / 255;
  return motor.spin == leka::kSpinForward ? magnitude : -magnitude;
}

std::string LekaFirmware::info_text() const {
  return "LEKA name=" + config_.robot_name + " firmware=" + config_.firmware_version +
         " buffer=" + std::to_string(config_.serial_buffer_bytes) +
         " state=" + (in_fault() ? "fault" : "ok") + "\r\n";
}

std::string LekaFirmware::summary() const {
  const auto signed_pwm = [this](const LekaMotor& m) {
    const int pwm = pwm_of(m);
    return (pwm < 0 ? "-" : "+") + std::to_string(std::abs(pwm));
  };
  const auto lit =
      std::count_if(state_.belt.begin(), state_.belt.end(), [](const Rgb& c) { return c != kOff; });
  std::string s = "L" + signed_pwm(state_.left) + " R" + signed_pwm(state_.right) + " EARS " +
                  hex_rgb(state_.ears[0]) + " " + hex_rgb(state_.ears[1]) + " BELT " +
                  std::to_string(lit) + "/" + std::to_string(state_.belt.size());
  if (const auto& b = state_.behaviour) {
    char id[8];
    std::snprintf(id, sizeof id, "0x%02X", b->id);
    s += (b->kind == LekaBehaviourKind::motivator ? " MOTIVATOR " : " GUIDANCE ") + std::string(id);
  }
  if (in_fault()) s += " FAULT";
  return s;
}

// ---------------------------------------------------------------- main loop

bool LekaFirmware::busy() const {
  return !serial_.empty() || state_.behaviour.has_value() || pwm_of(state_.left) != 0 ||
         pwm_of(state_.right) != 0 || chassis_.left_speed_mps() != 0 ||
         chassis_.right_speed_mps() != 0;
}

Time LekaFirmware::grid_at_or_after(Time t) const {
  const auto period = config_.loop_period.count();
  const auto k = (t.count() + period - 1) / period;
  return Time(k * period);
}

void LekaFirmware::run_due_passes(Time now, bool include_now) {
  const auto due = [&] { return next_loop_ < now || (include_now && next_loop_ == now); };
  while (due()) {
    if (!busy()) {
      // A pass with nothing to read, play or drive changes nothing, so the
      // idle stretch is skipped (never back to a pass that already ran).
      next_loop_ = std::max(next_loop_, grid_at_or_after(now));
      if (!due()) break;
    }
    run_pass(next_loop_);
    next_loop_ += config_.loop_period;
  }
  state_.serial_buffered = serial_.size() + decoder_.buffered();
}

void LekaFirmware::on_bytes(Time now, ByteView bytes) {
  // Passes that were due before these bytes came drain the buffer first.
  run_due_passes(now, false);
  const std::size_t held = serial_.size() + decoder_.buffered();
  const std::size_t room =
      config_.serial_buffer_bytes > held ? config_.serial_buffer_bytes - held : 0;
  const std::size_t taken = std::min(room, bytes.size());
  serial_.insert(serial_.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(taken));
  state_.counters.bytes_lost += bytes.size() - taken;
  state_.serial_buffered = serial_.size() + decoder_.buffered();
}

void LekaFirmware::on_tick(Time now) {
  run_due_passes(now, true);
}

std::optional<Time> LekaFirmware::next_tick() const {
  if (busy()) return next_loop_;
  return std::nullopt;
}

void LekaFirmware::run_pass(Time at) {
  if (!serial_.empty()) {
    items_.clear();
    decoder_.feed(serial_, items_);
    held_.insert(held_.end(), serial_.begin(), serial_.end());
    serial_.clear();
    held_.erase(held_.begin(), held_.end() - static_cast<std::ptrdiff_t>(decoder_.buffered()));
    // The robot's parser purges its buffer when it holds at least a minimal
    // frame's worth of bytes and no start sequence (the decoder alone would
    // keep them until a start sequence or a full buffer's worth came). Up to
    // three last bytes that may begin a start sequence stay, so a start
    // sequence split across two passes is not lost with the garbage.
    const bool framed =
        held_.size() >= leka::kStartSequence.size() &&
        std::equal(leka::kStartSequence.begin(), leka::kStartSequence.end(), held_.begin());
    if (!framed && held_.size() >= leka::kOverheadBytes + 1) {
      std::size_t keep = leka::kStartSequence.size() - 1;
      while (keep > 0 && !std::equal(held_.end() - static_cast<std::ptrdiff_t>(keep), held_.end(),
                                     leka::kStartSequence.begin()))
        --keep;
      const Bytes tail(held_.end() - static_cast<std::ptrdiff_t>(keep), held_.end());
      decoder_.finish(items_);      // the held bytes come out as one garbage run
      decoder_.feed(tail, items_);  // a start-sequence prefix yields no item
      held_ = tail;
    }
    for (const auto& item : items_)
      handle_item(at, item);
  }
  play_behaviour(at);
}

void LekaFirmware::handle_item(Time at, const leka::Item& item) {
  if (const auto* error = std::get_if<protocol::DecodeError>(&item)) {
    count_bad_frame();
    auto& c = state_.counters;
    switch (error->kind) {
      case protocol::ErrorKind::garbage:
        ++c.garbage;
        break;
      case protocol::ErrorKind::bad_checksum:
        ++c.bad_checksum;
        break;
      case protocol::ErrorKind::oversized:
        ++c.oversized;
        break;
      case protocol::ErrorKind::unknown_code:
        ++c.unknown_code;
        break;
      case protocol::ErrorKind::bad_value:
        ++c.bad_value;
        break;
      default:
        ++c.bad_format;
        break;
    }
    return;
  }
  const auto& frame = std::get<protocol::Frame<leka::Message>>(item);
  count_frame_in();
  if (frame.tolerated) ++state_.counters.tolerated;
  for (const auto& command : frame.message.commands)
    run_command(at, command);
}

void LekaFirmware::run_command(Time at, const Command& command) {
  const std::string_view kind = leka::spec_of(command).name;
  take_command(at, kind, [&] {
    if (in_fault() && moves(command)) {
      ++state_.counters.refused_in_fault;
    } else {
      execute(at, command);
      ++state_.counters.commands_run;
    }
  });
}

void LekaFirmware::execute(Time at, const Command& command) {
  // The master takes over: every command but info ends a behaviour
  // (motivator and guidance replace it with their own).
  if (!std::holds_alternative<leka::Info>(command)) end_behaviour(true);
  const std::size_t belt = base_belt_.size();
  std::visit(
      protocol::Overloaded{
          [&](const leka::Info&) {
            send(info_text());
            ++state_.counters.info_answers;
          },
          [&](const leka::StopLed&) {
            base_ears_.fill(kOff);
            std::fill(base_belt_.begin(), base_belt_.end(), kOff);
            show_base_leds();
          },
          [&](const leka::StopMotor&) { stop_motors(); },
          [&](const leka::StopRobot&) {
            base_ears_.fill(kOff);
            std::fill(base_belt_.begin(), base_belt_.end(), kOff);
            show_base_leds();
            stop_motors();
          },
          [&](const leka::EarAll& c) {
            base_ears_.fill(c.color);
            show_base_leds();
          },
          [&](const leka::EarRange& c) {
            for (std::size_t i = c.first; i <= c.last && i < base_ears_.size(); ++i)
              base_ears_[i] = c.color;
            show_base_leds();
          },
          [&](const leka::EarSingle& c) {
            if (c.led < base_ears_.size()) base_ears_[c.led] = c.color;
            show_base_leds();
          },
          [&](const leka::BeltAll& c) {
            std::fill(base_belt_.begin(), base_belt_.end(), c.color);
            show_base_leds();
          },
          [&](const leka::BeltRange& c) {
            for (std::size_t i = c.first; i <= c.last && i < belt; ++i)
              base_belt_[i] = c.color;
            show_base_leds();
          },
          [&](const leka::BeltSingle& c) {
            if (c.led < belt) base_belt_[c.led] = c.color;
            show_base_leds();
          },
          [&](const leka::MotorAll& c) {
            set_motors({c.direction, c.speed}, {c.direction, c.speed});
          },
          [&](const leka::MotorDuo& c) {
            set_motors({c.left_spin, c.left_speed}, {c.right_spin, c.right_speed});
          },
          [&](const leka::MotorLeft& c) {
            set_motors({c.spin, c.speed}, state_.right);
          },
          [&](const leka::MotorRight& c) {
            set_motors(state_.left, {c.spin, c.speed});
          },
          [&](const leka::Motivator& c) {
            start_behaviour(at, LekaBehaviourKind::motivator, c.id);
          },
          [&](const leka::Guidance& c) { start_behaviour(at, LekaBehaviourKind::guidance, c.id); },
      },
      command);
}

// ---------------------------------------------------------------- outputs

void LekaFirmware::set_motors(LekaMotor left, LekaMotor right) {
  state_.left = left;
  state_.right = right;
  chassis_.set_pwm(pwm_of(left), pwm_of(right));
}

void LekaFirmware::show_base_leds() {
  state_.ears = base_ears_;
  state_.belt = base_belt_;
}

void LekaFirmware::start_behaviour(Time at, LekaBehaviourKind kind, std::uint8_t id) {
  const Duration length =
      kind == LekaBehaviourKind::motivator ? config_.motivator_duration : config_.guidance_duration;
  state_.behaviour = LekaBehaviour{kind, id, at, at + length};
  ++state_.counters.behaviours_started;
  play_behaviour(at);
}

void LekaFirmware::end_behaviour(bool interrupted) {
  if (!state_.behaviour) return;
  const LekaBehaviourKind kind = state_.behaviour->kind;
  state_.behaviour.reset();
  show_base_leds();
  // A motivator leaves the wheels still rather than going back to an old
  // motor command the master may have forgotten.
  if (kind == LekaBehaviourKind::motivator) stop_motors();
  if (interrupted) ++state_.counters.behaviours_interrupted;
}

void LekaFirmware::play_behaviour(Time at) {
  if (!state_.behaviour) return;
  const LekaBehaviour b = *state_.behaviour;
  if (at >= b.ends) {
    end_behaviour(false);
    return;
  }
  const Duration elapsed = at - b.started;
  const std::size_t belt = state_.belt.size();
  if (b.kind == LekaBehaviourKind::motivator) {
    const Rgb colour = motivator_colour(b.id);
    state_.ears.fill(colour);
    std::fill(state_.belt.begin(), state_.belt.end(), kOff);
    state_.belt[static_cast<std::size_t>(elapsed / config_.chaser_step) % belt] = colour;
    // A wiggle on the spot, left first: a celebration that goes nowhere.
    const bool left_turn = (elapsed / config_.motivator_turn) % 2 == 0;
    const LekaMotor back{leka::kSpinBackward, config_.motivator_speed};
    const LekaMotor ahead{leka::kSpinForward, config_.motivator_speed};
    if (left_turn) {
      set_motors(back, ahead);
    } else {
      set_motors(ahead, back);
    }
    return;
  }
  // Guidance shows its number: belt LEDs 0..id-0x41 and both ears blink white.
  const bool on = (elapsed / config_.guidance_blink) % 2 == 0;
  const std::size_t lit = std::min<std::size_t>(b.id > 0x40 ? b.id - 0x40 : 0, belt);
  state_.ears.fill(on ? kWhite : kOff);
  std::fill(state_.belt.begin(), state_.belt.end(), kOff);
  std::fill(state_.belt.begin(), state_.belt.begin() + static_cast<std::ptrdiff_t>(lit),
            on ? kWhite : kOff);
}

// ---------------------------------------------------------------- events

void LekaFirmware::on_disconnect(Time /*now*/) {
  if (!config_.stop_on_disconnect) return;
  end_behaviour(true);
  stop_motors();
}

void LekaFirmware::on_fault(Time /*now*/, bool entered) {
  if (!entered) return;
  if (state_.behaviour && state_.behaviour->kind == LekaBehaviourKind::motivator) {
    end_behaviour(true);
  }
  stop_motors();
}

}  // namespace hil::mocks
