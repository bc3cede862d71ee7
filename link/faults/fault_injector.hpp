#pragma once
// The fault injector for one direction of one link. Sans-I/O: it is given
// the bytes the sender wrote and the time, and says which bytes to deliver
// when, and when to break the connection. Seeded: the same profile, seed
// and input give the same faults, byte for byte.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "link/faults/profile.hpp"
#include "link/protocol_adapter.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::link {

// Direction is defined with the profiles (link/faults/profile.hpp), whose
// rules filter on it.

/// One injected fault, for the run's timeline.
struct FaultEvent {
  Time at{0};
  Direction direction = Direction::to_car;
  FaultKind kind = FaultKind::drop;  ///< the kind of the rule that acted
  std::string rule;                  ///< the rule's name in the profile (or its index)
  std::uint64_t frame = 0;           ///< the frame acted on (1-based in this direction); 0: none
  protocol::Bytes before;            ///< the bytes the rule acted on
  protocol::Bytes after;             ///< what was delivered instead (empty for a drop)
  std::string detail;                ///< what happened, for a person
};
using FaultEventSink = std::function<void(const FaultEvent&)>;

/// Deliver these bytes to the receiver now.
struct Delivery {
  protocol::Bytes bytes;
};
/// Break the connection (graceful close or reset).
struct LinkBreak {
  bool reset = false;
};
using InjectorOutput = std::variant<Delivery, LinkBreak>;

/// With no rule for its direction an injector passes every write through
/// as it is, at once. Under rules, which act on whole frames, an incomplete
/// frame waits this long after the sender's last write for the rest of its
/// bytes; then its bytes go out as they were written: a car (or a `send`
/// behaviour) that writes part of a frame is heard as it is, not held back
/// until a frame that may never come. 100 ms spans the gaps between the
/// pieces of one frame on a 9600 baud line or a Wi-Fi hop.
inline constexpr Duration kPartialFrameHold = std::chrono::milliseconds(100);

class FaultInjector {
 public:
  /// `protocol` may be the raw adapter (every write is one frame). `start`
  /// is the run time the connection began: time-triggered rules (a reset at
  /// 7 s) whose time has already passed do not fire on a later connection.
  FaultInjector(Direction direction, std::shared_ptr<const ProtocolAdapter> protocol,
                FaultProfile profile, std::uint64_t seed, FaultEventSink sink = {},
                Time start = Time{0});
  ~FaultInjector();
  FaultInjector(FaultInjector&&) noexcept;
  FaultInjector& operator=(FaultInjector&&) noexcept;

  /// Bytes the sender wrote at `now`. A frame they leave incomplete is
  /// completed by later writes, or released kPartialFrameHold after the
  /// last one.
  void push(Time now, protocol::ByteView bytes);
  /// The sender closed: whatever is held (a partial frame) is released.
  /// Under a slow_close rule the end is held too: next_due() stays set
  /// until `now` plus its delay, and the end of the stream is to be passed
  /// on once next_due() is nullopt.
  void finish(Time now);
  /// Appends every output due at or before `now`, in order.
  void poll(Time now, std::vector<InjectorOutput>& out);
  /// When poll() next has something to give; nullopt when nothing is held.
  std::optional<Time> next_due() const;

  /// Replaces the rules while the link runs; the random stream and the frame
  /// counters carry on.
  void set_profile(FaultProfile profile);
  const FaultProfile& profile() const;

  /// Whether a new connection arriving at `now` is to be refused.
  bool refuse_connection(Time now) const;

  std::uint64_t seed() const;
  /// Frames seen and faults injected so far.
  std::uint64_t frames_seen() const;
  std::uint64_t faults_injected() const;

 private:
  class State;
  std::unique_ptr<State> state_;
};

}  // namespace hil::link
