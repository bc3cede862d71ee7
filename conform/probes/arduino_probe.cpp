// The Arduino robot's probe: every command of the README and of the real
// sketch, each request without an argument first in both payload forms
// (empty, as the README writes it, and one space, as the real RobotClient
// sends it) and afterwards in the probed profile's form, the edges of V,
// and every way the sketch's parser drops or refuses a frame
// (docs/protocols/arduino.md, "Profiles").
// Moves are 10 to 20 cm and rotations 15 degrees, each stopped with S.
#include <string>

#include "conform/probes/probe_builder.hpp"
#include "protocol/arduino/codec.hpp"

namespace hil::conform {

using std::chrono::milliseconds;

namespace {

class ArduinoRequests {
 public:
  explicit ArduinoRequests(std::string_view profile)
      : no_argument_(protocol::arduino::empty_payload(protocol::arduino::dialect_named(profile))) {}
  /// A request without an argument, its payload as the profile writes it.
  Bytes frame(std::string cmd) { return frame(std::move(cmd), std::string(no_argument_)); }
  /// The next request's frame, its SEQ counting up from 01.
  Bytes frame(std::string cmd, std::string payload) {
    return ProbeBuilder::bytes(
        protocol::arduino::frame_text({next_seq(), std::move(cmd), std::move(payload)}));
  }
  std::uint8_t next_seq() { return seq_++; }
  /// A request without an argument whose checksum is one off.
  Bytes with_bad_checksum(std::string cmd) {
    auto text =
        protocol::arduino::frame_text({next_seq(), std::move(cmd), std::string(no_argument_)});
    const auto star = text.rfind('*');
    const auto wrong =
        static_cast<std::uint8_t>(std::stoi(text.substr(star + 1, 2), nullptr, 16) + 1);
    static constexpr char kHex[] = "0123456789ABCDEF";
    text[star + 1] = kHex[wrong >> 4];
    text[star + 2] = kHex[wrong & 0xF];
    return ProbeBuilder::bytes(text);
  }
  /// V with the first PWM from 100 up whose checksum has a hex letter, that
  /// letter written in lowercase (the sketch reads either case).
  Bytes with_lowercase_checksum() {
    const auto seq = next_seq();
    for (int pwm = 100;; ++pwm) {
      auto text = protocol::arduino::frame_text({seq, "V", std::to_string(pwm)});
      const auto star = text.rfind('*');
      bool letter = false;
      for (auto i = star + 1; i < star + 3; ++i) {
        if (text[i] >= 'A' && text[i] <= 'F') {
          text[i] = static_cast<char>(text[i] - 'A' + 'a');
          letter = true;
        }
      }
      if (letter) return ProbeBuilder::bytes(text);
    }
  }

 private:
  std::uint8_t seq_ = 1;
  std::string_view no_argument_;
};

}  // namespace

Probe make_arduino_probe(std::string_view profile) {
  // The board restarts when its port opens (the real client waits 1.5 s).
  // At 9600 baud the longest answer (HELP, 45 bytes) takes 47 ms on the
  // line; 250 ms leaves room for the sketch's 30 ms sonar wait.
  ProbeBuilder b("arduino-probe/1", milliseconds(2000), milliseconds(250));
  ArduinoRequests r(profile);
  b.connect("connect", "open the port and wait 2 s for the board to start");
  for (const char* cmd : {"PING", "HELP", "STATUS", "B", "I", "S"}) {
    const std::string c = cmd;
    std::string low = c;
    for (auto& ch : low)
      ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    b.send(low + "-space", ExchangeKind::command,
           c + " with a payload of one space, as the real client sends it", r.frame(c, " "));
    if (c != "PING" && c != "HELP" && c != "S") b.physical();
    b.send(low + "-empty", ExchangeKind::command,
           c + " with an empty payload, as the README writes it", r.frame(c, ""));
    if (c != "PING" && c != "HELP" && c != "S") b.physical();
  }
  b.send("v-160", ExchangeKind::command, "V 160", r.frame("V", "160"));
  b.send("v-0", ExchangeKind::boundary, "V 0, the lowest PWM", r.frame("V", "0"));
  b.send("v-255", ExchangeKind::boundary, "V 255, the highest PWM", r.frame("V", "255"));
  b.send("v-256", ExchangeKind::error, "V 256, one past the highest", r.frame("V", "256"));
  b.send("v-minus-1", ExchangeKind::error, "V -1, one below the lowest", r.frame("V", "-1"));
  b.send("v-abc", ExchangeKind::error, "V abc, not a number", r.frame("V", "abc"));
  b.send("v-100", ExchangeKind::command, "V 100, a low PWM for the moves", r.frame("V", "100"));
  b.send_pieces("m-20-status", ExchangeKind::command,
                "M 20 (about 360 ms), then STATUS 100 ms into the move",
                {r.frame("M", "20"), r.frame("STATUS")}, milliseconds(100));
  b.physical();
  b.send("s-after-m", ExchangeKind::command, "S stops the move", r.frame("S"));
  b.send("status-after-s", ExchangeKind::command, "STATUS after the stop", r.frame("STATUS"))
      .physical();
  b.send("m-minus-10", ExchangeKind::command, "M -10, backwards (about 180 ms)",
         r.frame("M", "-10"))
      .window(milliseconds(400));
  b.send("status-after-rev", ExchangeKind::command, "STATUS after the backward move ended",
         r.frame("STATUS"))
      .physical();
  b.send("r-15", ExchangeKind::command, "R 15 (about 90 ms)", r.frame("R", "15"))
      .window(milliseconds(400));
  b.send("m-0", ExchangeKind::boundary, "M 0", r.frame("M", "0"));
  b.send("s-final", ExchangeKind::command, "S", r.frame("S"));
  b.send("lowercase-command", ExchangeKind::command, "ping in lowercase", r.frame("ping"));
  b.send("unknown-command", ExchangeKind::error, "FOO 1, no such command", r.frame("FOO", "1"));
  b.send("bad-checksum", ExchangeKind::error, "PING with its checksum wrong",
         r.with_bad_checksum("PING"));
  b.send("lowercase-checksum", ExchangeKind::framing,
         "V with its checksum's hex letter in lowercase", r.with_lowercase_checksum());
  b.send("bad-seq", ExchangeKind::error, "PING with SEQ ZZ",
         ProbeBuilder::bytes(protocol::arduino::frame_body("ZZ|PING| ")));
  b.send("one-digit-seq", ExchangeKind::error, "PING with SEQ 5",
         ProbeBuilder::bytes(protocol::arduino::frame_body("5|PING| ")));
  b.send("two-fields", ExchangeKind::error, "a frame of SEQ and CMD only",
         ProbeBuilder::bytes(protocol::arduino::frame_body("40|PING")));
  b.send("fourth-field", ExchangeKind::framing, "PING with a fourth field",
         ProbeBuilder::bytes(protocol::arduino::frame_body("41|PING| |x")));
  b.send("one-char-checksum", ExchangeKind::error, "a checksum of one character",
         ProbeBuilder::bytes("^42|PING| *3$"));
  b.send("short-frame", ExchangeKind::error, "^1*00$, under 7 bytes", ProbeBuilder::bytes("^1*0$"));
  b.send("oversized", ExchangeKind::error, "a frame of 120 bytes",
         ProbeBuilder::bytes(protocol::arduino::frame_body("43|V|" + std::string(107, '1'))));
  b.send("after-oversized", ExchangeKind::command, "PING after the oversized frame",
         r.frame("PING"));
  b.send("garbage-between", ExchangeKind::framing, "garbage, PING, garbage, HELP in one write",
         ProbeBuilder::join({ProbeBuilder::bytes("xyz"), r.frame("PING"),
                             ProbeBuilder::bytes("\r\n"), r.frame("HELP")}));
  b.send("two-in-one-write", ExchangeKind::framing, "V 120 and PING in one write",
         ProbeBuilder::join({r.frame("V", "120"), r.frame("PING")}));
  b.send_bytewise("split-in-bytes", "PING one byte per write, 3 ms apart", r.frame("PING"),
                  milliseconds(3));
  b.connect("reconnect", "close the port and open it again (the board restarts)");
  b.send("status-after-reconnect", ExchangeKind::command, "STATUS after the restart",
         r.frame("STATUS"))
      .physical();
  b.send("stop", ExchangeKind::stop, "S: the robot ends at rest", r.frame("S"));
  return b.take();
}

}  // namespace hil::conform
