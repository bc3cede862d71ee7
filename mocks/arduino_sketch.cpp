// The Arduino mock as the real sketch (dialect `firmware`): its receive
// path (protocol/arduino/sketch.hpp) and its commands, with the reply texts
// of andrii-mazurchuk/arduino_robot_steering- at 8dcfab0 (arduino.ino).
// docs/protocols/arduino.md, "Profiles", lists each fact.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "mocks/arduino.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::mocks {
namespace {

namespace arduino = protocol::arduino;

std::optional<std::uint8_t> seq_value(std::string_view seq) {
  return protocol::parse_hex_byte(seq);
}

}  // namespace

void ArduinoFirmware::receive_as_sketch(Time now, ByteView bytes) {
  sketch_frames_.clear();
  sketch_.feed(bytes, sketch_frames_);
  for (const auto& frame : sketch_frames_) {
    std::visit(protocol::Overloaded{
                   [&](const arduino::SketchDrop&) { count_bad_frame(); },
                   [&](const arduino::SketchRefusal& refusal) {
                     count_bad_frame();
                     sketch_answer(refusal.seq, false, arduino::to_string(refusal.code));
                   },
                   [&](const arduino::SketchRequest& request) {
                     count_frame_in();
                     handle_sketch_request(now, frame.raw, request);
                   },
               },
               frame.verdict);
  }
  sketch_frames_.clear();
}

void ArduinoFirmware::handle_sketch_request(Time now, const Bytes& raw,
                                            const arduino::SketchRequest& request) {
  // The sketch compares commands without regard to case; behaviours and
  // counters see the command in upper case, as the readme dialect does.
  const std::string kind = protocol::ascii_upper(request.cmd);
  take_command(
      now, kind,
      [&] {
        if (config_.repeat_answer_for_repeated_request && !last_request_.empty() &&
            raw == last_request_) {
          send(last_answer_);
          state_.last_seq = seq_value(request.seq);
        } else {
          const SketchReply reply = execute_sketch(now, kind, request.payload);
          sketch_answer(request.seq, reply.ack, reply.text);
          last_request_ = raw;
        }
      },
      [&] { sketch_answer(request.seq, false, config_.reject_code); });
}

ArduinoFirmware::SketchReply ArduinoFirmware::execute_sketch(Time now, std::string_view command,
                                                             std::string_view payload) {
  const auto motion_refused = [&]() -> std::optional<SketchReply> {
    if (in_fault()) return SketchReply{false, config_.fault_code};
    return std::nullopt;
  };
  if (command == "PING") return {true, "PONG"};
  if (command == "HELP") return {true, std::string(help_text(arduino::Dialect::firmware))};
  if (command == "STATUS") return {true, sketch_status(now)};
  if (command == "V") {
    if (auto no = motion_refused()) return *no;
    const long v = arduino::sketch_atol(payload);
    if (v < 0 || v > arduino::kMaxPwm) return {false, "BAD_V"};
    state_.pwm = static_cast<int>(v);
    return {true, "OK"};
  }
  if (command == "M" || command == "R") {
    if (auto no = motion_refused()) return *no;
    // No range check: any 32-bit number starts a move of that size.
    const int arg = static_cast<int>(arduino::sketch_atol(payload));
    start_motion(now, command == "M" ? ArduinoMotion::move : ArduinoMotion::rotate, arg);
    return {true, "ACCEPTED"};
  }
  if (command == "S") {
    stop_motion();
    return {true, "STOPPED"};
  }
  if (command == "B") {
    // The sketch turns the echo time into whole centimetres, truncating;
    // no echo within its 30 ms wait reads 0.
    const sim::SonarReading reading = vehicle_.sonar();
    // (1e-9: a simulated 0.40 m that comes out as 0.39999... is still 40.)
    const long cm =
        reading.echo ? static_cast<long>(std::floor(reading.distance_m * 100 + 1e-9)) : 0;
    return {true, "B:" + std::to_string(cm)};
  }
  if (command == "I") return {true, sketch_ir()};
  return {false, "BAD_CMD"};
}

void ArduinoFirmware::sketch_answer(std::string_view seq, bool ack, std::string_view text) {
  last_answer_ = arduino::sketch_frame(seq, ack ? "ACK" : "NACK", text);
  last_request_.clear();
  state_.last_seq = seq_value(seq);
  send(last_answer_);
}

std::string ArduinoFirmware::sketch_status(Time now) const {
  const char* dir = state_.last_dir > 0 ? "fwd" : state_.last_dir < 0 ? "rev" : "stop";
  std::string text = "STATUS:V=" + std::to_string(state_.pwm) + ",DIR=" + dir;
  if (!moving()) return text + ",MOT:IDLE";
  // millis() is whole milliseconds: the time left is truncated.
  const auto left = state_.motion_ends > now ? state_.motion_ends - now : Duration::zero();
  text += state_.motion == ArduinoMotion::move ? ",MOT:MOVE" : ",MOT:ROT";
  return text + ",tleft:" + std::to_string(left / link::milliseconds(1));
}

std::string ArduinoFirmware::sketch_ir() const {
  // DL and DR are the modules' digital pins as read: 1 where hil's IR
  // model sees an obstacle, as in the readme dialect.
  const sim::IrReading ir = vehicle_.ir();
  return "I:AL=" + std::to_string(ir.left_analog) + ",AR=" + std::to_string(ir.right_analog) +
         ",DL=" + (ir.left_obstacle ? "1" : "0") + ",DR=" + (ir.right_obstacle ? "1" : "0");
}

}  // namespace hil::mocks
