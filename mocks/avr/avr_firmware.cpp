#include "mocks/avr/avr_firmware.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "protocol/common/car_profile.hpp"
#include "sim/differential.hpp"

namespace hil::mocks {

namespace {

constexpr std::uint64_t kCyclesPerMicrosecond = avr::Chip::kFrequencyHz / 1'000'000;

// Cycles in `d`: the 16 MHz clock is 16 cycles per microsecond, so a
// nanosecond count maps exactly (62.5 ns a cycle), rounding down.
std::uint64_t cycles_in(Duration d) {
  return static_cast<std::uint64_t>(d.count()) * kCyclesPerMicrosecond / 1000;
}

// The signed duty of one motor channel: its PWM pin's duty, forward while
// only FWD is high, backward while only REV is.
int side_duty(const avr::Chip& chip, const avr::MotorPins& motor) {
  const bool fwd = chip.output_level(motor.forward);
  const bool rev = chip.output_level(motor.reverse);
  if (fwd == rev) return 0;
  const int duty = chip.pwm_duty(motor.pwm);
  return fwd ? duty : -duty;
}

// A millivolt level whose 10-bit conversion at AVCC 5,000 mV reads `value`.
std::uint32_t millivolts_for(int value) {
  const int v = std::clamp(value, 0, 1023);
  return static_cast<std::uint32_t>((v * 5000 + 1022) / 1023);
}

}  // namespace

AvrConfig AvrConfig::checked() const {
  constexpr std::string_view kName = "AvrConfig";
  require_config(kName, !elf.empty(), "elf: no firmware image given");
  avr::check_elf(elf);
  avr::check_pin_map(pins);
  require_config(kName, protocol::car_profile_problem("arduino", profile).empty(),
                 "profile: " + protocol::car_profile_problem("arduino", profile));
  require_config(kName, startup_delay >= Duration{0} && startup_delay <= std::chrono::seconds(10),
                 "startup_delay must be 0..10 s");
  require_config(kName,
                 step >= std::chrono::microseconds(10) && step <= std::chrono::milliseconds(10),
                 "step must be 10 us..10 ms");
  require_config(kName, sensor_period >= step && sensor_period <= std::chrono::seconds(1),
                 "sensor_period must be step..1 s");
  require_config(kName, echo_delay >= Duration{0} && echo_delay <= std::chrono::milliseconds(10),
                 "echo_delay must be 0..10 ms");
  require_config(kName, speed_of_sound_mps > 100 && speed_of_sound_mps < 1000,
                 "speed_of_sound_mps must be 100..1000");
  require_config(kName, min_trigger > Duration{0} && min_trigger <= std::chrono::milliseconds(1),
                 "min_trigger must be above 0 and at most 1 ms");
  require_config(kName, uart_warning_after > Duration{0}, "uart_warning_after must be above 0");
  return *this;
}

AvrFirmware::AvrFirmware(sim::World& world, sim::Vehicle& vehicle, AvrConfig config)
    : FirmwareWith(world, vehicle, "arduino",
                   protocol::find_car_profile("arduino", config.profile).name, config.checked()),
      chassis_(differential_chassis_of(vehicle, "the emulated Arduino board",
                                       "use the arduino vehicle preset")),
      chip_(std::make_unique<avr::Chip>(config_.elf)),
      adapter_(link::protocol_adapter(protocol(), profile())),
      link_baud_(protocol::find_car_profile("arduino", profile()).baud) {
  chip_->on_uart_transmit([this](std::uint8_t byte, std::uint64_t) { tx_.push_back(byte); });
  const avr::PinMap& pins = config_.pins;
  if (pins.sonar_trigger && pins.sonar_echo)
    chip_->on_output_change(*pins.sonar_trigger, [this](bool level) { on_trigger(level); });
  chip_->on_conversion([this](int channel) {
    const sim::IrReading ir = vehicle_.ir();
    if (config_.pins.ir_left.analog && config_.pins.ir_left.analog->adc_channel == channel)
      chip_->set_analog_millivolts(channel, millivolts_for(ir.left_analog));
    if (config_.pins.ir_right.analog && config_.pins.ir_right.analog->adc_channel == channel)
      chip_->set_analog_millivolts(channel, millivolts_for(ir.right_analog));
  });
  reset_chip(world.time());
}

AvrFirmware::~AvrFirmware() = default;

std::shared_ptr<const link::ProtocolAdapter> AvrFirmware::adapter() const {
  return adapter_;
}

std::uint64_t AvrFirmware::cycle_at(Time time) const {
  if (time <= run_from_) return epoch_cycle_;
  return epoch_cycle_ + cycles_in(time - run_from_);
}

void AvrFirmware::reset_chip(Time now) {
  chip_->reset();
  ++state_.boots;
  state_.reset_at = now;
  state_.phase = ChipPhase::reset;
  state_.uart_baud = 0;
  run_from_ = now + config_.startup_delay;
  epoch_cycle_ = chip_->cycle();
  last_tick_ = now;
  next_sensor_read_ = now;
  trigger_high_ = false;
  echo_busy_ = false;
  warned_uart_ = false;
  warned_baud_ = false;
  reported_stop_ = false;
  tx_.clear();
  from_client_ = adapter_->splitter_for(link::Direction::to_car, false);
  to_client_ = adapter_->splitter_for(link::Direction::to_client, false);
  // Outputs float while the chip is in reset: the motor driver sees no drive.
  chassis_.set_pwm(0, 0);
  state_.left_pwm = state_.right_pwm = 0;
  update_sensors(now);
}

void AvrFirmware::on_connect(Time now) {
  if (config_.reset_on_connect) reset_chip(now);
}

void AvrFirmware::on_bytes(Time now, ByteView bytes) {
  run_chip(now);
  // Before the chip runs its UART is off: what comes in is lost, as on a
  // board still in reset.
  for (const std::uint8_t b : bytes)
    chip_->uart_receive(b);
  std::vector<link::WireFrame> frames;
  from_client_->feed(bytes, frames);
  for (const auto& f : frames) {
    if (f.valid) {
      count_frame_in();
      frame_handled(now, f.kind);
    } else {
      count_bad_frame();
    }
  }
}

void AvrFirmware::on_tick(Time now) {
  run_chip(now);
  last_tick_ = std::max(last_tick_, now);
}

std::optional<Time> AvrFirmware::next_tick() const {
  const Time next = next_grid_point(last_tick_, config_.step);
  if (state_.phase == ChipPhase::reset && run_from_ > last_tick_) return std::min(next, run_from_);
  if (state_.phase == ChipPhase::halted || state_.phase == ChipPhase::crashed) {
    // A stopped chip drives nothing new; the world still needs time while
    // the wheels turn (a chip that stops with its motors on keeps them on).
    const bool turning = chassis_.left_pwm() != 0 || chassis_.right_pwm() != 0 ||
                         chassis_.left_speed_mps() != 0 || chassis_.right_speed_mps() != 0;
    if (!turning) return std::nullopt;
  }
  return next;
}

void AvrFirmware::run_chip(Time now) {
  if (now < run_from_) return;
  if (state_.phase == ChipPhase::reset) state_.phase = ChipPhase::running;
  if (state_.phase == ChipPhase::running) {
    chip_->run_to(cycle_at(now));
    if (!tx_.empty()) {
      send_bytes(tx_);
      std::vector<link::WireFrame> frames;
      to_client_->feed(tx_, frames);
      for (std::size_t i = 0; i < frames.size(); ++i)
        count_frame_out();
      tx_.clear();
    }
  }
  update_motors();
  update_sensors(now);
  check_health(now);
}

void AvrFirmware::update_motors() {
  if (state_.phase != ChipPhase::running) return;
  const int left = side_duty(*chip_, config_.pins.left);
  const int right = side_duty(*chip_, config_.pins.right);
  if (left == state_.left_pwm && right == state_.right_pwm) return;
  state_.left_pwm = left;
  state_.right_pwm = right;
  chassis_.set_pwm(left, right);
}

void AvrFirmware::update_sensors(Time now) {
  const avr::PinMap& pins = config_.pins;
  if (now >= next_sensor_read_ && (pins.ir_left.digital || pins.ir_right.digital)) {
    next_sensor_read_ = next_grid_point(now, config_.sensor_period);
    const sim::IrReading ir = vehicle_.ir();
    if (pins.ir_left.digital) chip_->drive(*pins.ir_left.digital, ir.left_obstacle);
    if (pins.ir_right.digital) chip_->drive(*pins.ir_right.digital, ir.right_obstacle);
  }
  if (state_.phase != ChipPhase::running) return;
  if (pins.left.encoder)
    queue_encoder_edges(*pins.left.encoder, chassis_.left_travel_m(), left_edges_, left_level_);
  if (pins.right.encoder)
    queue_encoder_edges(*pins.right.encoder, chassis_.right_travel_m(), right_edges_, right_level_);
}

void AvrFirmware::queue_encoder_edges(const avr::BoardPin& pin, double travel_m,
                                      std::uint64_t& sent, bool& level) {
  // Edges so far from the side's rolled distance (either way: a slotted
  // disc gives no direction); the new ones are spread over the next step.
  const double revolutions =
      std::abs(travel_m) / (std::numbers::pi * config_.pins.wheel_diameter_m);
  const auto due = static_cast<std::uint64_t>(revolutions * config_.pins.encoder_ticks_per_rev);
  if (due <= sent) return;
  const std::uint64_t fresh = due - sent;
  const std::uint64_t spacing = std::max<std::uint64_t>(1, cycles_in(config_.step) / (fresh + 1));
  const std::uint64_t start = chip_->cycle();
  for (std::uint64_t i = 1; i <= fresh; ++i) {
    level = !level;
    const bool at = level;
    chip_->at_cycle(start + i * spacing, [this, pin, at] { chip_->drive(pin, at); });
  }
  sent = due;
  state_.encoder_edges += fresh;
}

void AvrFirmware::on_trigger(bool level) {
  if (level) {
    trigger_high_ = true;
    trigger_rose_ = chip_->cycle();
    return;
  }
  if (!trigger_high_) return;
  trigger_high_ = false;
  const std::uint64_t fell = chip_->cycle();
  if (echo_busy_ || fell - trigger_rose_ < cycles_in(config_.min_trigger)) return;
  ++state_.sonar_pings;
  const sim::SonarReading reading = vehicle_.sonar();
  // Out of range: no echo pulse at all, so pulseIn() runs to its timeout.
  if (!reading.echo) return;
  const double round_trip_s = 2.0 * reading.distance_m / config_.speed_of_sound_mps;
  const auto width =
      static_cast<std::uint64_t>(std::llround(round_trip_s * avr::Chip::kFrequencyHz));
  const std::uint64_t rise = fell + cycles_in(config_.echo_delay);
  const avr::BoardPin echo = *config_.pins.sonar_echo;
  echo_busy_ = true;
  chip_->at_cycle(rise, [this, echo] { chip_->drive(echo, true); });
  chip_->at_cycle(rise + std::max<std::uint64_t>(width, 1), [this, echo] {
    chip_->drive(echo, false);
    echo_busy_ = false;
  });
}

void AvrFirmware::check_health(Time now) {
  for (const auto& m : chip_->take_messages())
    note("simavr: " + m);
  if (state_.phase == ChipPhase::running) {
    const avr::Chip::State s = chip_->state();
    if (s == avr::Chip::State::halted) state_.phase = ChipPhase::halted;
    if (s == avr::Chip::State::crashed) state_.phase = ChipPhase::crashed;
  }
  if ((state_.phase == ChipPhase::halted || state_.phase == ChipPhase::crashed) &&
      !reported_stop_) {
    reported_stop_ = true;
    std::ostringstream out;
    out << "the firmware "
        << (state_.phase == ChipPhase::halted ? "halted (asleep with interrupts off)" : "crashed")
        << " at cycle " << chip_->cycle() << "; it answers nothing until the next reset";
    note(out.str());
  }
  if (chip_->uart_enabled()) {
    state_.uart_baud = chip_->uart_baud();
    const std::uint32_t link_baud = link_baud_;
    // UART framing survives about 2 % of clock difference between the ends.
    if (!warned_baud_ && link_baud != 0 &&
        std::abs(static_cast<double>(state_.uart_baud) - link_baud) > 0.03 * link_baud) {
      warned_baud_ = true;
      note("the firmware set its UART to " + std::to_string(state_.uart_baud) +
           " baud; the Arduino robot's line runs at " + std::to_string(link_baud) +
           " baud, so a real board's bytes would come out garbled");
    }
  } else if (!warned_uart_ && state_.phase == ChipPhase::running &&
             now - run_from_ >= config_.uart_warning_after) {
    warned_uart_ = true;
    note("the firmware has not turned its UART on " +
         std::to_string(config_.uart_warning_after / std::chrono::milliseconds(1)) +
         " ms after the reset: it will answer nothing (Serial.begin() missing?)");
  }
}

void AvrFirmware::note(const std::string& line) {
  if (config_.log) config_.log(line);
}

std::string AvrFirmware::summary() const {
  switch (state_.phase) {
    case ChipPhase::reset:
      return "ATmega328P RESET";
    case ChipPhase::halted:
      return "ATmega328P HALTED";
    case ChipPhase::crashed:
      return "ATmega328P CRASHED";
    case ChipPhase::running:
      break;
  }
  std::ostringstream out;
  out << "ATmega328P RUN L" << (state_.left_pwm >= 0 ? "+" : "") << state_.left_pwm << " R"
      << (state_.right_pwm >= 0 ? "+" : "") << state_.right_pwm;
  return out.str();
}

}  // namespace hil::mocks
