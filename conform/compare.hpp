#pragma once
// Compares two captures of one probe exchange by exchange: a car's and a
// mock's (or two cars'). What is compared, and how close is close enough,
// is described in docs/conformance.md.
#include <cstddef>
#include <string>
#include <vector>

#include "conform/probe.hpp"
#include "link/capture/probe_capture.hpp"

namespace hil::conform {

/// How far the mock's timing may be from the car's and still match.
struct Tolerances {
  /// Reply latency (from the exchange's last write before the answer to
  /// the answer's first frame): within the larger of these.
  Duration latency_abs = std::chrono::milliseconds(50);
  double latency_rel = 0.5;
  /// Telemetry period (median interval of a kind's frames): within the
  /// larger of these.
  Duration period_abs = std::chrono::milliseconds(10);
  double period_rel = 0.2;
};

/// One side's answer in one exchange, as the report shows it.
struct Answer {
  std::vector<std::string> frames;  ///< each frame for a person: its text, or kind and hex
  std::size_t closes = 0;           ///< times the car closed the connection
  std::optional<Duration> latency;  ///< to the first answer frame; nullopt: no answer
  /// Per telemetry kind: frames seen and the median period (telemetry
  /// exchanges only).
  std::vector<std::pair<std::string, std::optional<Duration>>> periods;
  /// One line: "^01|ACK|PONG*..$", "(silent)", "(closed)".
  std::string summary() const;
};

struct ExchangeComparison {
  std::string name;
  std::string what;
  ExchangeKind kind = ExchangeKind::command;
  Answer car;
  Answer mock;
  /// Empty when the exchange matches; else one line per difference.
  std::vector<std::string> differences;
  /// Profiles of the car whose mock answers this exchange as the car did
  /// (filled in by check(), for a difference).
  std::vector<std::string> explained_by;
  bool matches() const { return differences.empty(); }
};

struct Comparison {
  std::string mock_profile;
  std::vector<ExchangeComparison> exchanges;
  std::size_t matches() const;
  bool all_match() const { return matches() == exchanges.size(); }
};

/// Compares `car` and `mock`, both captures of `probe` (same exchanges in
/// the same order; a capture cut short has its missing exchanges differ).
Comparison compare(const Capture& car, const Capture& mock, const Probe& probe,
                   std::string mock_profile, const Tolerances& tolerances = {});

}  // namespace hil::conform
