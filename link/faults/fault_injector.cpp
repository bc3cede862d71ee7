#include "link/faults/fault_injector.hpp"

#include <algorithm>
#include <string_view>
#include <utility>

#include "link/faults/delivery_queue.hpp"
#include "link/faults/frame_faults.hpp"
#include "link/faults/random.hpp"
#include "link/faults/rule_book.hpp"

namespace hil::link {
namespace {

using protocol::Bytes;
using protocol::ByteView;

// Each direction draws from its own stream, so faults on one side do not
// shift the choices made on the other.
constexpr std::uint64_t kDirectionSalt[2] = {0x5D4E8A6B1C3F2E71ULL, 0xA1B2C3D4E5F60718ULL};

}  // namespace

/// The injector of one direction: cuts the sender's writes into frames,
/// lets the rules (faults::RuleBook) choose the frames they act on, applies
/// their actions (faults/frame_faults.hpp) and queues the result
/// (faults::DeliveryQueue). Frames of a coalesce batch wait here until it
/// goes out; an incomplete frame waits for the rest of its bytes.
class FaultInjector::State {
 public:
  State(Direction d, std::shared_ptr<const ProtocolAdapter> p, std::uint64_t seed,
        FaultEventSink sink, Time start)
      : direction_(d),
        protocol_(p ? std::move(p) : protocol_adapter("raw")),
        seed_(seed),
        sink_(std::move(sink)),
        rng_(seed ^ kDirectionSalt[static_cast<std::size_t>(d)]),
        splitter_(protocol_->splitter_for(d, false)),
        text_(protocol_->text_frames()),
        last_now_(start) {}

  void install(FaultProfile p);
  void push(Time now, ByteView bytes);
  void finish(Time now);
  void poll(Time now, std::vector<InjectorOutput>& out) {
    advance(now);
    queue_.pop_due(now, out);
    if (close_due_ && *close_due_ <= now) close_due_.reset();
  }
  std::optional<Time> next_due() const;
  bool refuse_connection(Time now);

  const FaultProfile& profile() const { return rules_.profile(); }
  std::uint64_t seed() const { return seed_; }
  std::uint64_t frames_seen() const { return frames_seen_; }
  std::uint64_t faults() const { return faults_; }

 private:
  /// Frames a coalesce rule gathers into one write.
  struct Batch {
    std::optional<Time> deadline;
    std::size_t limit = 0;
    std::size_t frames = 0;
    Bytes bytes;
    Duration delay{0};
    std::optional<std::size_t> fragment_rule;
    std::uint64_t last_frame = 0;
    std::size_t rule = 0;
  };

  void emit(Time at, std::size_t rule, std::uint64_t frame, Bytes before, Bytes after,
            std::string detail);
  bool selected(std::size_t i, const WireFrame& frame, Time now, std::uint64_t n,
                bool applicable = true) {
    return rules_.selected(i, frame, now, n, rng_, applicable);
  }

  // The time rules and the stream's pieces
  void advance(Time now);
  void fire(std::size_t rule);
  void pass_through(Time now, ByteView bytes);
  void take_frames(Time now);
  std::optional<Time> partial_release() const;
  void release_partial(Time at);

  // One frame
  void process(Time now, WireFrame&& frame);
  void stall_on(Time now, const WireFrame& frame, std::uint64_t n);
  bool drop_frame(Time now, const WireFrame& frame, std::uint64_t n, const Bytes& bytes);
  void change_bytes(Time now, const WireFrame& frame, std::uint64_t n, Bytes& bytes);
  template <class Action, class Applies, class Change>
  void change_each(Time now, const WireFrame& frame, std::uint64_t n, Bytes& bytes, Applies applies,
                   Change change);
  Duration delay_of(Time now, const WireFrame& frame, std::uint64_t n, const Bytes& bytes);
  template <class Action>
  std::optional<std::size_t> first_selected(Time now, const WireFrame& frame, std::uint64_t n);
  void send(Time now, std::uint64_t n, Bytes bytes, Duration delay,
            std::optional<std::size_t> coalesce_rule, std::optional<std::size_t> fragment_rule);
  void break_on(Time now, const WireFrame& frame, std::uint64_t n);

  // Writes and breaks
  void write(Time now, std::uint64_t frame, Bytes bytes, Duration delay,
             std::optional<std::size_t> fragment_rule);
  void schedule(Time now, std::uint64_t frame, Time desired, Bytes bytes, bool joinable = false);
  bool limit_data(Time now, std::uint64_t frame, Bytes& bytes);
  void slow_close(Time now);
  void release_batch(Time at, std::string_view why);
  void break_after_queue(Time now, std::size_t rule, std::uint64_t frame);
  void break_at(Time at, std::size_t rule);

  Direction direction_;
  std::shared_ptr<const ProtocolAdapter> protocol_;
  std::uint64_t seed_;
  FaultEventSink sink_;
  FaultRandom rng_;
  std::unique_ptr<FrameSplitter> splitter_;
  bool text_;  // corruption keeps characters in their class
  faults::RuleBook rules_;
  faults::DeliveryQueue queue_;
  bool transparent_ = false;  // no rule applies to this direction
  std::optional<Batch> batch_;
  std::vector<WireFrame> frames_;

  std::uint64_t frames_seen_ = 0;
  std::uint64_t faults_ = 0;
  std::uint64_t pushes_ = 0;           // push() calls so far
  std::uint64_t faults_at_frame_ = 0;  // `faults_` when the current frame began
  Time last_now_{0};
  // The last write that left the splitter holding an incomplete frame.
  std::optional<Time> held_since_;
  bool finished_ = false;
  bool broken_ = false;
  // A slow_close rule holds the end of the stream until then.
  std::optional<Time> close_due_;
};

// ---------------------------------------------------------------- the sender's side

void FaultInjector::State::install(FaultProfile p) {
  validate(p);
  // A coalesce batch being gathered belongs to the old rules (it names
  // them by index): it goes out now, under them.
  if (batch_ && !broken_) release_batch(last_now_, "fault rules replaced");
  batch_.reset();
  // Time-triggered stalls not yet begun belong to the old rules.
  queue_.forget_timed_stalls(last_now_);
  rules_.install(std::move(p), direction_, last_now_);
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* stall = rules_.action<Stall>(i);
    if (!stall || !rules_.armed(i)) continue;
    const Time begin = *rules_.rule(i).trigger.at;
    queue_.add_stall(begin, begin + stall->duration, true);
  }
  const bool was_transparent = transparent_;
  transparent_ = rules_.none_apply();
  if (transparent_ && !was_transparent && held_since_) {
    release_partial(last_now_);  // nothing will complete it under rules now
  } else if (!transparent_ && was_transparent && splitter_->buffered() > 0) {
    // The start of that frame went out as written: frame afresh.
    splitter_ = protocol_->splitter_for(direction_, false);
  }
}

void FaultInjector::State::push(Time now, ByteView bytes) {
  advance(now);
  if (broken_ || finished_) return;
  ++pushes_;
  if (transparent_) {
    pass_through(now, bytes);
    return;
  }
  splitter_->feed(bytes, frames_);
  take_frames(now);
  if (splitter_->buffered() > 0) {
    held_since_ = now;
  } else {
    held_since_.reset();
  }
}

void FaultInjector::State::finish(Time now) {
  advance(now);
  if (broken_ || finished_) return;
  ++pushes_;
  held_since_.reset();
  splitter_->finish(frames_);
  if (transparent_) {
    frames_seen_ += frames_.size();  // its bytes went out as they came
    frames_.clear();
  }
  take_frames(now);
  if (batch_ && !broken_) release_batch(now, "sender closed");
  finished_ = true;
  if (!broken_) slow_close(now);
}

std::optional<Time> FaultInjector::State::next_due() const {
  Earliest next;
  next.consider(queue_.next_due());
  next.consider(partial_release());
  if (batch_) next.consider(batch_->deadline);
  next.consider(close_due_);
  // Once the sender has closed, timed rules no longer keep the link alive.
  if (!broken_ && !finished_) next.consider(rules_.next_armed());
  return next.time();
}

bool FaultInjector::State::refuse_connection(Time now) {
  const auto refusal = rules_.refusing(now);
  if (!refusal) return false;
  emit(now, refusal->first, 0, {}, {}, "connection refused until " + format_ms(refusal->second));
  return true;
}

void FaultInjector::State::emit(Time at, std::size_t rule, std::uint64_t frame, Bytes before,
                                Bytes after, std::string detail) {
  ++faults_;
  if (!sink_) return;
  FaultEvent e;
  e.at = at;
  e.direction = direction_;
  e.kind = rules_.rule(rule).kind();
  e.rule = rules_.name(rule);
  e.frame = frame;
  e.before = std::move(before);
  e.after = std::move(after);
  e.detail = std::move(detail);
  sink_(e);
}

// ---------------------------------------------------------------- time and pieces

/// Fires what is due by `now` on the clock rather than on a frame: stall
/// starts, timed breaks, coalesce windows, incomplete frames held too long.
/// Earliest first; at equal times the batch goes before the rules, and
/// rules in profile order.
void FaultInjector::State::advance(Time now) {
  last_now_ = std::max(last_now_, now);
  while (!broken_) {
    std::optional<Time> when;  // the batch's deadline, when it has passed
    if (batch_ && batch_->deadline && *batch_->deadline <= now) when = batch_->deadline;
    if (const auto hold = partial_release(); hold && *hold <= now && (!when || *hold < *when)) {
      release_partial(*hold);
      continue;
    }
    if (const auto rule = rules_.first_armed(now, when)) {
      fire(*rule);
    } else if (when) {
      release_batch(*when, "window ended");
    } else {
      return;
    }
  }
}

void FaultInjector::State::fire(std::size_t rule) {
  const Time at = *rules_.rule(rule).trigger.at;
  rules_.disarm(rule);
  if (const auto* stall = rules_.action<Stall>(rule)) {
    emit(at, rule, 0, {}, {}, "nothing delivered for " + format_ms(stall->duration));
  } else if (!finished_) {
    break_at(at, rule);
  }
}

/// Without rules for this direction the link passes bytes exactly as
/// written, when written; the splitter only counts the frames.
void FaultInjector::State::pass_through(Time now, ByteView bytes) {
  splitter_->feed(bytes, frames_);
  frames_seen_ += frames_.size();
  frames_.clear();
  schedule(now, 0, now, Bytes(bytes.begin(), bytes.end()), true);
}

void FaultInjector::State::take_frames(Time now) {
  auto pending = std::move(frames_);
  frames_.clear();
  for (auto& f : pending) {
    if (broken_) break;
    process(now, std::move(f));
  }
}

// When the incomplete frame the splitter holds goes out as it is.
std::optional<Time> FaultInjector::State::partial_release() const {
  if (!held_since_ || finished_ || broken_) return std::nullopt;
  return *held_since_ + kPartialFrameHold;
}

void FaultInjector::State::release_partial(Time at) {
  held_since_.reset();
  splitter_->finish(frames_);
  take_frames(at);
}

// ---------------------------------------------------------------- one frame

void FaultInjector::State::process(Time now, WireFrame&& frame) {
  const std::uint64_t n = ++frames_seen_;
  faults_at_frame_ = faults_;
  Bytes bytes = std::move(frame.raw);
  stall_on(now, frame, n);
  if (!drop_frame(now, frame, n, bytes)) {
    change_bytes(now, frame, n, bytes);
    const Duration delay = delay_of(now, frame, n, bytes);
    const auto coalesce_rule = first_selected<Coalesce>(now, frame, n);
    const auto fragment_rule = first_selected<Fragment>(now, frame, n);
    send(now, n, std::move(bytes), delay, coalesce_rule, fragment_rule);
  }
  break_on(now, frame, n);
}

/// A stall chosen by this frame holds the frame itself too.
void FaultInjector::State::stall_on(Time now, const WireFrame& frame, std::uint64_t n) {
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* stall = rules_.action<Stall>(i);
    if (!stall || rules_.rule(i).trigger.at || !selected(i, frame, now, n)) continue;
    queue_.add_stall(now, now + stall->duration, false);
    emit(now, i, n, {}, {}, "nothing delivered for " + format_ms(stall->duration));
  }
}

bool FaultInjector::State::drop_frame(Time now, const WireFrame& frame, std::uint64_t n,
                                      const Bytes& bytes) {
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* drop = rules_.action<Drop>(i);
    if (!drop || drop->unit != DropUnit::frame || !selected(i, frame, now, n)) continue;
    emit(now, i, n, bytes, {}, "frame dropped (" + (frame.kind.empty() ? "?" : frame.kind) + ")");
    return true;
  }
  return false;
}

/// Each rule of kind `Action` that `applies` to the frame as it is now and
/// selects it changes it by `change`, in profile order.
template <class Action, class Applies, class Change>
void FaultInjector::State::change_each(Time now, const WireFrame& frame, std::uint64_t n,
                                       Bytes& bytes, Applies applies, Change change) {
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* action = rules_.action<Action>(i);
    if (!action || !selected(i, frame, now, n, applies(*action, bytes))) continue;
    Bytes before = bytes;
    std::string detail = change(*action, bytes);
    emit(now, i, n, std::move(before), bytes, std::move(detail));
  }
}

/// The byte-changing rules, kind by kind: corrupt, drop bytes, duplicate,
/// garbage.
void FaultInjector::State::change_bytes(Time now, const WireFrame& frame, std::uint64_t n,
                                        Bytes& bytes) {
  std::optional<ByteRange> range;  // the place the corrupt rule at hand acts on
  change_each<Corrupt>(
      now, frame, n, bytes,
      [&](const Corrupt& c, const Bytes& b) {
        range.reset();
        if (c.target == CorruptTarget::checksum) range = protocol_->checksum_field(b);
        if (c.target == CorruptTarget::field) range = protocol_->field(b, c.field);
        if (c.target == CorruptTarget::random && !b.empty()) range = ByteRange{0, b.size()};
        return range.has_value();
      },
      [&](const Corrupt& c, Bytes& b) { return faults::corrupt(c, b, *range, text_, rng_); });
  change_each<Drop>(
      now, frame, n, bytes,
      [](const Drop& d, const Bytes& b) { return d.unit == DropUnit::bytes && !b.empty(); },
      [&](const Drop& d, Bytes& b) { return faults::drop_bytes(d, b, rng_); });
  change_each<Duplicate>(
      now, frame, n, bytes, [](const Duplicate&, const Bytes& b) { return !b.empty(); },
      [](const Duplicate& d, Bytes& b) { return faults::duplicate(d, b); });
  change_each<Garbage>(
      now, frame, n, bytes, [](const Garbage&, const Bytes&) { return true; },
      [&](const Garbage& g, Bytes& b) { return faults::add_garbage(g, b, rng_); });
}

/// The sum of the delays the delay rules that select the frame draw.
Duration FaultInjector::State::delay_of(Time now, const WireFrame& frame, std::uint64_t n,
                                        const Bytes& bytes) {
  Duration delay{0};
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* d = rules_.action<Delay>(i);
    if (!d || !selected(i, frame, now, n)) continue;
    const Duration this_delay = faults::delay_of(*d, rng_);
    delay += this_delay;
    emit(now, i, n, bytes, bytes, "delayed " + format_ms(this_delay));
  }
  return delay;
}

/// The first rule of kind `Action` that selects the frame; every such rule
/// still counts it.
template <class Action>
std::optional<std::size_t> FaultInjector::State::first_selected(Time now, const WireFrame& frame,
                                                                std::uint64_t n) {
  std::optional<std::size_t> chosen;
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    if (rules_.action<Action>(i) && selected(i, frame, now, n) && !chosen) chosen = i;
  }
  return chosen;
}

/// Writes the frame, or adds it to the coalesce batch (which a selecting
/// coalesce rule opens).
void FaultInjector::State::send(Time now, std::uint64_t n, Bytes bytes, Duration delay,
                                std::optional<std::size_t> coalesce_rule,
                                std::optional<std::size_t> fragment_rule) {
  if (!batch_ && coalesce_rule) {
    const auto& c = *rules_.action<Coalesce>(*coalesce_rule);
    batch_ = Batch{};
    batch_->rule = *coalesce_rule;
    batch_->limit = c.count;
    if (c.window > Duration{0}) batch_->deadline = now + c.window;
  }
  if (!batch_) {
    write(now, n, std::move(bytes), delay, fragment_rule);
    return;
  }
  batch_->bytes.insert(batch_->bytes.end(), bytes.begin(), bytes.end());
  ++batch_->frames;
  batch_->last_frame = n;
  batch_->delay = std::max(batch_->delay, delay);
  if (!batch_->fragment_rule) batch_->fragment_rule = fragment_rule;
  if (batch_->limit != 0 && batch_->frames >= batch_->limit) release_batch(now, "count reached");
}

void FaultInjector::State::break_on(Time now, const WireFrame& frame, std::uint64_t n) {
  for (std::size_t i = 0; i < rules_.size() && !broken_; ++i) {
    const bool breaks = rules_.action<Disconnect>(i) || rules_.action<Reset>(i);
    if (!breaks || rules_.rule(i).trigger.at) continue;
    if (selected(i, frame, now, n)) break_after_queue(now, i, n);
  }
}

// ---------------------------------------------------------------- writes and breaks

/// One write the sender's frames make after frame rules: fragmented when a
/// fragment rule chose one of its frames, delayed by `delay`.
void FaultInjector::State::write(Time now, std::uint64_t frame, Bytes bytes, Duration delay,
                                 std::optional<std::size_t> fragment_rule) {
  if (bytes.empty()) return;
  const Time desired = now + delay;
  if (!fragment_rule) {
    // No rule touched this frame if no fault was recorded since it began.
    schedule(now, frame, desired, std::move(bytes), faults_ == faults_at_frame_);
    return;
  }
  const auto pieces =
      faults::fragment(*rules_.action<Fragment>(*fragment_rule), bytes.size(), rng_);
  emit(now, *fragment_rule, frame, bytes, bytes, faults::describe(pieces));
  std::size_t offset = 0;
  Time at = desired;
  for (const auto& piece : pieces) {
    const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(offset);
    schedule(now, frame, at, Bytes(first, first + static_cast<std::ptrdiff_t>(piece.bytes)));
    offset += piece.bytes;
    at = queue_.last_due() + piece.gap;
  }
}

/// Queues one write for `desired` or, to keep stream order, later; paced
/// by the bandwidth rule active then.
void FaultInjector::State::schedule(Time now, std::uint64_t frame, Time desired, Bytes bytes,
                                    bool joinable) {
  if (broken_) return;  // a limit reached by an earlier piece closed the link
  const bool limit_reached = limit_data(now, frame, bytes);
  if (limit_reached) joinable = false;
  Time t = queue_.slot(desired);
  const auto bandwidth = rules_.bandwidth_at(t);
  if (!bandwidth) {
    if (joinable && queue_.join(t, bytes, pushes_)) return;
  } else {
    const auto rate = rules_.action<Bandwidth>(*bandwidth)->bytes_per_second;
    const Time paced = queue_.pace(t, bytes.size(), rate);
    emit(now, *bandwidth, frame, bytes, bytes,
         std::to_string(bytes.size()) + " bytes at " + std::to_string(rate) + " B/s arrive " +
             format_ms(paced - t) + " later");
    t = paced;
  }
  queue_.add(t, std::move(bytes), pushes_, joinable);
  if (limit_reached) {
    queue_.add_break(std::max(now, queue_.last_due()), false);
    broken_ = true;
  }
}

/// Counts a write against the limit_data rules active at `now`; when it
/// reaches the smallest limit left, cuts it there, reports it and says so
/// (the caller queues the cut write, then the close).
bool FaultInjector::State::limit_data(Time now, std::uint64_t frame, Bytes& bytes) {
  std::optional<std::size_t> tightest;
  std::uint64_t room = 0;
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* limit = rules_.action<LimitData>(i);
    if (!limit || !rules_.applies(i) || !rules_.rule(i).window.contains(now)) continue;
    const std::uint64_t left = limit->bytes - std::min(limit->bytes, rules_.bytes_passed(i));
    if (!tightest || left < room) {
      tightest = i;
      room = left;
    }
  }
  if (!tightest) return false;
  const std::uint64_t take = std::min<std::uint64_t>(room, bytes.size());
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    if (rules_.action<LimitData>(i) && rules_.applies(i) && rules_.rule(i).window.contains(now))
      rules_.bytes_passed(i) += take;
  }
  if (take < room) return false;
  Bytes before = bytes;
  bytes.resize(static_cast<std::size_t>(take));
  std::string detail = "limit of " + std::to_string(rules_.action<LimitData>(*tightest)->bytes) +
                       " bytes reached: " + std::to_string(take) + " of " +
                       std::to_string(before.size()) + " bytes passed, link closed";
  emit(now, *tightest, frame, std::move(before), bytes, std::move(detail));
  return true;
}

/// The first slow_close rule active at `now` holds the end of the stream.
void FaultInjector::State::slow_close(Time now) {
  for (std::size_t i = 0; i < rules_.size(); ++i) {
    const auto* slow = rules_.action<SlowClose>(i);
    if (!slow || !rules_.applies(i) || !rules_.rule(i).window.contains(now)) continue;
    close_due_ = now + slow->delay;
    emit(now, i, 0, {}, {},
         "sender closed; the close is passed on " + format_ms(slow->delay) + " later");
    return;
  }
}

void FaultInjector::State::release_batch(Time at, std::string_view why) {
  Batch b = std::move(*batch_);
  batch_.reset();
  emit(at, b.rule, b.last_frame, b.bytes, b.bytes,
       std::to_string(b.frames) + " frames in one write (" + std::string(why) + ")");
  write(at, b.last_frame, std::move(b.bytes), b.delay, b.fragment_rule);
}

void FaultInjector::State::break_after_queue(Time now, std::size_t rule, std::uint64_t frame) {
  const bool reset = rules_.action<Reset>(rule) != nullptr;
  if (batch_) release_batch(now, "link break");
  if (broken_) return;  // the batch reached a limit_data rule's limit
  emit(now, rule, frame, {}, {},
       std::string(reset ? "reset" : "disconnect") + " after frame " + std::to_string(frame));
  queue_.add_break(std::max(now, queue_.last_due()), reset);
  broken_ = true;
}

void FaultInjector::State::break_at(Time at, std::size_t rule) {
  const bool reset = rules_.action<Reset>(rule) != nullptr;
  // What has not arrived by `at` is lost with the connection.
  Bytes lost = queue_.cut_after(at);
  if (batch_) {
    lost.insert(lost.end(), batch_->bytes.begin(), batch_->bytes.end());
    batch_.reset();
  }
  std::string detail = std::string(reset ? "reset" : "disconnect") + " at " + format_ms(at);
  if (!lost.empty()) detail += ", " + std::to_string(lost.size()) + " bytes in flight lost";
  emit(at, rule, 0, std::move(lost), {}, std::move(detail));
  queue_.add_break(at, reset);
  broken_ = true;
}

// ---------------------------------------------------------------- FaultInjector

FaultInjector::FaultInjector(Direction direction, std::shared_ptr<const ProtocolAdapter> protocol,
                             FaultProfile profile, std::uint64_t seed, FaultEventSink sink,
                             Time start)
    : state_(
          std::make_unique<State>(direction, std::move(protocol), seed, std::move(sink), start)) {
  state_->install(std::move(profile));
}

FaultInjector::~FaultInjector() = default;
FaultInjector::FaultInjector(FaultInjector&&) noexcept = default;
FaultInjector& FaultInjector::operator=(FaultInjector&&) noexcept = default;

void FaultInjector::push(Time now, protocol::ByteView bytes) {
  state_->push(now, bytes);
}

void FaultInjector::finish(Time now) {
  state_->finish(now);
}

void FaultInjector::poll(Time now, std::vector<InjectorOutput>& out) {
  state_->poll(now, out);
}

std::optional<Time> FaultInjector::next_due() const {
  return state_->next_due();
}

void FaultInjector::set_profile(FaultProfile profile) {
  state_->install(std::move(profile));
}

const FaultProfile& FaultInjector::profile() const {
  return state_->profile();
}

bool FaultInjector::refuse_connection(Time now) const {
  return state_->refuse_connection(now);
}

std::uint64_t FaultInjector::seed() const {
  return state_->seed();
}
std::uint64_t FaultInjector::frames_seen() const {
  return state_->frames_seen();
}
std::uint64_t FaultInjector::faults_injected() const {
  return state_->faults();
}

}  // namespace hil::link
