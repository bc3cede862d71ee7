#pragma once
// Scripted misbehaviour of a mock firmware: what a scenario arms to make the
// car reject, swallow or volunteer frames, fall silent, fail or hang up, at
// a time or after a frame (docs/mocks.md, "Scripted behaviour").

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "link/byte_pipe.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/common/text.hpp"

namespace hil::mocks {

using link::Duration;
using link::Time;

/// When an armed behaviour fires. With neither condition set it fires at
/// once (the next time the firmware runs).
struct When {
  /// Run time it fires at (or the first time the firmware runs after it).
  std::optional<Time> at;
  /// Fires after the firmware has handled a client frame of this kind (same
  /// kind names and prefix matching as fault rules: "MV" matches "MV:FWD").
  std::string after_frame;
  /// With after_frame: fires after the N-th such frame (1 = the next one).
  std::uint64_t after_count = 1;
  friend bool operator==(const When&, const When&) = default;
};

/// Answer the next `count` commands of a kind negatively (LOGI FB:x:0, WR8
/// RESPONSE error, Arduino NACK, Leka: not run). The command has no effect.
struct Reject {
  std::string match;  ///< kind prefix; empty: every command
  std::uint64_t count = 1;
  friend bool operator==(const Reject&, const Reject&) = default;
};

/// Swallow commands of a kind: no answer and no effect, as if lost inside
/// the car. Ends after `count` commands or after `duration`, whichever is
/// set and comes first; with neither, ignores until the behaviours are
/// cleared.
struct Ignore {
  std::string match;
  std::optional<std::uint64_t> count;
  std::optional<Duration> duration;
  friend bool operator==(const Ignore&, const Ignore&) = default;
};

/// No periodic telemetry (LOGI STAT, WR8 DATA) for this long; answers to
/// commands still go out.
struct MuteTelemetry {
  Duration duration{};
  friend bool operator==(const MuteTelemetry&, const MuteTelemetry&) = default;
};

/// Sends these bytes to the client as they are (any frame, valid or not).
struct SendBytes {
  protocol::Bytes bytes;
  friend bool operator==(const SendBytes&, const SendBytes&) = default;
};

/// The firmware's fault state: motors stop, motion commands are refused,
/// and the state shows where the protocol can show it (WR8 state FAULT).
struct EnterFault {
  friend bool operator==(const EnterFault&, const EnterFault&) = default;
};
struct ClearFault {
  friend bool operator==(const ClearFault&, const ClearFault&) = default;
};

/// Closes the client's connection (graceful: FIN; reset: RST).
struct CloseConnection {
  link::CloseMode mode = link::CloseMode::graceful;
  friend bool operator==(const CloseConnection&, const CloseConnection&) = default;
};

using Action =
    std::variant<Reject, Ignore, MuteTelemetry, SendBytes, EnterFault, ClearFault, CloseConnection>;

struct Behaviour {
  std::string name;  ///< for logs; "#<n>" (1-based arming order) when empty
  When when;
  Action action;
  friend bool operator==(const Behaviour&, const Behaviour&) = default;
};

/// "reject", "ignore", "mute-telemetry", "send", "fault", "clear-fault", "close".
std::string_view action_name(const Action& action);

/// Kind-prefix matching by whole ':'- or '.'-separated parts, as fault rules
/// match (protocol/common/text.hpp).
using protocol::kind_matches;

/// What a firmware does with one command, after the armed behaviours had
/// their say.
enum class Disposition : std::uint8_t { handle, reject, ignore };

/// The armed behaviours of one firmware and their progress. Sans-I/O: the
/// firmware asks it what is due and acts on the answers.
class Script {
 public:
  void arm(Behaviour behaviour);
  /// Disarms everything, active rejects and ignores included.
  void clear();

  /// Behaviours whose time has come, in arming order, removed from the
  /// waiting list. Reject and Ignore actions become active at once.
  std::vector<Behaviour> take_due(Time now);
  /// The client frame of `kind` was handled; returns the behaviours it
  /// fired (after_frame), which became active as take_due() describes.
  std::vector<Behaviour> frame_handled(Time now, std::string_view kind);
  /// What to do with a command of `kind` now. Consumes one count of the
  /// first active reject or ignore that matches.
  Disposition dispose(Time now, std::string_view kind);

  /// Earliest `at` of a waiting behaviour, or the end of a timed ignore.
  std::optional<Time> next_due() const;
  std::size_t waiting() const { return waiting_.size(); }
  std::size_t active() const { return rejects_.size() + ignores_.size(); }

 private:
  struct Waiting {
    Behaviour behaviour;
    std::uint64_t frames_seen = 0;
  };
  struct ActiveIgnore {
    Ignore rule;
    std::optional<Time> until;
  };
  void activate(Time now, const Behaviour& b);
  void expire(Time now);
  /// Activates and hands back, in order, the waiting behaviours `ready` says are due.
  template <class Ready>
  std::vector<Behaviour> fire(Time now, Ready ready);

  std::vector<Waiting> waiting_;
  std::vector<Reject> rejects_;
  std::vector<ActiveIgnore> ignores_;
  std::uint64_t armed_ = 0;
};

}  // namespace hil::mocks
