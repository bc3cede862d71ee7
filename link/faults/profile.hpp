#pragma once
// Fault profiles: the rules a FaultInjector applies to one direction of a
// link. docs/faults.md is the reference for every kind, key and default.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "base/enum_names.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::link {

/// Which way bytes flow on a link between a client and a car.
enum class Direction : std::uint8_t { to_car, to_client };
std::string_view to_string(Direction d);  ///< "to_car" or "to_client"

/// The directions a rule applies to.
enum class DirectionFilter : std::uint8_t { both, to_car, to_client };
std::string_view to_string(DirectionFilter d);
/// "to_car", "to_client", "both": the words of a rule's 'direction'.
extern const base::EnumNames<DirectionFilter, 3> kDirectionFilterNames;
bool applies_to(DirectionFilter filter, Direction d);

/// Inclusive [min, max] range of byte counts.
struct ByteCountRange {
  std::size_t min = 1;
  std::size_t max = 1;
  friend bool operator==(const ByteCountRange&, const ByteCountRange&) = default;
};

/// Inclusive [min, max] range of durations.
struct DurationRange {
  Duration min{0};
  Duration max{0};
  friend bool operator==(const DurationRange&, const DurationRange&) = default;
};

// ---- what a rule does, one struct per kind ----

/// Splits each write holding a selected frame into pieces of `piece_bytes`
/// (the last piece may be shorter), `gap` apart.
struct Fragment {
  ByteCountRange piece_bytes{1, 8};
  DurationRange gap;
  friend bool operator==(const Fragment&, const Fragment&) = default;
};

/// A selected frame opens a batch; every frame after it joins the batch until
/// it holds `count` frames or `window` has passed since it opened, then the
/// batch goes out as one write. At least one of the two is set.
struct Coalesce {
  std::size_t count = 0;  ///< 0: no count limit
  Duration window{0};     ///< 0: no time limit
  friend bool operator==(const Coalesce&, const Coalesce&) = default;
};

enum class CorruptTarget : std::uint8_t {
  checksum,  ///< the protocol's checksum field, kept in its format
  field,     ///< a named field (ProtocolAdapter::field), kept in its format
  random,    ///< `bits` random bits anywhere in the frame
};
std::string_view to_string(CorruptTarget t);
/// "checksum", "field", "random": the words of a corrupt rule's 'target'.
extern const base::EnumNames<CorruptTarget, 3> kCorruptTargetNames;

/// Changes `bits` positions of the target (distinct bytes for checksum and
/// field, distinct bits for random). Text stays text: a hex digit becomes
/// another hex digit, a decimal digit another digit, a letter another letter.
struct Corrupt {
  CorruptTarget target = CorruptTarget::random;
  std::string field;     ///< for CorruptTarget::field
  std::size_t bits = 1;  ///< positions changed, at least 1
  friend bool operator==(const Corrupt&, const Corrupt&) = default;
};

enum class DropUnit : std::uint8_t { frame, bytes };

/// Drops the whole frame, or `count` consecutive bytes at a random place in it.
struct Drop {
  DropUnit unit = DropUnit::frame;
  ByteCountRange count{1, 1};  ///< for DropUnit::bytes
  friend bool operator==(const Drop&, const Drop&) = default;
};

/// Sends the frame `copies` more times, back to back.
struct Duplicate {
  std::size_t copies = 1;
  friend bool operator==(const Duplicate&, const Duplicate&) = default;
};

/// Writes bytes just before the frame: `fixed` when it is not empty, else
/// random bytes, `length` of them.
struct Garbage {
  ByteCountRange length{1, 16};
  protocol::Bytes fixed;
  friend bool operator==(const Garbage&, const Garbage&) = default;
};

/// Delivers the frame `base` plus a uniform [0, jitter] later, never before
/// a frame sent earlier (a stream keeps its order).
struct Delay {
  Duration base{0};
  Duration jitter{0};
  friend bool operator==(const Delay&, const Delay&) = default;
};

/// Delivers nothing for `duration`, from `at` or from a selected frame's
/// arrival; what falls due meanwhile goes out when it ends.
struct Stall {
  Duration duration{0};
  friend bool operator==(const Stall&, const Stall&) = default;
};

/// Paces deliveries: a write of n bytes occupies the line n / rate seconds
/// and arrives when its last byte has.
struct Bandwidth {
  std::uint64_t bytes_per_second = 0;
  friend bool operator==(const Bandwidth&, const Bandwidth&) = default;
};

/// Closes the link gracefully, at `at` or after a selected frame.
struct Disconnect {
  friend bool operator==(const Disconnect&, const Disconnect&) = default;
};

/// Resets the link (TCP RST), at `at` or after a selected frame.
struct Reset {
  friend bool operator==(const Reset&, const Reset&) = default;
};

/// New connections are refused from `at` for `duration`.
struct Refuse {
  Duration duration{0};
  friend bool operator==(const Refuse&, const Refuse&) = default;
};

/// Lets the first `bytes` bytes of its direction pass (counted from when the
/// rule is installed, in the writes the receiver gets): the write that
/// reaches the limit is cut at it, and then the link is closed gracefully.
struct LimitData {
  std::uint64_t bytes = 1;
  friend bool operator==(const LimitData&, const LimitData&) = default;
};

/// When the sender ends its stream, the end reaches the receiver `delay`
/// later (and never before the bytes still due).
struct SlowClose {
  Duration delay{0};
  friend bool operator==(const SlowClose&, const SlowClose&) = default;
};

using FaultAction = std::variant<Fragment, Coalesce, Corrupt, Drop, Duplicate, Garbage, Delay,
                                 Stall, Bandwidth, Disconnect, Reset, Refuse, LimitData, SlowClose>;

/// How many rule kinds there are (FaultKind's values are 0 to this - 1).
inline constexpr std::size_t kFaultKindCount = std::variant_size_v<FaultAction>;

/// The rule kinds, in FaultAction order.
enum class FaultKind : std::uint8_t {
  fragment,
  coalesce,
  corrupt,
  drop,
  duplicate,
  garbage,
  delay,
  stall,
  bandwidth,
  disconnect,
  reset,
  refuse,
  limit_data,
  slow_close,
};
std::string_view to_string(FaultKind k);  ///< "fragment", "coalesce", ...
std::optional<FaultKind> parse_fault_kind(std::string_view text);
/// The same words, in FaultKind order, for listing the kinds.
extern const base::EnumNames<FaultKind, kFaultKindCount> kFaultKindNames;
FaultKind kind_of(const FaultAction& action);

/// Which frames a rule acts on (or, with `at`, when it fires). Every
/// condition that is set must hold; a frame-rule with none set acts on every
/// frame. Conditions are checked in this order, and `probability` is drawn
/// only for frames that passed all others, so adding a rule never shifts the
/// random choices of frames it does not consider.
struct Trigger {
  /// Kind prefix, by whole ':'- or '.'-separated parts ("FB:ST" matches
  /// "FB:ST" but not "FB:STAT"); empty matches every frame.
  std::string match;
  /// The frame's number in this direction (1-based, every frame counts).
  std::optional<std::uint64_t> at_frame;
  /// Only the first N frames that pass the window and `match`.
  std::optional<std::uint64_t> first;
  /// Only every N-th frame that passes the window and `match` (N, 2N, ...).
  std::optional<std::uint64_t> every;
  /// Chance in [0, 1] for each frame that passed the rest.
  std::optional<double> probability;
  /// Time trigger (stall, disconnect, reset, refuse): run time it fires at.
  /// Bandwidth, limit_data and slow_close take no trigger.
  std::optional<Time> at;

  bool has_frame_condition() const {
    return !match.empty() || at_frame || first || every || probability;
  }
  friend bool operator==(const Trigger&, const Trigger&) = default;
};

/// Half-open run-time window [from, to) in which a rule is active.
struct TimeWindow {
  Time from{0};
  std::optional<Time> to;  ///< nullopt: until the end of the run
  bool contains(Time t) const { return t >= from && (!to || t < *to); }
  friend bool operator==(const TimeWindow&, const TimeWindow&) = default;
};

struct FaultRule {
  std::string name;  ///< for events; "#<n>" (1-based position) when empty
  DirectionFilter direction = DirectionFilter::both;
  TimeWindow window;
  Trigger trigger;
  FaultAction action;

  FaultKind kind() const { return kind_of(action); }
  friend bool operator==(const FaultRule&, const FaultRule&) = default;
};

struct FaultProfile {
  std::vector<FaultRule> rules;
  friend bool operator==(const FaultProfile&, const FaultProfile&) = default;
};

/// The rules of `profile` that apply to direction `d`. Unnamed rules are
/// named "#<n>" after their position in `profile`, so events name the same
/// rule whichever direction reports them.
FaultProfile for_direction(const FaultProfile& profile, Direction d);

/// What is wrong with a rule, as a sentence naming the offending key; nullopt
/// when the rule is fine.
std::optional<std::string> rule_problem(const FaultRule& rule);

/// Throws std::invalid_argument when a rule breaks a constraint docs/faults.md
/// states (a range with min > max, a probability outside [0, 1], a stall
/// with no trigger, ...). The YAML loader reports the same problems with
/// file positions; this is for profiles built in code.
void validate(const FaultProfile& profile);

}  // namespace hil::link
