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

#include "link/time.hpp"

namespace hil::harness {

using link::Duration;
using link::Time;

/// Where a record came from.
enum class Source : std::uint8_t {
  wire,    ///< a frame crossing the link, a link open/close
  fault,   ///< the fault injector acted
  client,  ///< the client reported something (reference events, an external program's output or
           ///< exit)
  sim,     ///< the simulated chassis (samples, stations, collisions, rest)
  step,    ///< the scenario's own steps (operator actions, car events, waits)
  car,     ///< the mock firmware (behaviours fired, fault state)
};
std::string_view to_string(Source source);  ///< "wire", "fault", ...

/// One thing that happened. `kind` and `data` by source (the full list, with
/// every field, is in docs/scenarios.md, "The timeline"):
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
struct Record {
  Time at{0};
  Source source = Source::step;
  std::string kind;
  nlohmann::json data = nlohmann::json::object();
};

/// Records in the order they happened (equal times keep arrival order).
class Timeline {
 public:
  void add(Record record);
  void add(Time at, Source source, std::string kind,
           nlohmann::json data = nlohmann::json::object());

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
