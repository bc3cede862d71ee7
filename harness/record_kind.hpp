#pragma once
// The kinds of timeline records, one enum per source, and RecordKind, which
// names one of them. Everything that writes a record (the recorder, the
// runner, the client sessions), reads one (expectations, reports) or
// matches one (the scenario loader's matchers) uses these types; the words
// ("frame", "connection", "at_rest") exist only in to_string and
// parse_record_kind, which is also what the NDJSON timeline and the
// scenario language are written in.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string_view>

#include "link/faults/profile.hpp"

namespace hil::harness {

/// Where a record came from.
enum class Source : std::uint8_t {
  wire,    ///< a frame crossing the link, a link open/close
  fault,   ///< the fault injector acted
  client,  ///< the client reported something (reference events, an external program's output
           ///< or exit)
  sim,     ///< the simulated chassis (samples, stations, collisions, rest)
  step,    ///< the scenario's own steps (operator actions, car events, waits)
  car,     ///< the mock firmware (behaviours fired, fault state)
};
std::string_view to_string(Source source);  ///< "wire", "fault", ...
std::optional<Source> parse_source(std::string_view text);

enum class WireKind : std::uint8_t { frame, open, close };
enum class ClientKind : std::uint8_t {
  connection,   ///< the connection's state changed
  command,      ///< a command's state changed
  stale,        ///< the car's telemetry went stale
  fresh,        ///< ... and came back
  notice,       ///< something for the operator
  action,       ///< an operator action ended
  login,        ///< WR8: the login's answer
  parse_error,  ///< a frame the client could not decode
  movement,     ///< LOGI: movement controls enabled or not
  output,       ///< an external program's line of output
  exit,         ///< an external program ended
  start,        ///< an external program started
  origin,       ///< where an external program's run time counts from (harness/origin.hpp)
};
enum class SimKind : std::uint8_t { sample, station, collision, at_rest, moving };
enum class StepKind : std::uint8_t { start, end };
enum class CarEventKind : std::uint8_t { behaviour, fault_state };
/// A fault record's kind is its rule's: link::FaultKind.

std::string_view to_string(WireKind kind);
std::string_view to_string(ClientKind kind);
std::string_view to_string(SimKind kind);
std::string_view to_string(StepKind kind);
std::string_view to_string(CarEventKind kind);

/// One record kind of one source: `RecordKind(SimKind::at_rest)`.
class RecordKind {
 public:
  constexpr RecordKind(WireKind k) : source_(Source::wire), value_(index(k)) {}
  constexpr RecordKind(link::FaultKind k) : source_(Source::fault), value_(index(k)) {}
  constexpr RecordKind(ClientKind k) : source_(Source::client), value_(index(k)) {}
  constexpr RecordKind(SimKind k) : source_(Source::sim), value_(index(k)) {}
  constexpr RecordKind(StepKind k) : source_(Source::step), value_(index(k)) {}
  constexpr RecordKind(CarEventKind k) : source_(Source::car), value_(index(k)) {}

  constexpr Source source() const { return source_; }
  /// The kind within its source: "frame", "drop", "connection", ...
  std::string_view name() const;

  /// The kind `E` when this is one of the source of E, else nullopt.
  template <typename E>
  constexpr std::optional<E> as() const {
    if (RecordKind(E{}).source_ != source_) return std::nullopt;
    return static_cast<E>(value_);
  }

  friend constexpr bool operator==(RecordKind, RecordKind) = default;

 private:
  template <typename E>
  static constexpr std::uint8_t index(E e) {
    return static_cast<std::uint8_t>(e);
  }

  Source source_;
  std::uint8_t value_;
};

/// "source/name", for test messages.
std::ostream& operator<<(std::ostream& out, RecordKind kind);

/// The kind `name` of `source` ("sample" of sim); nullopt for a word that is
/// not one.
std::optional<RecordKind> parse_record_kind(Source source, std::string_view name);

}  // namespace hil::harness
