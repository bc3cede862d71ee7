#pragma once
// What the random sessions of the client properties share: the ways a mock
// car misbehaves, as the scripted behaviour that makes it do so, and the
// command that lets virtual time run on.

#include <rapidcheck.h>

#include <ostream>

#include "link/byte_pipe.hpp"
#include "link/executor.hpp"
#include "mocks/behaviour.hpp"

namespace hil::test {

enum class Misbehaviour {
  ignore_all,      ///< answers nothing for a while
  reject_next,     ///< refuses the next request
  mute_telemetry,  ///< sends no telemetry for a while
  hang_up,         ///< closes the connection
  reset,           ///< resets the connection
};

/// Whether the misbehaviour lasts a while (and so has a duration to show).
constexpr bool lasts(Misbehaviour m) {
  return m == Misbehaviour::ignore_all || m == Misbehaviour::mute_telemetry;
}

/// The behaviour, armed at once, that makes the car misbehave so; `lasting`
/// is how long the lasting kinds last.
inline mocks::Behaviour misbehaviour(Misbehaviour m, link::Duration lasting) {
  mocks::Action action;
  switch (m) {
    case Misbehaviour::ignore_all:
      action = mocks::Ignore{.match = "", .count = {}, .duration = lasting};
      break;
    case Misbehaviour::reject_next:
      action = mocks::Reject{.match = "", .count = 1};
      break;
    case Misbehaviour::mute_telemetry:
      action = mocks::MuteTelemetry{lasting};
      break;
    case Misbehaviour::hang_up:
      action = mocks::CloseConnection{link::CloseMode::graceful};
      break;
    case Misbehaviour::reset:
      action = mocks::CloseConnection{link::CloseMode::reset};
      break;
  }
  return {.name = "", .when = {}, .action = action};
}

/// The session's wait: the rig's virtual time runs on by 1 .. kMaxMs - 1 ms.
template <class Command, class Model, class Rig, int kMaxMs>
struct AdvanceTime : Command {
  int ms = *rc::gen::inRange(1, kMaxMs);
  void apply(Model&) const override {}
  void run(const Model&, Rig& rig) const override {
    rig.car.executor.run_for(link::milliseconds(ms));
  }
  void show(std::ostream& os) const override { os << "advance " << ms << " ms"; }
};

}  // namespace hil::test
