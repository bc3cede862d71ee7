#pragma once
// What a scenario asks of its car that the emulated board cannot give. The
// Arduino car as its real firmware (`car: {firmware: ...}`, `hil run
// --sketch/--elf`; mocks/avr/avr_firmware.hpp) runs the image as it is:
// scripted behaviours that change the firmware's own answers (reject,
// ignore, mute-telemetry, fault, clear-fault) and a reply latency have no
// effect on it, so a scenario that relies on them would pass or fail for
// the wrong reason. Sending bytes and closing the connection act on the
// link in front of the board and work with it (docs/firmware.md).

#include <cstddef>
#include <optional>
#include <string>

#include "harness/scenario.hpp"

namespace hil::harness {

/// Whether a scripted behaviour of this kind acts on the emulated board.
bool acts_on_emulated_board(const mocks::Action& action);

/// "a `reject` behaviour", "an `ignore` behaviour": the action's kind in a sentence.
std::string behaviour_phrase(const mocks::Action& action);

/// A step that arms a behaviour the emulated board cannot act on.
struct UnplayableStep {
  const char* list;    ///< the scenario's key: "setup", "steps", "teardown" or "schedule"
  const char* prefix;  ///< how messages name one of its steps: "setup step ", "step ", ...
  std::size_t index;   ///< in that list, from 0
  const Step* step;
  const mocks::Action* action;
};

/// The first such step, in the order setup, steps, teardown, schedule.
std::optional<UnplayableStep> first_unplayable_step(const Scenario& scenario);

/// Why the emulated board cannot play `scenario`'s car, or nullopt: it can.
/// The first of its armed behaviours that needs the behavioural mock ("it
/// arms a `reject` behaviour (step 2, line 27), which needs the behavioural
/// mock"), or its `reply_latency`.
std::optional<std::string> emulated_board_problem(const Scenario& scenario);

}  // namespace hil::harness
