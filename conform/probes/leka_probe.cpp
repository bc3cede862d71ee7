// The Leka Alpha probe: every command of the profile's table with typical
// and boundary values, the frames the robot must refuse, frames cut and
// joined on the wire, a silent stretch, and a reconnect
// (docs/protocols/leka.md, docs/mocks/leka.md).
//
// The robot answers nothing but `info` (one text line), so a command shows
// that it was taken only by an `info` in the same frame: nearly every
// frame of the probe ends with one. A frame the robot refuses is dropped
// whole, its `info` included, and the exchange stays silent. Frames are
// written in the profile's own command ids and checksum.
//
// Safety: motors turn at speed 60 of 255 for two listen windows in a row
// at most (forward, then back); a speed of 255 is always followed by
// stop.motor in the same frame, so the wheels never get going; motivators and guidances (which may
// move the robot) are stopped by the next frame or in their own frame; the probe ends with
// stop.robot.
#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "conform/probes/probe_builder.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/leka/message.hpp"

namespace hil::conform {

namespace {

namespace leka = protocol::leka;
using leka::Command;
using leka::Rgb;
using std::chrono::milliseconds;

// The robot's link: 115,200 baud, 8N1, so ten bits a byte.
constexpr Duration kByteTime = std::chrono::microseconds(87);
// The longest line the robot's side of the link is cut into (the line
// splitter's bound), and the longest frame the probe writes.
constexpr std::size_t kMaxLineBytes = leka::kMaxFrameBytes;
// One pass of the robot's main loop (10 ms in the mock; the real period is
// not documented) before a frame is read.
constexpr Duration kLoopPass = milliseconds(10);
constexpr Duration kMargin = milliseconds(200);
// The port opens without resetting the robot (it is behind a BLE-UART
// bridge); the settle leaves the bridge time to pass bytes again.
constexpr Duration kSettle = milliseconds(500);
// Motors turn this fast in the exchanges that move: about 0.1 m/s on hil's
// model of the robot (0.4 m/s at 255).
constexpr std::uint8_t kSlow = 60;

constexpr Rgb kBlack{0, 0, 0};
constexpr Rgb kWhite{255, 255, 255};
constexpr Rgb kDimRed{60, 0, 0};
constexpr Rgb kDimGreen{0, 60, 0};
constexpr Rgb kDimBlue{0, 0, 60};

// Time to write the bytes, then a pass, then `lines` lines of the longest
// kind, then the margin.
Duration listen_for(std::size_t written, std::size_t lines) {
  const std::size_t line_bytes = std::max<std::size_t>(lines, 1) * kMaxLineBytes;
  const auto total = kByteTime * static_cast<long>(written + line_bytes) + kLoopPass + kMargin;
  return std::chrono::ceil<milliseconds>(total);
}

// ------------------------------------------------------------ frames

// A frame the robot takes: the codec refuses to build anything else.
Bytes frame(leka::Dialect d, std::vector<Command> commands) {
  return leka::encode(leka::CommandGroup{std::move(commands)}, {}, d);
}
Bytes group(leka::Dialect d, std::vector<Command> commands) {
  return leka::group_bytes(leka::CommandGroup{std::move(commands)}, d);
}
// A well-framed frame with a value out of range (right checksum).
Bytes unchecked(leka::Dialect d, std::vector<Command> commands) {
  return leka::frame_group(group(d, std::move(commands)), d);
}
leka::Dialect other_dialect(leka::Dialect d) {
  return d == leka::Dialect::readme ? leka::Dialect::comspecs_v3 : leka::Dialect::readme;
}

// ------------------------------------------------------------ exchanges

// `writes`, then a window that fits them and `lines` lines of answer.
void add_writes(ProbeBuilder& b, std::string name, std::string what, ExchangeKind kind,
                std::vector<ProbeWrite> writes, std::size_t lines) {
  std::size_t written = 0;
  for (const auto& w : writes)
    written += w.bytes.size();
  b.add(std::move(name), std::move(what), kind, std::move(writes), listen_for(written, lines));
}
// A frame of valid commands (the last one is info): one line per info.
void add_frame(ProbeBuilder& b, leka::Dialect d, std::string name, std::string what,
               ExchangeKind kind, std::vector<Command> commands, std::size_t lines) {
  add_writes(b, std::move(name), std::move(what), kind,
             ProbeBuilder::once(frame(d, std::move(commands))), lines);
}
// A frame the robot should drop whole: it stays silent.
void add_refused(ProbeBuilder& b, leka::Dialect d, std::string name, std::string what,
                 std::vector<Command> commands) {
  add_writes(b, std::move(name), std::move(what), ExchangeKind::error,
             ProbeBuilder::once(unchecked(d, std::move(commands))), 0);
}

// ------------------------------------------------------------ commands

void add_basics(ProbeBuilder& b, leka::Dialect d) {
  add_frame(b, d, "info", "info alone: the robot's one line", ExchangeKind::command, {leka::Info{}},
            1);
  add_frame(b, d, "info-twice", "info + info in one frame: two lines", ExchangeKind::command,
            {leka::Info{}, leka::Info{}}, 2);
  add_frame(b, d, "stop-led", "stop.led + info", ExchangeKind::command,
            {leka::StopLed{}, leka::Info{}}, 1);
  add_frame(b, d, "stop-motor", "stop.motor + info", ExchangeKind::command,
            {leka::StopMotor{}, leka::Info{}}, 1);
  add_frame(b, d, "stop-robot", "stop.robot + info", ExchangeKind::command,
            {leka::StopRobot{}, leka::Info{}}, 1);
}

void add_ears(ProbeBuilder& b, leka::Dialect d) {
  const auto k = ExchangeKind::boundary;
  add_frame(b, d, "ear-all", "led.ear.all dim red + info", ExchangeKind::command,
            {leka::EarAll{kDimRed}, leka::Info{}}, 1);
  add_frame(b, d, "ear-all-max", "led.ear.all 255 255 255 + info", k,
            {leka::EarAll{kWhite}, leka::Info{}}, 1);
  add_frame(b, d, "ear-all-min", "led.ear.all 0 0 0 + info", k,
            {leka::EarAll{kBlack}, leka::Info{}}, 1);
  add_frame(b, d, "ear-single", "led.ear.single ear 0 dim green + info", ExchangeKind::command,
            {leka::EarSingle{0, kDimGreen}, leka::Info{}}, 1);
  // Dim blue, not white: in white, the comspecs-v3 frame (group 13 01 FF
  // FF FF 70) has the same checksum in both profiles and reads in readme
  // as led.belt.all + stop.robot + info, so it would not tell them apart.
  add_frame(b, d, "ear-single-id-1", "led.ear.single ear 1 (the last) dim blue + info", k,
            {leka::EarSingle{1, kDimBlue}, leka::Info{}}, 1);
  add_refused(b, d, "ear-single-id-2", "led.ear.single ear 2 (no such ear) + info: refused",
              {leka::EarSingle{2, kDimBlue}, leka::Info{}});
  if (d != leka::Dialect::comspecs_v3) return;
  // led.ear.range exists only in the spec's YAML table.
  add_frame(b, d, "ear-range", "led.ear.range ears 0..1 dim blue + info", ExchangeKind::command,
            {leka::EarRange{0, 1, kDimBlue}, leka::Info{}}, 1);
  add_frame(b, d, "ear-range-one", "led.ear.range ears 1..1 white + info", k,
            {leka::EarRange{1, 1, kWhite}, leka::Info{}}, 1);
  add_refused(b, d, "ear-range-last-2", "led.ear.range ears 0..2 (no ear 2) + info: refused",
              {leka::EarRange{0, 2, kDimRed}, leka::Info{}});
  add_refused(b, d, "ear-range-reversed",
              "led.ear.range ears 1..0 (first after last) + info: refused",
              {leka::EarRange{1, 0, kDimRed}, leka::Info{}});
}

void add_belt(ProbeBuilder& b, leka::Dialect d) {
  const auto k = ExchangeKind::boundary;
  add_frame(b, d, "belt-all", "led.belt.all dim green + info", ExchangeKind::command,
            {leka::BeltAll{kDimGreen}, leka::Info{}}, 1);
  add_frame(b, d, "belt-all-max", "led.belt.all 255 255 255 + info", k,
            {leka::BeltAll{kWhite}, leka::Info{}}, 1);
  add_frame(b, d, "belt-all-min", "led.belt.all 0 0 0 + info", k,
            {leka::BeltAll{kBlack}, leka::Info{}}, 1);
  add_frame(b, d, "belt-single", "led.belt.single LED 0 dim red + info", ExchangeKind::command,
            {leka::BeltSingle{0, kDimRed}, leka::Info{}}, 1);
  add_frame(b, d, "belt-single-id-19", "led.belt.single LED 19 (the last) white + info", k,
            {leka::BeltSingle{19, kWhite}, leka::Info{}}, 1);
  add_refused(b, d, "belt-single-id-20", "led.belt.single LED 20 (past the belt) + info: refused",
              {leka::BeltSingle{20, kDimBlue}, leka::Info{}});
  add_refused(b, d, "belt-single-id-0x19",
              "led.belt.single LED 0x19 (the README table's last id) + info: refused",
              {leka::BeltSingle{0x19, kDimBlue}, leka::Info{}});
  add_frame(b, d, "belt-range", "led.belt.range LEDs 2..5 dim blue + info", ExchangeKind::command,
            {leka::BeltRange{2, 5, kDimBlue}, leka::Info{}}, 1);
  add_frame(b, d, "belt-range-full", "led.belt.range LEDs 0..19 white + info", k,
            {leka::BeltRange{0, 19, kWhite}, leka::Info{}}, 1);
  add_frame(b, d, "belt-range-one", "led.belt.range LEDs 7..7 dim red + info", k,
            {leka::BeltRange{7, 7, kDimRed}, leka::Info{}}, 1);
  add_refused(b, d, "belt-range-last-20",
              "led.belt.range LEDs 0..20 (past the belt) + info: refused",
              {leka::BeltRange{0, 20, kDimRed}, leka::Info{}});
  add_refused(b, d, "belt-range-reversed",
              "led.belt.range LEDs 6..5 (first after last) + info: refused",
              {leka::BeltRange{6, 5, kDimRed}, leka::Info{}});
}

void add_motors(ProbeBuilder& b, leka::Dialect d) {
  using leka::kSpinBackward;
  using leka::kSpinForward;
  const auto c = ExchangeKind::command;
  const auto k = ExchangeKind::boundary;
  const leka::StopMotor stop;
  const leka::Info info;
  add_frame(b, d, "motor-all-forward", "motor.all forward at 60 + info: drives slowly", c,
            {leka::MotorAll{kSpinForward, kSlow}, info}, 1);
  add_frame(b, d, "motor-all-backward", "motor.all backward at 60 + info: drives back", c,
            {leka::MotorAll{kSpinBackward, kSlow}, info}, 1);
  add_frame(b, d, "motor-all-zero", "motor.all forward at 0 + info: stands", k,
            {leka::MotorAll{kSpinForward, 0}, info}, 1);
  add_frame(b, d, "motor-all-max", "motor.all backward at 255 + stop.motor + info", k,
            {leka::MotorAll{kSpinBackward, 255}, stop, info}, 1);
  add_refused(b, d, "motor-all-direction-2",
              "motor.all direction 2 at 0 + stop.motor + info: refused",
              {leka::MotorAll{2, 0}, stop, info});
  add_frame(b, d, "motor-duo", "motor.duo left forward 60, right backward 60 + info: turns", c,
            {leka::MotorDuo{kSpinForward, kSlow, kSpinBackward, kSlow}, info}, 1);
  add_frame(b, d, "motor-duo-zero", "motor.duo all 0 + info: stands", k,
            {leka::MotorDuo{kSpinForward, 0, kSpinForward, 0}, info}, 1);
  add_frame(b, d, "motor-duo-max", "motor.duo both backward at 255 + stop.motor + info", k,
            {leka::MotorDuo{kSpinBackward, 255, kSpinBackward, 255}, stop, info}, 1);
  add_refused(b, d, "motor-duo-left-spin-2", "motor.duo left spin 2 + stop.motor + info: refused",
              {leka::MotorDuo{2, 0, kSpinForward, 0}, stop, info});
  add_refused(b, d, "motor-duo-right-spin-2", "motor.duo right spin 2 + stop.motor + info: refused",
              {leka::MotorDuo{kSpinForward, 0, 2, 0}, stop, info});
  add_frame(b, d, "motor-left", "motor.left forward at 60 + info: turns right", c,
            {leka::MotorLeft{kSpinForward, kSlow}, info}, 1);
  add_frame(b, d, "motor-left-zero", "motor.left forward at 0 + info: stands", k,
            {leka::MotorLeft{kSpinForward, 0}, info}, 1);
  add_frame(b, d, "motor-left-max", "motor.left backward at 255 + stop.motor + info", k,
            {leka::MotorLeft{kSpinBackward, 255}, stop, info}, 1);
  add_refused(b, d, "motor-left-spin-2", "motor.left spin 2 + stop.motor + info: refused",
              {leka::MotorLeft{2, 0}, stop, info});
  add_frame(b, d, "motor-right", "motor.right backward at 60 + info: turns right", c,
            {leka::MotorRight{kSpinBackward, kSlow}, info}, 1);
  add_frame(b, d, "motor-right-zero", "motor.right forward at 0 + info: stands", k,
            {leka::MotorRight{kSpinForward, 0}, info}, 1);
  add_frame(b, d, "motor-right-max", "motor.right backward at 255 + stop.motor + info", k,
            {leka::MotorRight{kSpinBackward, 255}, stop, info}, 1);
  add_refused(b, d, "motor-right-spin-2", "motor.right spin 2 + stop.motor + info: refused",
              {leka::MotorRight{2, 0}, stop, info});
}

void add_behaviours(ProbeBuilder& b, leka::Dialect d) {
  const auto k = ExchangeKind::boundary;
  const leka::StopRobot stop;
  const leka::Info info;
  add_frame(b, d, "motivator", "motivator 0x52 + info: plays (stopped by the next frame)",
            ExchangeKind::command, {leka::Motivator{0x52}, info}, 1);
  add_frame(b, d, "motivator-0x51", "motivator 0x51 (the first) + stop.robot + info", k,
            {leka::Motivator{0x51}, stop, info}, 1);
  add_frame(b, d, "motivator-0x55", "motivator 0x55 (the last) + stop.robot + info", k,
            {leka::Motivator{0x55}, stop, info}, 1);
  add_refused(b, d, "motivator-0x50",
              "motivator 0x50 (below the table) + stop.robot + info: refused",
              {leka::Motivator{0x50}, stop, info});
  add_refused(b, d, "motivator-0x56",
              "motivator 0x56 (past the table) + stop.robot + info: refused",
              {leka::Motivator{0x56}, stop, info});
  add_frame(b, d, "guidance", "guidance 0x4B (tilt left) + info: plays (stopped by the next frame)",
            ExchangeKind::command, {leka::Guidance{0x4B}, info}, 1);
  add_frame(b, d, "guidance-0x41", "guidance 0x41 (the first) + stop.robot + info", k,
            {leka::Guidance{0x41}, stop, info}, 1);
  // stop.motor, not stop.robot: the group 40 4F FF 70 has the same
  // checksum in both profiles, so it would not tell them apart.
  add_frame(b, d, "guidance-0x4f", "guidance 0x4F (the last) + stop.motor + info", k,
            {leka::Guidance{0x4F}, leka::StopMotor{}, info}, 1);
  add_refused(b, d, "guidance-0x40", "guidance 0x40 (below the table) + stop.robot + info: refused",
              {leka::Guidance{0x40}, stop, info});
  add_refused(b, d, "guidance-0x50", "guidance 0x50 (past the table) + stop.robot + info: refused",
              {leka::Guidance{0x50}, stop, info});
}

// ------------------------------------------------------------ frames

// 24 led.belt.single (120 bytes) then `tail`: the largest group is 122.
std::vector<Command> long_group(std::vector<Command> tail) {
  std::vector<Command> commands;
  for (std::uint8_t i = 0; i < 24; ++i) {
    const auto led = static_cast<std::uint8_t>(i % 20);
    commands.push_back(leka::BeltSingle{led, Rgb{static_cast<std::uint8_t>(10 * i), 0, 40}});
  }
  commands.insert(commands.end(), tail.begin(), tail.end());
  return commands;
}

void add_frame_limits(ProbeBuilder& b, leka::Dialect d) {
  add_frame(b, d, "group-122",
            "a 122-byte group (a 128-byte frame): 24 led.belt.single + stop.led + info",
            ExchangeKind::boundary, long_group({leka::StopLed{}, leka::Info{}}), 1);
  // One byte more than a frame can hold: the length byte says 123.
  add_writes(
      b, "group-123", "a 123-byte group (oversized): 24 led.belt.single + stop.led + info x2",
      ExchangeKind::error,
      ProbeBuilder::once(unchecked(d, long_group({leka::StopLed{}, leka::Info{}, leka::Info{}}))),
      0);
  add_writes(b, "length-0", "start sequence, length 0 and a checksum: no command",
             ExchangeKind::error, ProbeBuilder::once(leka::frame_group(Bytes{}, d)), 0);
}

void add_refused_frames(ProbeBuilder& b, leka::Dialect d) {
  Bytes bad = frame(d, {leka::Info{}});
  bad.back() = static_cast<std::uint8_t>(bad.back() + 1);
  add_writes(b, "bad-checksum", "info with its checksum one too high", ExchangeKind::error,
             ProbeBuilder::once(std::move(bad)), 0);
  const auto other = other_dialect(d);
  add_writes(b, "other-profile-checksum",
             "info framed as the other profile frames it (its checksum)", ExchangeKind::error,
             ProbeBuilder::once(leka::frame_group(group(other, {leka::Info{}}), other)), 0);
  // info, then motor.all without its speed byte: the group ends inside it.
  Bytes cut = group(d, {leka::Info{}, leka::MotorAll{leka::kSpinForward, 0}});
  cut.pop_back();
  add_writes(b, "command-cut", "info + motor.all missing its speed byte (right checksum)",
             ExchangeKind::error, ProbeBuilder::once(leka::frame_group(cut, d)), 0);
  Bytes unknown = group(d, {leka::Info{}});
  unknown.push_back(0x99);
  add_writes(b, "unknown-id", "info + id 0x99 (no such command; right checksum)",
             ExchangeKind::error, ProbeBuilder::once(leka::frame_group(unknown, d)), 0);
  add_refused(b, d, "bad-value-after-info", "info + led.ear.single ear 2: the whole frame refused",
              {leka::Info{}, leka::EarSingle{2, kDimBlue}});
}

// ------------------------------------------------------------ on the wire

void add_framing(ProbeBuilder& b, leka::Dialect d) {
  // No start sequence in it; a false start (2A 2B) in the middle.
  const Bytes noise{0x00, 0xFF, 0x55, 0xAA, 0x2A, 0x2B, 0x00, 0x13, 0x37, 0x0D, 0x0A, 0x70};
  add_writes(b, "garbage", "12 bytes of noise with no start sequence", ExchangeKind::error,
             ProbeBuilder::once(noise), 0);
  add_writes(
      b, "garbage-between-frames", "info, 12 bytes of noise, led.ear.all + info: two lines",
      ExchangeKind::framing,
      ProbeBuilder::once(ProbeBuilder::join(
          {frame(d, {leka::Info{}}), noise, frame(d, {leka::EarAll{kDimGreen}, leka::Info{}})})),
      2);
  add_writes(
      b, "split-bytes", "led.belt.all + info written one byte at a time, 3 ms apart",
      ExchangeKind::framing,
      ProbeBuilder::bytewise(frame(d, {leka::BeltAll{kDimRed}, leka::Info{}}), milliseconds(3)), 1);

  const Bytes info = frame(d, {leka::Info{}});
  add_writes(b, "split-pause", "info: its start sequence, then 100 ms later the rest",
             ExchangeKind::framing,
             {{Duration{0}, Bytes(info.begin(), info.begin() + 4)},
              {milliseconds(100), Bytes(info.begin() + 4, info.end())}},
             1);
  add_writes(b, "two-frames", "info and led.belt.all + info in one write: two lines",
             ExchangeKind::framing,
             ProbeBuilder::once(ProbeBuilder::join(
                 {frame(d, {leka::Info{}}), frame(d, {leka::BeltAll{kDimBlue}, leka::Info{}})})),
             2);

  // Long enough for any periodic frame of 100 ms or faster to show ten
  // times; the robot is expected to stay silent.
  b.listen("telemetry", "no writes for 1 s: the robot sends nothing", milliseconds(1000));
}

void add_connection(ProbeBuilder& b, leka::Dialect d) {
  // All but the checksum byte of a frame, then the port closes.
  Bytes partial = frame(d, {leka::EarAll{kDimBlue}, leka::Info{}});
  partial.pop_back();
  add_writes(b, "partial-before-reconnect",
             "led.ear.all + info without its checksum byte, then the port is closed",
             ExchangeKind::framing, ProbeBuilder::once(std::move(partial)), 0);
  b.connect("reconnect", "close the port and open it again: the robot sends nothing");
  add_frame(b, d, "info-after-reconnect", "info after the reconnect: the robot still answers",
            ExchangeKind::command, {leka::Info{}}, 1);
}

}  // namespace

Probe make_leka_probe(std::string_view profile) {
  const auto d = leka::dialect_named(profile);
  // A connect waits for what one line would take.
  ProbeBuilder b("leka-probe/1", kSettle, listen_for(0, 1));
  b.connect("connect", "open the port: the robot sends nothing on its own");
  add_basics(b, d);
  add_ears(b, d);
  add_belt(b, d);
  add_motors(b, d);
  add_behaviours(b, d);
  add_frame_limits(b, d);
  add_refused_frames(b, d);
  add_framing(b, d);
  add_connection(b, d);
  add_frame(b, d, "stop", "stop.robot + info: LEDs and motors off, then the line",
            ExchangeKind::stop, {leka::StopRobot{}, leka::Info{}}, 1);
  // The robot sends nothing on its own.
  return b.take();
}

}  // namespace hil::conform
