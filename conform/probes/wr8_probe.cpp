// The WR8 probe, written in the framing of the profile it probes
// (docs/protocols/wr8.md): `document` sends the PDF's packets with no
// length byte, `svgui-2019` and `svgui-head` the real programs' packets,
// each after its length byte. The three probes share their shape (login
// rules, every packet with valid and edge values, malformed and cut
// frames, telemetry, a reconnect, a closing stop) but not their packets.
//
// Safety: moves are short (10 cm at most) or made at zero speed; the
// longest drive the document vehicle accepts (1000 cm) is never sent, and
// one past it, which the car refuses, goes while every gain is 0; the
// probe never leaves a v2019 vehicle busy (tasks that would, go with COI 0).
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "conform/probes/probe_builder.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/message.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::conform {

namespace wr8_probe {
namespace {

namespace wr8 = protocol::wr8;
namespace svgui = protocol::wr8::svgui;
using std::chrono::milliseconds;

/// Gap between the single-byte writes of a split frame.
constexpr Duration kByteGap = milliseconds(5);
/// An answer over TCP on Wi-Fi, and then some.
constexpr Duration kReply = milliseconds(300);

// ------------------------------------------------------------- document

Bytes doc(const wr8::Message& m) {
  return wr8::encode(m);
}
Bytes doc_task(std::uint8_t coi, wr8::TaskCode task, std::vector<wr8::Word> params = {}) {
  return wr8::encode_unchecked(wr8::Task{coi, task, std::move(params)});
}
Bytes doc_settings(std::uint8_t coi, float p, float i, float d, std::int32_t servo_zero) {
  using wr8::SettingCode;
  return doc(wr8::Settings{coi,
                           {{SettingCode::p, wr8::Word::from_f32(p)},
                            {SettingCode::i, wr8::Word::from_f32(i)},
                            {SettingCode::d, wr8::Word::from_f32(d)},
                            {SettingCode::servo_zero, wr8::Word::from_i32(servo_zero)}}});
}
Bytes doc_setting(std::uint8_t coi, wr8::SettingCode code, wr8::Word value) {
  return doc(wr8::Settings{coi, {{code, value}}});
}
Bytes doc_auth(std::string_view text) {
  wr8::Auth auth;
  for (std::size_t k = 0; k < auth.text.size() && k < text.size(); ++k)
    auth.text[k] = static_cast<std::uint8_t>(text[k]);
  return doc(auth);
}
/// AUTH with the profile's string, the one the vehicle expects.
Bytes doc_good_auth() {
  return doc(wr8::Auth{wr8::default_profile().auth_text});
}
/// A task parameter: a distance in cm or an angle in degrees.
wr8::Word i32(std::int32_t v) {
  return wr8::Word::from_i32(v);
}

// The defaults of the document vehicle (docs/mocks/wr8.md, Settings).
constexpr float kP = 1.5F;
constexpr float kI = 0.25F;
constexpr float kD = 0.05F;
constexpr std::int32_t kServoZero = 90;

void document_login(ProbeBuilder& b) {
  using wr8::TaskCode;
  b.add("task-before-auth", "TASK check (COI 1) before any AUTH: dropped unanswered",
        ExchangeKind::error, ProbeBuilder::once(doc_task(1, TaskCode::check)));
  b.add("auth-bad", "AUTH with a wrong 10-byte string: no answer, the car closes after 1 s",
        ExchangeKind::error, ProbeBuilder::once(doc_auth("HIL-WR8-00")), milliseconds(1500));
  b.connect("reconnect-after-refusal", "open a new connection after the refused login");
  b.add("auth", "AUTH with the profile's string: AUTH-REPLY (device, id, state now)",
        ExchangeKind::command, ProbeBuilder::once(doc_good_auth()), kReply, true);
  b.add("auth-again", "AUTH again while logged in: AUTH-REPLY again", ExchangeKind::command,
        ProbeBuilder::once(doc_good_auth()), kReply, true);
}

void document_commands(ProbeBuilder& b) {
  using wr8::SettingCode;
  using wr8::TaskCode;
  b.add("empty", "EMPTY keepalive: no answer", ExchangeKind::command,
        ProbeBuilder::once(doc(wr8::Empty{})));
  b.add("check", "TASK check COI 2: RESPONSE completed", ExchangeKind::command,
        ProbeBuilder::once(doc_task(2, TaskCode::check)));
  b.add("check-coi-0", "TASK check COI 0 (the lowest COI)", ExchangeKind::boundary,
        ProbeBuilder::once(doc_task(0, TaskCode::check)));
  b.add("check-coi-255", "TASK check COI 255 (the highest COI)", ExchangeKind::boundary,
        ProbeBuilder::once(doc_task(255, TaskCode::check)));
  b.add("get-settings", "TASK get-settings COI 3: SETTINGS with all four, then completed",
        ExchangeKind::command, ProbeBuilder::once(doc_task(3, TaskCode::get_settings)));
  b.add("settings", "SETTINGS COI 4 P 1.5 I 0.25 D 0.05 servo zero 90: completed",
        ExchangeKind::command, ProbeBuilder::once(doc_settings(4, kP, kI, kD, kServoZero)));
  b.add("settings-no-entries", "SETTINGS COI 5 with no entries: completed", ExchangeKind::boundary,
        ProbeBuilder::once(doc(wr8::Settings{5, {}})));
  b.add("settings-min", "SETTINGS COI 6 P I D 0, servo zero 0 (each field's lowest): completed",
        ExchangeKind::boundary, ProbeBuilder::once(doc_settings(6, 0, 0, 0, 0)), milliseconds(500));
  // Sent while every gain is 0: a car that takes 1001 cm against its
  // document then has no gain to drive with.
  b.add("drive-over-max", "TASK drive 1001 cm COI 23 with every gain 0: error", ExchangeKind::error,
        ProbeBuilder::once(doc_task(23, TaskCode::drive, {i32(1001)})));
  b.add("settings-max", "SETTINGS COI 8 P I D 100, servo zero 180 (each field's highest)",
        ExchangeKind::boundary, ProbeBuilder::once(doc_settings(8, 100, 100, 100, 180)),
        milliseconds(500));
  const float above_max_gain = std::nextafter(100.0F, 1000.0F);
  b.add("settings-p-over", "SETTINGS COI 9 P just above 100 (the next float32): error",
        ExchangeKind::error,
        ProbeBuilder::once(doc_setting(9, SettingCode::p, wr8::Word::from_f32(above_max_gain))));
  b.add("settings-i-negative", "SETTINGS COI 10 I -0.5: error", ExchangeKind::error,
        ProbeBuilder::once(doc_setting(10, SettingCode::i, wr8::Word::from_f32(-0.5F))));
  b.add("settings-servo-over", "SETTINGS COI 11 servo zero 181: error", ExchangeKind::error,
        ProbeBuilder::once(doc_setting(11, SettingCode::servo_zero, wr8::Word::from_i32(181))));
  b.add("settings-servo-under", "SETTINGS COI 12 servo zero -1: error", ExchangeKind::error,
        ProbeBuilder::once(doc_setting(12, SettingCode::servo_zero, wr8::Word::from_i32(-1))));
  b.add("settings-restore", "SETTINGS COI 13 back to the defaults: completed",
        ExchangeKind::command, ProbeBuilder::once(doc_settings(13, kP, kI, kD, kServoZero)),
        milliseconds(500));

  b.add("drive", "TASK drive 10 cm COI 20: started, then completed", ExchangeKind::command,
        ProbeBuilder::once(doc_task(20, TaskCode::drive, {i32(10)})), milliseconds(2500));
  b.add("drive-min", "TASK drive 1 cm COI 21 (the shortest): started, then completed",
        ExchangeKind::boundary, ProbeBuilder::once(doc_task(21, TaskCode::drive, {i32(1)})),
        milliseconds(1500));
  b.add("drive-zero", "TASK drive 0 cm COI 22: error", ExchangeKind::error,
        ProbeBuilder::once(doc_task(22, TaskCode::drive, {i32(0)})));
  b.add("turn", "TASK turn 15 degrees COI 24: started, then completed", ExchangeKind::command,
        ProbeBuilder::once(doc_task(24, TaskCode::turn, {i32(15)})), milliseconds(800));
  b.add("turn-min", "TASK turn -30 degrees COI 25 (the lowest): started, then completed",
        ExchangeKind::boundary, ProbeBuilder::once(doc_task(25, TaskCode::turn, {i32(-30)})),
        milliseconds(800));
  b.add("turn-max", "TASK turn 30 degrees COI 26 (the highest): started, then completed",
        ExchangeKind::boundary, ProbeBuilder::once(doc_task(26, TaskCode::turn, {i32(30)})),
        milliseconds(800));
  b.add("turn-over", "TASK turn 31 degrees COI 27: error", ExchangeKind::error,
        ProbeBuilder::once(doc_task(27, TaskCode::turn, {i32(31)})));
  b.add("turn-under", "TASK turn -31 degrees COI 28: error", ExchangeKind::error,
        ProbeBuilder::once(doc_task(28, TaskCode::turn, {i32(-31)})));
  b.add("motion-busy",
        "TASK turn 0 COI 29, 10 ms later TASK drive 5 cm COI 30: the drive is refused while "
        "the turn runs",
        ExchangeKind::error,
        {{Duration{0}, doc_task(29, TaskCode::turn, {i32(0)})},
         {milliseconds(10), doc_task(30, TaskCode::drive, {i32(5)})}},
        milliseconds(800));
  b.add("blink",
        "TASK blink COI 31, 100 ms later a second blink COI 32: started, error for the second, "
        "completed after 2 s",
        ExchangeKind::command,
        {{Duration{0}, doc_task(31, TaskCode::blink)},
         {milliseconds(100), doc_task(32, TaskCode::blink)}},
        milliseconds(2500));
}

void document_errors(ProbeBuilder& b) {
  using wr8::TaskCode;
  // Each malformed TASK or SETTINGS still carries its COI at byte 1.
  b.add("task-bad-size", "TASK COI 40 whose size byte (3) is no multiple of 4: error",
        ExchangeKind::error, ProbeBuilder::once(wr8::raw_packet(3, Bytes{40, 1, 3, 0x0A, 0, 0})));
  b.add("task-missing-parameter", "TASK drive COI 41 without its distance: error",
        ExchangeKind::error, ProbeBuilder::once(doc_task(41, TaskCode::drive)));
  b.add("task-unknown-code", "TASK COI 42 with task code 9: error", ExchangeKind::error,
        ProbeBuilder::once(doc_task(42, static_cast<TaskCode>(9))));
  b.add("settings-bad-size", "SETTINGS COI 43 whose size byte (4) is no multiple of 5: error",
        ExchangeKind::error, ProbeBuilder::once(wr8::raw_packet(4, Bytes{43, 4, 0, 0, 0, 0})));
  b.add("settings-unknown-type", "SETTINGS COI 44 with setting type 7: error", ExchangeKind::error,
        ProbeBuilder::once(wr8::encode_unchecked(
            wr8::Settings{44, {{static_cast<wr8::SettingCode>(7), wr8::Word::from_i32(1)}}})));
  b.add("unknown-packet-code", "code 7 (no packet) and two bytes: skipped unanswered",
        ExchangeKind::error, ProbeBuilder::once(Bytes{0x07, 0x2A, 0x2A}));
  b.add("vehicle-packet", "a RESPONSE (a vehicle's packet) sent to the car: skipped unanswered",
        ExchangeKind::error,
        ProbeBuilder::once(doc(wr8::Response{45, wr8::ResponseCode::completed})));
  // 63 values is the most a size byte counting bytes can declare (252).
  b.add("oversized", "TASK check COI 46 with 63 parameters (256 bytes, the longest TASK): error",
        ExchangeKind::error,
        ProbeBuilder::once(doc_task(46, TaskCode::check, std::vector<wr8::Word>(63, wr8::Word{}))));
  b.add("garbage-between-frames",
        "FF FE, TASK check COI 47, 7F 80, TASK check COI 48 in one write: both completed",
        ExchangeKind::framing,
        ProbeBuilder::once(ProbeBuilder::join({Bytes{0xFF, 0xFE}, doc_task(47, TaskCode::check),
                                               Bytes{0x7F, 0x80}, doc_task(48, TaskCode::check)})));
  b.add("split-bytes", "SETTINGS COI 49 (the defaults) one byte every 5 ms: completed",
        ExchangeKind::framing,
        ProbeBuilder::bytewise(doc_settings(49, kP, kI, kD, kServoZero), kByteGap));
  b.add("two-frames-one-write", "TASK check COI 50 and COI 51 in one write: both completed",
        ExchangeKind::framing,
        ProbeBuilder::once(
            ProbeBuilder::join({doc_task(50, TaskCode::check), doc_task(51, TaskCode::check)})));
}

void document_probe(ProbeBuilder& b) {
  using wr8::TaskCode;
  b.connect("connect", "open the connection: no DATA before a login");
  document_login(b);
  document_commands(b);
  document_errors(b);
  b.listen("telemetry", "listen: DATA every 100 ms (state, time, odometry, speed, angle, battery)",
           milliseconds(1100));
  b.connect("reconnect", "close and open again: the session ends, no DATA");
  b.add("task-after-reconnect", "TASK check COI 60 on the new connection: dropped, no login yet",
        ExchangeKind::error, ProbeBuilder::once(doc_task(60, TaskCode::check)));
  b.add("auth-after-reconnect", "AUTH with the profile's string: AUTH-REPLY, DATA again",
        ExchangeKind::command, ProbeBuilder::once(doc_good_auth()), kReply, true);
  b.add("stop", "TASK turn 0 COI 61 (wheels straight): started, completed; then the close",
        ExchangeKind::stop, ProbeBuilder::once(doc_task(61, TaskCode::turn, {i32(0)})),
        milliseconds(800));
}

// ------------------------------------------------------------- svgui-2019

constexpr auto kV2019 = svgui::Version::v2019;
constexpr auto kHead = svgui::Version::head;

Bytes v19(const svgui::Message& m) {
  return svgui::encode_prefixed(m, kV2019);
}
Bytes v19_task(std::uint8_t coi, std::uint8_t type, std::vector<std::int32_t> params = {}) {
  return v19(svgui::Task{coi, type, std::move(params)});
}
constexpr std::uint8_t kForward = 1;
constexpr std::uint8_t kWheels = 2;
constexpr std::uint8_t kSignals = 3;

Bytes auth_2019() {
  return v19(svgui::Auth{ProbeBuilder::bytes("konnichiwa")});
}
Bytes auth_head() {
  Bytes text = ProbeBuilder::bytes("konnichiwa");
  text.push_back(0);
  return svgui::encode_prefixed(svgui::Auth{text}, kHead);
}

void v2019_commands(ProbeBuilder& b) {
  b.add("auth-head-form", "the head GUI's AUTH (length byte 12, NUL at the end): no answer",
        ExchangeKind::error, ProbeBuilder::once(auth_head()));
  b.add("auth-bad", "AUTH whose text does not end in konnichiwa: no answer, kept open",
        ExchangeKind::error,
        ProbeBuilder::once(v19(svgui::Auth{ProbeBuilder::bytes("sayonara!!")})));
  b.add("auth", "AUTH konnichiwa (length byte 11): AUTH-REPLY 1 2 WAIT", ExchangeKind::command,
        ProbeBuilder::once(auth_2019()));
  b.add("auth-again", "AUTH again: the same AUTH-REPLY", ExchangeKind::command,
        ProbeBuilder::once(auth_2019()));
  b.add("wheels", "TASK wheels 15 degrees COI 2: ANSWER 2 done when the wheels are there",
        ExchangeKind::command, ProbeBuilder::once(v19_task(2, kWheels, {15})), milliseconds(800));
  b.add("wheels-int-max", "TASK wheels 2147483647 degrees COI 3 (int32's highest): done",
        ExchangeKind::boundary,
        ProbeBuilder::once(v19_task(3, kWheels, {std::numeric_limits<std::int32_t>::max()})),
        milliseconds(800));
  b.add("wheels-int-min", "TASK wheels -2147483648 degrees COI 4 (int32's lowest): done",
        ExchangeKind::boundary,
        ProbeBuilder::once(v19_task(4, kWheels, {std::numeric_limits<std::int32_t>::min()})),
        milliseconds(800));
  b.add("task-coi-0", "TASK wheels 0 COI 0 (the idle COI): done with COI 0", ExchangeKind::boundary,
        ProbeBuilder::once(v19_task(0, kWheels, {0})), milliseconds(800));
  b.add("task-coi-255", "TASK wheels 0 COI 255 (the highest COI): done", ExchangeKind::boundary,
        ProbeBuilder::once(v19_task(255, kWheels, {0})));
  b.add("forward", "TASK forward 10 cm COI 5: ANSWER done (no started)", ExchangeKind::command,
        ProbeBuilder::once(v19_task(5, kForward, {10})), milliseconds(2000));
  b.add("forward-back", "TASK forward -10 cm COI 6 (backwards): done", ExchangeKind::boundary,
        ProbeBuilder::once(v19_task(6, kForward, {-10})), milliseconds(2000));
  b.add("forward-zero", "TASK forward 0 cm COI 7: done", ExchangeKind::boundary,
        ProbeBuilder::once(v19_task(7, kForward, {0})), milliseconds(800));
  b.add("busy",
        "TASK forward 5 cm COI 8, 50 ms later TASK wheels 0 COI 9: the second is dropped while "
        "the first runs",
        ExchangeKind::error,
        {{Duration{0}, v19_task(8, kForward, {5})}, {milliseconds(50), v19_task(9, kWheels, {0})}},
        milliseconds(2000));
  b.add("signals", "TASK turn signals COI 10: done after 2 s", ExchangeKind::command,
        ProbeBuilder::once(v19_task(10, kSignals)), milliseconds(2500));
  // The vehicle reads int32 at bytes 2, 7, 12 and 17: these values read
  // back as p 1, i 0, d 0, servo zero 90 (the defaults), so the garbling
  // moves nothing. COI 0 leaves the vehicle idle.
  b.add("settings",
        "SETTINGS COI 0 whose garbled read is p 1 i 0 d 0 servo zero 90: no answer, not busy",
        ExchangeKind::command, ProbeBuilder::once(v19(svgui::Settings{0, {1, 0, 0, 0x5A000000}})));
  b.add("task-after-settings", "TASK wheels 0 COI 11 after a COI 0 SETTINGS: done",
        ExchangeKind::command, ProbeBuilder::once(v19_task(11, kWheels, {0})));
}

void v2019_errors(ProbeBuilder& b) {
  b.add("task-type-4", "TASK type 4 (the document's get-settings) COI 0: no action, no answer",
        ExchangeKind::error, ProbeBuilder::once(v19_task(0, 4)));
  b.add("task-unknown-type", "TASK type 9 COI 0: no action, no answer", ExchangeKind::error,
        ProbeBuilder::once(v19_task(0, 9)));
  b.add("task-missing-parameter", "TASK forward COI 20 without a parameter: dropped unread",
        ExchangeKind::error, ProbeBuilder::once(v19_task(20, kForward)));
  b.add("task-short", "TASK wheels COI 21 declaring 2 parameters, carrying 1: dropped unread",
        ExchangeKind::error,
        ProbeBuilder::once(ProbeBuilder::join({Bytes{8, 3, 21, kWheels, 2}, Bytes{0, 0, 0, 0}})));
  b.add("unknown-packet-code", "a packet of code 7: no answer", ExchangeKind::error,
        ProbeBuilder::once(Bytes{2, 7, 0}));
  b.add("length-zero", "a length byte 0 alone: no answer", ExchangeKind::error,
        ProbeBuilder::once(Bytes{0}));
  // Length byte 0x80 is negative to the program, which reads whatever came.
  // The codec frames no packet of 128 bytes: a 30-parameter TASK is made
  // one parameter longer by hand.
  Bytes oversized{0x80};
  Bytes wheels = svgui::encode(svgui::Task{22, kWheels, std::vector<std::int32_t>(30, 0)}, kV2019);
  wheels[3] = 31;
  wheels.insert(wheels.end(), 4, 0);
  oversized.insert(oversized.end(), wheels.begin(), wheels.end());
  b.add("oversized",
        "length byte 80 and a 128-byte TASK wheels 0 COI 22 (31 parameters): read whole, done",
        ExchangeKind::error, ProbeBuilder::once(oversized));
  b.add("garbage-between-frames",
        "TASK wheels 0 COI 23, FF FE, TASK wheels 0 COI 24 in one write: read as one packet",
        ExchangeKind::framing,
        ProbeBuilder::once(ProbeBuilder::join(
            {v19_task(23, kWheels, {0}), Bytes{0xFF, 0xFE}, v19_task(24, kWheels, {0})})));
  b.add("split-bytes", "TASK wheels 0 COI 25 one byte every 5 ms: every byte a packet, no answer",
        ExchangeKind::framing, ProbeBuilder::bytewise(v19_task(25, kWheels, {0}), kByteGap));
  b.add("two-frames-one-write",
        "TASK wheels 0 COI 26 and COI 27 in one write: read as one, only 26 is done",
        ExchangeKind::framing,
        ProbeBuilder::once(
            ProbeBuilder::join({v19_task(26, kWheels, {0}), v19_task(27, kWheels, {0})})));
}

void v2019_probe(ProbeBuilder& b) {
  b.connect("connect", "open the connection: DATA every 100 ms from the start");
  b.add("task-before-auth", "TASK wheels 0 COI 1 before any AUTH: served, ANSWER 1 done",
        ExchangeKind::command, ProbeBuilder::once(v19_task(1, kWheels, {0})));
  v2019_commands(b);
  v2019_errors(b);
  b.listen("telemetry", "listen: DATA every 100 ms (state, time, encoder, steering, batteries)",
           milliseconds(1100));
  b.connect("reconnect", "close and open again: DATA from the start again");
  b.add("task-after-reconnect", "TASK wheels 0 COI 30 on the new connection: served, done",
        ExchangeKind::command, ProbeBuilder::once(v19_task(30, kWheels, {0})));
  b.add("stop", "TASK wheels 0 COI 31 (wheels straight): done; then the close", ExchangeKind::stop,
        ProbeBuilder::once(v19_task(31, kWheels, {0})), milliseconds(500));
}

// ------------------------------------------------------------- svgui-head

Bytes head(const svgui::Message& m) {
  return svgui::encode_prefixed(m, kHead);
}
/// SET's defaults in kSetNames order (docs/mocks/wr8.md, SvguiConfig).
constexpr std::array<double, 12> kHeadSet = {1, 0, 0, 90, 1, 0.1, 0, 10, 1, 0.1, 0, 10};
Bytes head_set(std::array<double, 12> values) {
  return head(svgui::Set{values});
}
Bytes head_control(double x, double y) {
  return head(svgui::Control{x, y});
}
Bytes set_request() {
  return head(svgui::SetRequest{});
}

void head_commands(ProbeBuilder& b) {
  b.add("auth-v2019-form", "the v2019 GUI's AUTH (length byte 11, no NUL): AUTH-REPLY and MAP",
        ExchangeKind::command, ProbeBuilder::once(auth_2019()), kReply, true);
  b.add("auth-bad", "AUTH whose text does not end in konnichiwa: no answer, kept open",
        ExchangeKind::error,
        ProbeBuilder::once(head(svgui::Auth{ProbeBuilder::bytes("sayonara!!")})));
  b.add("auth", "AUTH konnichiwa and NUL: AUTH-REPLY 1 2 WAIT, then the MAP", ExchangeKind::command,
        ProbeBuilder::once(auth_head()), kReply, true);
  b.add("set-request", "SET-REQUEST: a SET of the twelve settings in force", ExchangeKind::command,
        ProbeBuilder::once(set_request()));
  auto changed = kHeadSet;
  changed[0] = 2.5;  // steering p
  b.add("set", "SET with steering p 2.5, 50 ms later SET-REQUEST: no answer to SET, the SET back",
        ExchangeKind::command,
        {{Duration{0}, head_set(changed)}, {milliseconds(50), set_request()}});
  auto extremes = kHeadSet;
  extremes[7] = std::numeric_limits<double>::max();      // forward integral limit
  extremes[11] = std::numeric_limits<double>::lowest();  // backward integral limit
  b.add("set-extremes",
        "SET with the integral limits at the largest and lowest doubles, then SET-REQUEST",
        ExchangeKind::boundary,
        {{Duration{0}, head_set(extremes)}, {milliseconds(50), set_request()}});
  auto nan = kHeadSet;
  nan[2] = std::numeric_limits<double>::quiet_NaN();
  b.add("set-nan", "SET with a NaN, then SET-REQUEST: the SET is dropped, the earlier one back",
        ExchangeKind::error, {{Duration{0}, head_set(nan)}, {milliseconds(50), set_request()}});
  b.add("set-defaults", "SET with the defaults: no answer", ExchangeKind::command,
        ProbeBuilder::once(head_set(kHeadSet)));
  b.add("control", "CONTROL x 0 y 0.2, 100 ms later x 0 y 0: a short creep, no answer",
        ExchangeKind::command,
        {{Duration{0}, head_control(0, 0.2)}, {milliseconds(100), head_control(0, 0)}});
  b.add("control-x-max", "CONTROL x 1 y 0 (full right, no speed): no answer",
        ExchangeKind::boundary, ProbeBuilder::once(head_control(1, 0)));
  b.add("control-x-min", "CONTROL x -1 y 0 (full left, no speed): no answer",
        ExchangeKind::boundary, ProbeBuilder::once(head_control(-1, 0)));
  b.add("control-y-max", "CONTROL x 0 y 1, 50 ms later x 0 y 0: full speed for 50 ms",
        ExchangeKind::boundary,
        {{Duration{0}, head_control(0, 1)}, {milliseconds(50), head_control(0, 0)}});
  b.add("control-x-over", "CONTROL x 1.5 y 0: clamped to full right, no answer",
        ExchangeKind::error, ProbeBuilder::once(head_control(1.5, 0)));
  b.add("control-nan", "CONTROL with a NaN axis: dropped", ExchangeKind::error,
        ProbeBuilder::once(head_control(std::numeric_limits<double>::quiet_NaN(), 0)));
}

void head_errors(ProbeBuilder& b) {
  b.add("task-v2019", "a v2019 TASK wheels 0 COI 1 (no packet of head): no answer",
        ExchangeKind::error, ProbeBuilder::once(v19_task(1, kWheels, {0})));
  b.add("unknown-packet-code", "a packet of code 11: no answer", ExchangeKind::error,
        ProbeBuilder::once(Bytes{2, 11, 0}));
  b.add("control-short", "CONTROL cut to 10 bytes (length byte 10): no answer", ExchangeKind::error,
        ProbeBuilder::once(Bytes{10, 10, 0, 0, 0, 1, 0, 0, 0, 0, 0}));
  b.add("length-zero", "a length byte 0 alone: no answer", ExchangeKind::error,
        ProbeBuilder::once(Bytes{0}));
  b.add("split-bytes", "SET-REQUEST one byte every 5 ms: each byte read as a length byte",
        ExchangeKind::framing, ProbeBuilder::bytewise(set_request(), kByteGap));
  // Each of these leaves bytes unread in the head program, which reads one
  // packet per arrival: a reconnect follows each.
  b.add("two-frames-one-write",
        "SET-REQUEST twice in one write: one SET back, the second request waits unread",
        ExchangeKind::framing,
        ProbeBuilder::once(ProbeBuilder::join({set_request(), set_request()})));
  b.connect("reconnect", "close and open again: the unread bytes go, DATA from the start");
  b.add("garbage-between-frames",
        "SET-REQUEST, FF FE, SET-REQUEST in one write: one SET back, the rest unread",
        ExchangeKind::framing,
        ProbeBuilder::once(ProbeBuilder::join({set_request(), Bytes{0xFF, 0xFE}, set_request()})));
  b.connect("reconnect-2", "close and open again");
  Bytes oversized{0x80};
  for (int k = 0; k < 128; ++k)
    oversized.push_back(0x7F);
  b.add("oversized", "length byte 80 and 128 bytes: the program reads no packet",
        ExchangeKind::error, ProbeBuilder::once(oversized));
}

void head_probe(ProbeBuilder& b) {
  b.connect("connect", "open the connection: HIGH-FREQ and LOW-FREQ DATA from the start");
  b.add("set-request-before-auth", "SET-REQUEST before any AUTH: served, a SET back",
        ExchangeKind::command, ProbeBuilder::once(set_request()));
  head_commands(b);
  b.listen("telemetry", "listen: HIGH-FREQ DATA every 50 ms, LOW-FREQ DATA every 1000 ms",
           milliseconds(2100));
  head_errors(b);
  b.connect("reconnect-3", "close and open again after the unreadable length byte");
  b.add("set-request-after-reconnect", "SET-REQUEST on the new connection: served, a SET back",
        ExchangeKind::command, ProbeBuilder::once(set_request()));
  b.add("stop", "CONTROL x 0 y 0: the car holds still; then the close", ExchangeKind::stop,
        ProbeBuilder::once(head_control(0, 0)));
}

}  // namespace
}  // namespace wr8_probe

Probe make_wr8_probe(std::string_view profile) {
  using namespace wr8_probe;
  // A TCP server: nothing restarts when the connection opens.
  ProbeBuilder b("wr8-probe/1", milliseconds(100), kReply);
  const auto version = svgui::version_of_profile(profile);
  if (!version) {
    document_probe(b);
    return b.take({"DATA"});
  }
  if (*version == kV2019) {
    v2019_probe(b);
    return b.take({"DATA"});
  }
  head_probe(b);
  return b.take({"HIGH_FREQ_DATA", "LOW_FREQ_DATA"});
}

}  // namespace hil::conform
