#pragma once
// Runs one scenario: builds the car and its world, puts the faults on the
// link, starts the client (the reference client in virtual time, or an
// external program in real time), plays the steps and the schedule,
// records the timeline, and checks the expectations.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "harness/outcome.hpp"
#include "harness/scenario.hpp"

namespace hil::harness {

class ScenarioClient;
struct ClientSetup;

/// The default slack of a run in real time: a loaded 2-core machine
/// delays a frame or a client's answer by tens of milliseconds.
inline constexpr Duration kRealTimeSlack = std::chrono::milliseconds(100);
/// The default slack of a real firmware on the emulated board in virtual
/// time: the sketch's own processing and the board's 250 us slices put its
/// frames up to about a millisecond after the behavioural mock's, which
/// answers in the instant the request's last byte is in (docs/firmware.md).
inline constexpr Duration kEmulatedBoardSlack = std::chrono::milliseconds(2);

/// `hil run -j auto`: runs in real time at once per core. Such a run mostly
/// waits (its car's clock, its client's answers), so on 2 cores 32 of the
/// LOGI library's runs with an external client go at once and every one
/// keeps its timing (docs/performance.md, "The gate's width").
inline constexpr std::size_t kRealTimeRunsPerCore = 16;

struct RunOptions {
  /// Overrides the scenario's seed (and a random choice when it has none).
  std::optional<std::uint64_t> seed;
  /// Runs every scenario against this external program instead of its own
  /// client (placeholders as in ExecClient::command).
  std::optional<std::string> client_exec;
  /// Plays every scenario's car from this probe capture instead of its
  /// mock firmware (`hil run --replay`); a scenario of another car, or of
  /// another profile than the capture's, is skipped (skip_reason()).
  std::optional<mocks::ReplaySpec> replay;
  /// Runs every Arduino scenario's car as this firmware on the emulated
  /// board instead of its own car (`hil run --sketch/--elf`); a scenario of
  /// another car, one that plays a capture, and one that asks for what the
  /// board cannot do (emulated_board_problem()) are skipped (skip_reason()).
  std::optional<mocks::AvrConfig> firmware;
  /// How `firmware` was given, for the skip reasons ("--elf robot.elf").
  std::string firmware_given = "the firmware";
  /// Told each warning of an emulated board (this run's firmware or the
  /// scenario's own), one line each.
  std::function<void(const std::string&)> on_firmware_note;
  /// Where reports may put files of this run (wire log); empty: nowhere.
  std::string work_dir;
  /// Room for real time in every expectation (check() in
  /// harness/expect.hpp); nullopt: 0 in virtual time, kRealTimeSlack in
  /// real time.
  std::optional<Duration> time_slack;
  /// Called with the exact shell command line of an external client, its
  /// placeholders filled in, just before it is started (hil run prints it:
  /// a scenario never starts a program a person cannot see).
  std::function<void(const std::string&)> on_client_command;
  /// Period of the simulation samples in the timeline.
  Duration sample_period{std::chrono::milliseconds(100)};
  /// Makes the client of a scenario that runs the car's reference client
  /// (harness/client_under_test.hpp), in its place: a test runs a library
  /// against a reference client with a bug planted in it. Returning null,
  /// or leaving this empty, keeps the car's own reference client; an
  /// external program is never replaced.
  std::function<std::unique_ptr<ScenarioClient>(const ClientSetup&)> reference_client;
};

/// Why `scenario` is not run with `options`, or nullopt: it is. A scenario
/// that sets options of hil's reference client (`client: reference:
/// settings:`) is skipped when RunOptions::client_exec puts an external
/// program in that client's place: hil cannot give the program those
/// options, and its verdict would judge a client set up otherwise. With
/// RunOptions::replay, a scenario of another car or profile than the
/// capture's is skipped: its client would speak to a car it was not
/// written for. With RunOptions::firmware, so is a scenario of another car
/// than the Arduino one, one that plays a capture, and one that arms a
/// behaviour or sets a reply latency the emulated board cannot act on: it
/// would pass or fail for the wrong reason.
std::optional<std::string> skip_reason(const Scenario& scenario, const RunOptions& options);

/// Whether a run of `scenario` with `options` is in real time: its client
/// is an external program (a scenario's `client: exec:` or
/// RunOptions::client_exec) or the reference client asked for real sockets
/// (`real_time: true`). Such a run mostly waits, on its clock and on the
/// client; one in virtual time keeps a core busy from start to end.
bool runs_in_real_time(const Scenario& scenario, const RunOptions& options);

/// Never throws for a scenario's own failures; they are in the outcome. A
/// scenario skip_reason() skips is not run: its outcome says why.
ScenarioOutcome run_scenario(const Scenario& scenario, const RunOptions& options = {});

}  // namespace hil::harness
