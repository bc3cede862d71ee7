#pragma once
// A scenario as hil runs it: the car and its world, the client under test,
// the faults, the steps an operator and the car take, and the expectations
// the run must meet. Loaded from QA's YAML (harness/scenario_yaml.hpp); the
// language is in docs/scenarios.md.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/timeline.hpp"
#include "link/faults/profile.hpp"
#include "mocks/behaviour.hpp"
#include "mocks/car.hpp"

namespace hil::harness {

// ---------------------------------------------------------------- matching

/// One test on a record: `field` names a key of the record's data, or
/// "kind", or a key inside an object of it ("fields.percent"); prefix matching on frame kinds
/// follows the fault rules' rule (whole ':'- or '.'-separated parts: "MV" matches "MV:STOP").
struct FieldTest {
  enum class Op : std::uint8_t {
    equals,
    not_equals,
    kind_prefix,  ///< frame-kind prefix by whole parts
    contains,     ///< substring of a string field
    less,
    less_equal,
    greater,
    greater_equal,
    /// Either kind is a whole-part prefix of the other, the record's not
    /// empty: a frame that did not decode is named only as far as the
    /// decoder got ("FB" for a damaged "FB:SP").
    kind_either_prefix,
  };
  std::string field;
  Op op = Op::equals;
  nlohmann::json value;
  friend bool operator==(const FieldTest&, const FieldTest&) = default;
};

/// Which records count: a source, a kind (empty: any), and tests that must
/// all hold.
struct Matcher {
  Source source = Source::step;
  std::optional<RecordKind> kind;  ///< nullopt: any kind of `source`
  std::vector<FieldTest> tests;
  std::string text;  ///< as the scenario wrote it, for reports ("car received MV:STOP")
  friend bool operator==(const Matcher&, const Matcher&) = default;
};

/// A moment of the run: the start (no event), or the n-th record matching
/// `event` (n = 1 the first, -1 the last), moved by `offset`.
struct Anchor {
  std::optional<Matcher> event;
  int occurrence = 1;
  Duration offset{0};
  friend bool operator==(const Anchor&, const Anchor&) = default;
};

/// The span an expectation looks at: from `from` to `from + within`, both
/// ends included; without `within`, to the end of the run.
struct Window {
  Anchor from;
  std::optional<Duration> within;
  friend bool operator==(const Window&, const Window&) = default;
};

enum class Quantifier : std::uint8_t {
  exists,    ///< at least one match in the window (the default)
  never,     ///< no match in the window
  exactly,   ///< `count` matches
  at_least,  ///< `count` or more
  at_most,   ///< `count` or fewer
  at_times,  ///< a match within `tolerance` of each of `times` (from the window start)
  always,    ///< every record of the matcher's source and kind in the window passes its tests
};

struct Expectation {
  int line = 0;       ///< in the scenario file, for reports
  std::string label;  ///< the scenario's own words, or one made from the fields
  Matcher what;
  Window window;
  Quantifier quantifier = Quantifier::exists;
  std::uint64_t count = 0;
  std::vector<Duration> times;
  Duration tolerance{0};
  /// With at_times: no other match in the window either.
  bool only = false;
  friend bool operator==(const Expectation&, const Expectation&) = default;
};

// ------------------------------------------------------------------- steps

/// An operator action in the car's vocabulary ("speed 50", "press FWD"),
/// checked by the car's operator-language parser when the file loads.
struct ActionStep {
  std::string text;
  friend bool operator==(const ActionStep&, const ActionStep&) = default;
};
/// Let time pass.
struct WaitStep {
  Duration duration{0};
  friend bool operator==(const WaitStep&, const WaitStep&) = default;
};
/// Wait until a record matches; the step fails after `timeout`.
struct WaitUntilStep {
  Matcher until;
  Duration timeout{0};
  friend bool operator==(const WaitUntilStep&, const WaitUntilStep&) = default;
};
/// The car misbehaves on purpose: a scripted behaviour armed now (reject,
/// ignore, mute telemetry, send bytes, fault state, hang up).
struct CarStep {
  mocks::Behaviour behaviour;
  friend bool operator==(const CarStep&, const CarStep&) = default;
};
/// The link's faults from now on: `profile` replaces the current rules
/// (an empty profile turns faults off).
struct FaultsStep {
  link::FaultProfile profile;
  friend bool operator==(const FaultsStep&, const FaultsStep&) = default;
};
/// Something in the world: an obstacle put `ahead_m` in front of the car,
/// or taken away.
struct ObstacleStep {
  bool add = true;
  double ahead_m = 0.3;
  std::string name = "obstacle";
  friend bool operator==(const ObstacleStep&, const ObstacleStep&) = default;
};

using StepAction =
    std::variant<ActionStep, WaitStep, WaitUntilStep, CarStep, FaultsStep, ObstacleStep>;

struct Step {
  int line = 0;      ///< in the scenario file
  std::string text;  ///< as written, for reports and the timeline
  StepAction action;
  /// The step must fail (a NACK, a timeout, an uncertain command): it
  /// passes when it fails, and fails when it succeeds.
  bool expect_failure = false;
  /// With expect_failure: the failure's reason must contain this ("" any).
  std::string failure_contains;
  friend bool operator==(const Step&, const Step&) = default;
};

/// Steps that start at a time or when a record matches, beside the main
/// sequence (e.g. "at 5 s, drop the connection").
struct ScheduledStep {
  Anchor when;
  Step step;
  friend bool operator==(const ScheduledStep&, const ScheduledStep&) = default;
};

// ------------------------------------------------------------------ client

/// The built-in reference client, in virtual time unless `real_time`.
struct ReferenceClient {
  bool real_time = false;
  /// Options of the car's client library by name, as the scenario wrote
  /// them ({"auth": "WRONG-AUTH", "max_retries": "0"}, a list as an array);
  /// reference_settings() in harness/reference_settings.hpp lists them.
  nlohmann::json settings = nlohmann::json::object();
  friend bool operator==(const ReferenceClient&, const ReferenceClient&) = default;
};

/// An external program, run in real time. Placeholders in `command`:
/// {host} {port} {endpoint} {pty} {actions} (a file of the actions, one a
/// line) and {scenario}; the contract is in docs/client-contract.md.
struct ExecClient {
  std::string command;
  Duration startup_timeout{std::chrono::seconds(10)};
  friend bool operator==(const ExecClient&, const ExecClient&) = default;
};

using ClientSpec = std::variant<ReferenceClient, ExecClient>;

// ---------------------------------------------------------------- scenario

/// How the car must be when the run judges it, a while after the client
/// stopped (docs/scenarios.md, "The end of a run").
enum class AtEnd : std::uint8_t {
  at_rest,  ///< at rest, its motors not driven (the default)
  moving,   ///< still moving or driven: the scenario ends moving on purpose
  any,      ///< not judged
};

struct Scenario {
  std::string file;  ///< where it was loaded from ("" for one built in code)
  std::string name;
  std::string description;
  std::vector<std::string> tags;
  mocks::CarKind car = mocks::CarKind::logi;
  /// `car: {kind: ..., replay: FILE}`: the car plays a probe capture
  /// (mocks/replay.hpp) instead of its mock firmware; the capture is read
  /// when the scenario loads.
  std::optional<mocks::ReplaySpec> replay;
  /// `car: {kind: arduino, firmware: {sketch: FILE}}` (or `{elf: FILE}`):
  /// the Arduino car runs this firmware on the emulated board
  /// (mocks/avr/avr_firmware.hpp) instead of the behavioural mock; the
  /// sketch is built (or found in the cache) when the scenario loads.
  std::optional<mocks::AvrConfig> firmware;
  /// The car's profile (protocol/common/car_profile.hpp), mock and
  /// reference client alike; empty: the car's default.
  std::string profile;
  /// The car's processing time before each answer; none: its profile's
  /// (protocol/common/car_profile.hpp). Zero: in the same instant.
  std::optional<Duration> reply_latency;
  std::string world;                  ///< a world file; empty: the built-in arena for the car
  std::optional<std::uint64_t> seed;  ///< none: chosen per run and printed
  std::map<std::string, std::string> variables;  ///< ${name} in texts, already substituted
  link::FaultProfile faults;  ///< from the start; rules carry their own directions
  ClientSpec client = ReferenceClient{};
  std::vector<Step> setup;
  std::vector<Step> steps;
  std::vector<Step> teardown;  ///< run even when a step failed
  std::vector<ScheduledStep> schedule;
  std::vector<Expectation> expectations;
  /// The run ends at the latest this long after it started (then the
  /// remaining steps fail as "timed out").
  Duration timeout{std::chrono::seconds(120)};
  /// Time the run goes on after the last step, so late frames are seen.
  Duration settle{std::chrono::milliseconds(500)};
  /// How the car must be at the end, once the client has stopped.
  AtEnd at_end = AtEnd::at_rest;
};

}  // namespace hil::harness
