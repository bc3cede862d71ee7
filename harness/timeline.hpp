#pragma once
// What a scenario run saw, in time order: every frame on the wire (both
// directions, before and after faults), every fault, every client event and
// operator action, every step, and the simulated chassis. Expectations are
// checked against it; reports and the NDJSON timeline are written from it.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/record_kind.hpp"
#include "link/time.hpp"

namespace hil::harness {

using link::Duration;
using link::Time;

/// One thing that happened: its kind (harness/record_kind.hpp), which
/// names its source, and its data. `kind` and `data` by source (the full list, with
/// every field, is in docs/timeline.md, "The timeline"):
/// - wire, kind "frame": data {"dir": "to_car"|"to_client", "stage": "sent"|"delivered",
///   "frame": the frame's kind ("MV:STOP", "AUTH", "NACK"), "text" or "hex": the bytes,
///   "valid": bool, "error": why it is not valid ("checksum", ...)}; kind "open", "close"
///   (data {"by", "reason"}).
/// - fault: kind = the rule's kind ("drop", "corrupt", ...); data {"dir", "rule", "detail"}.
/// - client: kind "connection" {"state"}, "command" {"command", "state", "request"},
///   "stale", "notice" {"text"}, "action" {"index", "text", "ok", "reason"},
///   "output" {"line"} and "exit" {"code"} for an external program.
/// - sim: kind "sample" {"x_m", "y_m", "heading_deg", "speed_mps"} at a fixed period,
///   "station" {"station"}, "collision" {"with"}, "at_rest", "moving".
/// - step: kind "start" / "end" {"index", "line", "text", "ok", "reason"}.
/// - car: kind "behaviour" {"name"}, "fault_state" {"on"}.
/// Values the scenario loader's matchers compare with (so write exactly these):
/// - client "connection" state: "connecting", "authenticating", "connected",
///   "disconnected", "reconnecting" (waiting to reconnect); "command" state: the client
///   library's word ("sent", "accepted", "rejected", "uncertain", "cancelled"; WR8 also
///   "started", "completed", "error", "timed_out"); "command": the frame kind ("SP", "MV:FWD").
/// - client "action" text and step "text": Step::text exactly (the loader resolves
///   `{step: ...}` to it); "ok", wire "valid" and car "on" are JSON booleans.
/// - client "exit" code and sim "station" are JSON numbers (station 2, not "002");
///   sim "sample" fields are numbers in metres, degrees and m/s.
/// What the reference runner writes on top of the fields above:
/// - wire "frame": also "bytes" (count), "message" (a valid frame decoded, for a person),
///   "fields" (the message's name=value pairs as an object, numbers as numbers; absent when none);
///   for an invalid one "error" is the decoder's error kind ("bad_checksum", "garbage",
///   "bad_format", "truncated", ...) and "detail" its whole message. "open" {"client", "car"};
///   "close" also "mode" ("graceful" | "reset"). A refused connection has no open/close, only
///   its fault record.
/// - fault: also "frame_number" (1-based in its direction) when the rule acted on a frame.
/// - client "connection": also "attempt" (reconnect attempt, 0 for the operator's connect),
///   "detail" (the client's own name of the state where it has one, such as the Arduino
///   link's "OPEN", else the state's word), Arduino "reason"; the Arduino
///   link also reaches "degraded" and "down". "command": also "request" (the client's id),
///   LOGI "text" (the frame) and "attempt"; WR8 "command" is the task ("drive", "turn",
///   "settings"); Arduino has no "command" but "detail" ("ACK OK", "NACK BAD_V") and states
///   "ok", "nack", "timeout", "link_down", "invalid_request".
/// - client kinds "fresh" (the stale warning cleared), "login" {"ok", "reason"} (WR8),
///   "parse_error" {"text"} (a frame the client could not decode), "movement" {"enabled",
///   "reason"} (LOGI: whether movement controls are enabled).
/// - sim "station": also "tag" (the tag's id, "002"; "station" is the tag's id when it is not
///   a number). "moving" when the chassis reaches 5 mm/s or 0.02 rad/s, "at_rest" when both
///   fall below half of that; a run starts with an "at_rest" at 0. Stations, collisions and
///   rest are looked at every 10 ms, samples at RunOptions::sample_period from 0.
/// - step "start" / "end": also "phase" ("setup", "steps", "teardown", "schedule"); "index"
///   is the step's place in ScenarioOutcome::steps; only "end" has "ok" and "reason".
/// - car "behaviour" when a car step arms it: {"name", "action"} ("reject", "close", ...).
struct Record {
  Time at{0};
  RecordKind kind{StepKind::start};
  nlohmann::json data = nlohmann::json::object();

  Source source() const { return kind.source(); }
};

/// Records in the order they happened (equal times keep arrival order).
class Timeline {
 public:
  void add(Record record);
  void add(Time at, RecordKind kind, nlohmann::json data = nlohmann::json::object());

  const std::vector<Record>& records() const { return records_; }
  std::size_t size() const { return records_.size(); }
  bool empty() const { return records_.empty(); }

  /// One JSON object per line: {"t_ms": .., "source": .., "kind": .., ...data}.
  std::string to_ndjson() const;
  static nlohmann::ordered_json to_json(const Record& record);

 private:
  std::vector<Record> records_;
};

}  // namespace hil::harness
