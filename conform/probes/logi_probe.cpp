// The LOGI car's probe: every command of the guide with valid and edge
// values, the decoder's error cases, and the cuts of the stream on which
// the guide's stream rule and the STM32's hand-over parser disagree
// (docs/protocols/logi.md, "Where the two differ"). The car moves only in
// MAN mode at 20 % for 300 ms at a time, and is stopped after each move.
#include <string>

#include "conform/probes/probe_builder.hpp"
#include "protocol/logi/codec.hpp"

namespace hil::conform {

using std::chrono::milliseconds;

namespace {

Bytes logi_frame(std::string_view payload) {
  return ProbeBuilder::bytes(protocol::logi::frame_text(payload));
}

// The two checksum digits (before the closing '#') in lowercase.
Bytes lowercase_checksum(Bytes frame) {
  for (std::size_t i = frame.size() - 3; i + 1 < frame.size(); ++i) {
    if (frame[i] >= 'A' && frame[i] <= 'F') frame[i] = static_cast<std::uint8_t>(frame[i] + 32);
  }
  return frame;
}

}  // namespace

Probe make_logi_probe(std::string_view profile) {
  (void)profile;  // both profiles take the same bytes; the probe finds which cut they use
  // Over Wi-Fi a LOGI car answers in tens of milliseconds; 300 ms leaves room.
  ProbeBuilder b("logi-probe/1", milliseconds(0), milliseconds(300));
  b.connect("connect", "open the TCP connection");
  b.listen("telemetry", "listen 5 s: STAT frames and their period", milliseconds(5000));
  b.send("sp-020", ExchangeKind::command, "SP:020, a low speed for the moves",
         logi_frame("SP:020"));
  b.send("sp-000", ExchangeKind::boundary, "SP:000, the lowest speed", logi_frame("SP:000"));
  b.send("sp-100", ExchangeKind::boundary, "SP:100, the highest speed", logi_frame("SP:100"));
  b.send("sp-101", ExchangeKind::error, "SP:101, one past the highest", logi_frame("SP:101"));
  b.send("sp-020-again", ExchangeKind::command, "SP:020 before the moves", logi_frame("SP:020"));
  b.send("md-man", ExchangeKind::command, "MD:MAN, manual mode", logi_frame("MD:MAN"));
  for (const char* dir : {"FWD", "BWD", "LEFT", "RIGHT", "LF", "RF", "LB", "RB", "CW", "CCW"}) {
    const std::string d = dir;
    b.send("mv-" + d, ExchangeKind::command, "MV:" + d + " for 300 ms", logi_frame("MV:" + d));
    b.send("mv-stop-after-" + d, ExchangeKind::command, "MV:STOP", logi_frame("MV:STOP"));
  }
  b.send("mv-bad-dir", ExchangeKind::error, "MV:UP, no such direction", logi_frame("MV:UP"));
  b.send("gs-001", ExchangeKind::boundary, "GS:001, the first station", logi_frame("GS:001"));
  b.send("gs-002", ExchangeKind::boundary, "GS:002, the last station", logi_frame("GS:002"));
  b.send("gs-000", ExchangeKind::error, "GS:000, not a station", logi_frame("GS:000"));
  b.send("gs-003", ExchangeKind::error, "GS:003, one past the last station", logi_frame("GS:003"));
  b.send("md-auto", ExchangeKind::command, "MD:AUTO, line tracking", logi_frame("MD:AUTO"));
  b.send("st-run", ExchangeKind::command, "ST:RUN in AUTO mode for 300 ms", logi_frame("ST:RUN"));
  b.send("st-stop", ExchangeKind::command, "ST:STOP", logi_frame("ST:STOP"));
  b.send("mv-in-auto", ExchangeKind::error, "MV:FWD in AUTO mode", logi_frame("MV:FWD"));
  b.send("md-man-again", ExchangeKind::command, "MD:MAN again", logi_frame("MD:MAN"));
  b.send("bad-checksum", ExchangeKind::error, "SP:050 with checksum 00",
         ProbeBuilder::bytes("LOGI:SP:050:00#"));
  b.send("lowercase-checksum", ExchangeKind::error,
         "SP:050 with its checksum in lowercase hex (d7)",
         lowercase_checksum(logi_frame("SP:050")));
  b.send("unknown-code", ExchangeKind::error, "ZZ:1, no such command", logi_frame("ZZ:1"));
  b.send("malformed-value", ExchangeKind::error, "SP:5X0, not a number", logi_frame("SP:5X0"));
  b.send("short-frame", ExchangeKind::error, "LOGI:X:0#, 9 bytes",
         ProbeBuilder::bytes("LOGI:X:0#"));
  b.send("oversized", ExchangeKind::error, "a header and 300 bytes without '#'",
         ProbeBuilder::join({ProbeBuilder::bytes("LOGI:SP:"), Bytes(300, '0')}));
  b.send("after-oversized", ExchangeKind::command, "SP:020 after the oversized frame",
         logi_frame("SP:020"));
  b.send("garbage-before", ExchangeKind::framing, "two bytes of garbage, then SP:020",
         ProbeBuilder::join({ProbeBuilder::bytes("xx"), logi_frame("SP:020")}));
  b.send("crlf-after", ExchangeKind::framing, "SP:020 followed by CR LF",
         ProbeBuilder::join({logi_frame("SP:020"), ProbeBuilder::bytes("\r\n")}));
  b.send("two-in-one-write", ExchangeKind::framing, "SP:020 and MD:MAN in one write",
         ProbeBuilder::join({logi_frame("SP:020"), logi_frame("MD:MAN")}));
  const Bytes sp = logi_frame("SP:020");
  b.send_pieces(
      "split-in-two", ExchangeKind::framing, "SP:020 as LOGI:SP:0, then the rest 50 ms later",
      {Bytes(sp.begin(), sp.begin() + 9), Bytes(sp.begin() + 9, sp.end())}, milliseconds(50));
  b.send_bytewise("split-in-bytes", "SP:020 one byte per write, 5 ms apart", logi_frame("SP:020"),
                  milliseconds(5));
  b.send("hash-inside", ExchangeKind::framing, "GS:0#1 with its sum over the whole text",
         ProbeBuilder::bytes(protocol::logi::frame_text("GS:0#1")));
  b.connect("reconnect", "close the connection and open it again");
  b.send("after-reconnect", ExchangeKind::command, "SP:020 on the new connection",
         logi_frame("SP:020"));
  b.send("stop", ExchangeKind::stop, "MV:STOP: the car ends at rest", logi_frame("MV:STOP"));
  return b.take({"STAT"});
}

}  // namespace hil::conform
