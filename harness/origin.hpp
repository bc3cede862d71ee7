#pragma once
// The origin of a run: the moment every window, time edge and timed
// schedule entry that a scenario writes "from the start" counts from
// (docs/scenarios.md, "The origin"). For hil's reference client it is the
// run's start; for an external program it is the program's first contact
// with the car, so its start-up time does not eat into the windows.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "harness/timeline_recorder.hpp"
#include "link/executor.hpp"
#include "link/faults/profile.hpp"

namespace hil::harness {

struct Origin {
  enum class Cause : std::uint8_t {
    run_start,         ///< the reference client: time 0
    first_connection,  ///< the car accepted the program's first connection (or got its first byte)
    first_result,      ///< the program's first result line came before any connection
    program_start,     ///< neither came within its startup_timeout, or before it exited
  };
  Time at{0};
  Cause cause = Cause::run_start;
  friend bool operator==(const Origin&, const Origin&) = default;
};

/// "the client's first connection at +0.612 s": where the origin is.
std::string origin_text(const Origin& origin);

/// Whether a rule of `profile` fires at a run time (`at: 5s`) or is
/// active in a window of run times (`from`, `to`).
bool has_timed_rules(const link::FaultProfile& profile);
/// `profile` with every rule's run times moved `by` later (a window from 0
/// still opens at 0): its times counted from the origin.
link::FaultProfile moved(link::FaultProfile profile, Duration by);
/// `profile` as it stands while an external program's origin is not known
/// yet: what is in force from time 0 (a window from 0, a `refuse` or
/// `stall` at 0) stays in force, since its end counts from the origin, and
/// what starts later has not started. moved() puts the profile in force
/// once the origin is known.
link::FaultProfile awaiting_origin(link::FaultProfile profile);

/// Finds an external program's origin while the run goes on: the first
/// wire `open` or frame to the car in the timeline, the program's first
/// result line (first_result()), or, when neither came within
/// `startup_timeout` of the program's start, the program's start. Every
/// `when_fixed` callback runs once, when the origin is fixed, and a
/// client `origin` record marks it in the timeline.
class OriginWatch {
 public:
  /// Watches from now (the program's start); `executor` and `timeline`
  /// must outlive it.
  OriginWatch(link::Executor& executor, RunTimeline& timeline, Duration startup_timeout);
  ~OriginWatch();
  OriginWatch(const OriginWatch&) = delete;
  OriginWatch& operator=(const OriginWatch&) = delete;

  /// The program printed its first result line now.
  void first_result();
  /// Runs `f` with the origin once it is fixed (at once if it is).
  void when_fixed(std::function<void(const Origin&)> f);
  /// The origin, or nullopt while it is not fixed yet.
  const std::optional<Origin>& origin() const { return origin_; }
  /// The origin, fixed at the program's start if nothing came by now.
  Origin settled();

 private:
  void fix(Time at, Origin::Cause cause);

  link::Executor& executor_;
  RunTimeline& timeline_;
  Time program_start_{0};
  std::optional<Origin> origin_;
  std::vector<std::function<void(const Origin&)>> waiting_;
  RunTimeline::ListenerId listener_ = 0;
  link::Executor::TimerId timer_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::harness
