#include "link/faults/fault_injector.hpp"

#include <algorithm>
#include <deque>
#include <string_view>
#include <type_traits>
#include <utility>

#include "link/faults/random.hpp"

namespace hil::link {
namespace {

using protocol::Bytes;
using protocol::ByteView;

// Each direction draws from its own stream, so faults on one side do not
// shift the choices made on the other.
constexpr std::uint64_t kDirectionSalt[2] = {0x5D4E8A6B1C3F2E71ULL, 0xA1B2C3D4E5F60718ULL};

/// Prefix match by whole ':'- or '.'-separated parts.
bool kind_matches(std::string_view kind, std::string_view prefix) {
  if (prefix.empty()) return true;
  if (kind.size() < prefix.size() || kind.substr(0, prefix.size()) != prefix) return false;
  return kind.size() == prefix.size() || kind[prefix.size()] == ':' || kind[prefix.size()] == '.';
}

void append(Bytes& to, ByteView from) {
  to.insert(to.end(), from.begin(), from.end());
}

bool is_digit(std::uint8_t c) {
  return c >= '0' && c <= '9';
}
bool is_upper(std::uint8_t c) {
  return c >= 'A' && c <= 'Z';
}
bool is_lower(std::uint8_t c) {
  return c >= 'a' && c <= 'z';
}
bool is_hex(std::uint8_t c) {
  return is_digit(c) || (c >= 'A' && c <= 'F') || (c >= 'a' && c <= 'f');
}

Duration between(FaultRandom& rng, Duration lo, Duration hi) {
  const auto span = static_cast<std::uint64_t>((hi - lo).count());
  return lo + Duration{static_cast<Duration::rep>(rng.between(0, span))};
}

std::size_t between(FaultRandom& rng, std::size_t lo, std::size_t hi) {
  return static_cast<std::size_t>(rng.between(lo, hi));
}

}  // namespace

struct FaultInjector::State {
  State(Direction d, std::shared_ptr<const ProtocolAdapter> p, std::uint64_t s, FaultEventSink k)
      : direction(d),
        protocol(p ? std::move(p) : protocol_adapter("raw")),
        seed(s),
        sink(std::move(k)),
        rng(s ^ kDirectionSalt[static_cast<std::size_t>(d)]),
        splitter(protocol->splitter_for(d, false)),
        text_protocol(protocol->name() == "logi" || protocol->name() == "arduino") {}

  struct RuleState {
    bool applies = false;       // the rule is for this injector's direction
    bool armed = false;         // a time trigger still to fire
    std::uint64_t matched = 0;  // frames that passed window and match
  };
  struct Pending {
    Time due{0};
    std::optional<Bytes> bytes;  // nullopt: a LinkBreak
    bool reset = false;
    // Untouched frames of one push() due at the same time go out as one
    // write, as the sender wrote them (and at stream speed, not per frame).
    std::uint64_t push = 0;
    bool mergeable = false;
  };
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
  struct Interval {
    Time begin{0};
    Time end{0};
    bool timed = false;  // from a rule's `at` (replaced by set_profile)
  };

  Direction direction;
  std::shared_ptr<const ProtocolAdapter> protocol;
  FaultProfile profile;
  std::uint64_t seed;
  FaultEventSink sink;
  FaultRandom rng;
  std::unique_ptr<FrameSplitter> splitter;
  bool text_protocol;
  bool transparent = false;  // no rule applies to this direction

  std::vector<RuleState> rule_state;
  std::deque<Pending> queue;  // due times never decrease: it is a stream
  Time last_due{0};
  Time line_free{0};  // when the bandwidth-limited line is next idle
  std::optional<Batch> batch;
  std::vector<Interval> stalls;
  std::vector<WireFrame> frames;

  std::uint64_t frames_seen = 0;
  std::uint64_t faults = 0;
  std::uint64_t pushes = 0;           // push() calls so far
  std::uint64_t faults_at_frame = 0;  // `faults` when the current frame began
  Time last_now{0};
  // The last write that left the splitter holding an incomplete frame.
  std::optional<Time> held_since;
  bool finished = false;
  bool broken = false;

  // ------------------------------------------------------------ rules

  void install(FaultProfile p) {
    validate(p);
    // A coalesce batch being gathered belongs to the old rules (it names
    // them by index): it goes out now, under them.
    if (batch && !broken) release_batch(last_now, "fault rules replaced");
    batch.reset();
    profile = std::move(p);
    rule_state.assign(profile.rules.size(), RuleState{});
    // Time-triggered stalls not yet begun belong to the old rules.
    std::erase_if(stalls, [&](const Interval& s) { return s.timed && s.begin >= last_now; });
    for (std::size_t i = 0; i < profile.rules.size(); ++i) {
      const auto& rule = profile.rules[i];
      auto& st = rule_state[i];
      st.applies = applies_to(rule.direction, direction);
      if (!st.applies || !rule.trigger.at || *rule.trigger.at < last_now) continue;
      const FaultKind k = rule.kind();
      if (k == FaultKind::stall) {
        const Time begin = *rule.trigger.at;
        add_stall(begin, begin + std::get<Stall>(rule.action).duration, true);
        st.armed = true;
      } else if (k == FaultKind::disconnect || k == FaultKind::reset) {
        st.armed = true;
      }
    }
    const bool was_transparent = transparent;
    transparent = std::none_of(rule_state.begin(), rule_state.end(),
                               [](const RuleState& r) { return r.applies; });
    if (transparent && !was_transparent && held_since) {
      release_partial(last_now);  // nothing will complete it under rules now
    } else if (!transparent && was_transparent && splitter->buffered() > 0) {
      // The start of that frame went out as written: frame afresh.
      splitter = protocol->splitter_for(direction, false);
    }
  }

  /// Without rules for this direction the link passes bytes exactly as
  /// written, when written; the splitter only counts the frames.
  void pass_through(Time now, protocol::ByteView bytes) {
    splitter->feed(bytes, frames);
    frames_seen += frames.size();
    frames.clear();
    schedule(now, 0, now, Bytes(bytes.begin(), bytes.end()), true);
  }

  std::string rule_name(std::size_t i) const {
    const auto& name = profile.rules[i].name;
    return name.empty() ? "#" + std::to_string(i + 1) : name;
  }

  void emit(Time at, std::size_t rule, std::uint64_t frame, Bytes before, Bytes after,
            std::string detail) {
    ++faults;
    if (!sink) return;
    FaultEvent e;
    e.at = at;
    e.direction = direction;
    e.kind = std::string(to_string(profile.rules[rule].kind()));
    e.rule = rule_name(rule);
    e.frame = frame;
    e.before = std::move(before);
    e.after = std::move(after);
    e.detail = std::move(detail);
    sink(e);
  }

  /// Whether rule `i` acts on frame number `n` arriving at `now`. Counts the
  /// frame towards `first`/`every` and draws `probability` only once the
  /// cheaper conditions hold, so the random stream depends on nothing else.
  bool selected(std::size_t i, const WireFrame& frame, Time now, std::uint64_t n,
                bool applicable = true) {
    const auto& rule = profile.rules[i];
    auto& st = rule_state[i];
    if (!st.applies || !applicable || !rule.window.contains(now)) return false;
    const auto& t = rule.trigger;
    if (!kind_matches(frame.kind, t.match)) return false;
    const std::uint64_t m = ++st.matched;
    if (t.at_frame && *t.at_frame != n) return false;
    if (t.first && m > *t.first) return false;
    if (t.every && m % *t.every != 0) return false;
    if (t.probability && !rng.chance(*t.probability)) return false;
    return true;
  }

  template <class Action>
  bool is(std::size_t i) const {
    return std::holds_alternative<Action>(profile.rules[i].action);
  }

  // ------------------------------------------------------------ timing

  Time after_stalls(Time t) const {
    // Stalls may chain or overlap, so repeat until t is in none of them.
    for (bool moved = true; moved;) {
      moved = false;
      for (const auto& s : stalls) {
        if (t >= s.begin && t < s.end) {
          t = s.end;
          moved = true;
        }
      }
    }
    return t;
  }

  void add_stall(Time begin, Time end, bool timed) {
    stalls.push_back(Interval{begin, end, timed});
    // after_stalls never reorders (it maps a time to one no earlier, and a
    // later time to one no earlier than that), so the queue stays sorted.
    for (auto& p : queue)
      p.due = after_stalls(p.due);
    last_due = after_stalls(last_due);
  }

  std::size_t bandwidth_rule_at(Time t) const {
    for (std::size_t i = 0; i < profile.rules.size(); ++i) {
      if (rule_state[i].applies && is<Bandwidth>(i) && profile.rules[i].window.contains(t))
        return i;
    }
    return profile.rules.size();
  }

  /// Queues one write for `desired` or, to keep stream order, later.
  void schedule(Time now, std::uint64_t frame, Time desired, Bytes bytes, bool mergeable = false) {
    Time t = after_stalls(std::max(desired, last_due));
    const std::size_t bw = bandwidth_rule_at(t);
    if (mergeable && bw >= profile.rules.size() && !queue.empty()) {
      Pending& last = queue.back();
      if (last.mergeable && last.bytes && last.push == pushes && last.due == t) {
        append(*last.bytes, bytes);
        return;
      }
    }
    if (bw < profile.rules.size()) {
      const auto rate = std::get<Bandwidth>(profile.rules[bw].action).bytes_per_second;
      const auto n = static_cast<std::uint64_t>(bytes.size());
      const auto on_line_ns = (n * 1'000'000'000ULL + rate - 1) / rate;
      const Time start = std::max(t, line_free);
      const Time arrive = start + Duration{static_cast<Duration::rep>(on_line_ns)};
      line_free = arrive;
      const Time paced = after_stalls(arrive);
      emit(now, bw, frame, bytes, bytes,
           std::to_string(n) + " bytes at " + std::to_string(rate) + " B/s arrive " +
               format_ms(paced - t) + " later");
      t = paced;
    }
    last_due = t;
    queue.push_back(Pending{t, std::move(bytes), false, pushes, mergeable});
  }

  /// One write the sender's frames make after frame rules: fragmented when a
  /// fragment rule chose one of its frames, delayed by `delay`.
  void write(Time now, std::uint64_t frame, Bytes bytes, Duration delay,
             std::optional<std::size_t> fragment_rule) {
    if (bytes.empty()) return;
    const Time desired = now + delay;
    if (!fragment_rule) {
      // No rule touched this frame if no fault was recorded since it began.
      schedule(now, frame, desired, std::move(bytes), faults == faults_at_frame);
      return;
    }
    const auto& f = std::get<Fragment>(profile.rules[*fragment_rule].action);
    std::vector<std::size_t> sizes;
    std::vector<Duration> gaps;
    for (std::size_t left = bytes.size(); left > 0;) {
      const std::size_t size = std::min(left, between(rng, f.piece_bytes.min, f.piece_bytes.max));
      sizes.push_back(size);
      left -= size;
      gaps.push_back(left > 0 ? between(rng, f.gap.min, f.gap.max) : Duration{0});
    }
    std::string detail = std::to_string(sizes.size()) + " pieces:";
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      detail += (k == 0 ? " " : " + ") + std::to_string(sizes[k]);
    }
    detail += " bytes";
    emit(now, *fragment_rule, frame, bytes, bytes, std::move(detail));
    std::size_t offset = 0;
    Time at = desired;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(offset);
      schedule(now, frame, at, Bytes(first, first + static_cast<std::ptrdiff_t>(sizes[k])));
      offset += sizes[k];
      at = last_due + gaps[k];
    }
  }

  void release_batch(Time at, std::string_view why) {
    Batch b = std::move(*batch);
    batch.reset();
    emit(at, b.rule, b.last_frame, b.bytes, b.bytes,
         std::to_string(b.frames) + " frames in one write (" + std::string(why) + ")");
    write(at, b.last_frame, std::move(b.bytes), b.delay, b.fragment_rule);
  }

  // ------------------------------------------------------------ breaks

  void break_after_queue(Time now, std::size_t rule, std::uint64_t frame) {
    const bool reset = is<Reset>(rule);
    if (batch) release_batch(now, "link break");
    emit(now, rule, frame, {}, {},
         std::string(reset ? "reset" : "disconnect") + " after frame " + std::to_string(frame));
    queue.push_back(Pending{std::max(now, last_due), std::nullopt, reset});
    broken = true;
  }

  void break_at(Time at, std::size_t rule) {
    const bool reset = is<Reset>(rule);
    // What has not arrived by `at` is lost with the connection.
    Bytes lost;
    auto cut =
        std::find_if(queue.begin(), queue.end(), [&](const Pending& p) { return p.due > at; });
    for (auto it = cut; it != queue.end(); ++it) {
      if (it->bytes) append(lost, *it->bytes);
    }
    queue.erase(cut, queue.end());
    if (batch) {
      append(lost, batch->bytes);
      batch.reset();
    }
    std::string detail = std::string(reset ? "reset" : "disconnect") + " at " + format_ms(at);
    if (!lost.empty()) detail += ", " + std::to_string(lost.size()) + " bytes in flight lost";
    emit(at, rule, 0, std::move(lost), {}, std::move(detail));
    queue.push_back(Pending{at, std::nullopt, reset});
    broken = true;
  }

  /// Fires what is due by `now` on the clock rather than on a frame: stall
  /// starts, timed breaks, coalesce windows. Earliest first; at equal times
  /// the batch goes before the rules, and rules in profile order.
  void advance(Time now) {
    last_now = std::max(last_now, now);
    while (!broken) {
      std::optional<Time> when;
      std::size_t which = profile.rules.size();  // == size: the batch deadline
      if (batch && batch->deadline && *batch->deadline <= now) when = batch->deadline;
      if (const auto hold = partial_release(); hold && *hold <= now && (!when || *hold < *when)) {
        release_partial(*hold);
        continue;
      }
      for (std::size_t i = 0; i < profile.rules.size(); ++i) {
        if (!rule_state[i].armed) continue;
        const Time at = *profile.rules[i].trigger.at;
        if (at > now || (when && at >= *when)) continue;
        when = at;
        which = i;
      }
      if (!when) return;
      if (which == profile.rules.size()) {
        release_batch(*when, "window ended");
        continue;
      }
      rule_state[which].armed = false;
      if (is<Stall>(which)) {
        emit(*when, which, 0, {}, {},
             "nothing delivered for " +
                 format_ms(std::get<Stall>(profile.rules[which].action).duration));
      } else if (!finished) {
        break_at(*when, which);
      }
    }
  }

  // ------------------------------------------------------------ frames

  void corrupt(const Corrupt& c, Bytes& bytes, ByteRange range, std::string& detail) {
    if (c.target == CorruptTarget::random) {
      const std::size_t total_bits = bytes.size() * 8;
      const std::size_t count = std::min(c.bits, total_bits);
      std::vector<std::size_t> chosen;
      while (chosen.size() < count) {
        const auto bit = static_cast<std::size_t>(rng.below(total_bits));
        if (std::find(chosen.begin(), chosen.end(), bit) != chosen.end()) continue;
        chosen.push_back(bit);
        bytes[bit / 8] = static_cast<std::uint8_t>(bytes[bit / 8] ^ (1U << (bit % 8)));
      }
      detail = std::to_string(count) + " random bit" + (count == 1 ? "" : "s") + " flipped";
      return;
    }
    // Checksum or field: change whole bytes, keeping text in its character
    // class so the frame still parses and only the value is wrong.
    const std::size_t width = range.second - range.first;
    const std::size_t count = std::min(c.bits, width);
    bool lower_hex = false;
    for (std::size_t k = range.first; k < range.second; ++k) {
      lower_hex = lower_hex || (bytes[k] >= 'a' && bytes[k] <= 'f');
    }
    std::vector<std::size_t> chosen;
    while (chosen.size() < count) {
      const std::size_t at = range.first + static_cast<std::size_t>(rng.below(width));
      if (std::find(chosen.begin(), chosen.end(), at) != chosen.end()) continue;
      chosen.push_back(at);
      bytes[at] = substitute(bytes[at], c.target == CorruptTarget::checksum, lower_hex);
    }
    detail = (c.target == CorruptTarget::checksum ? std::string("checksum") : "field " + c.field) +
             ": " + std::to_string(count) + " byte" + (count == 1 ? "" : "s") + " changed";
  }

  std::uint8_t substitute(std::uint8_t c, bool checksum, bool lower_hex) {
    const auto other = [&](std::string_view set) {
      const auto pos = set.find(static_cast<char>(c));
      auto k = static_cast<std::size_t>(rng.below(set.size() - 1));
      if (pos != std::string_view::npos && k >= pos) ++k;  // skip c itself
      return static_cast<std::uint8_t>(set[k]);
    };
    if (text_protocol) {
      if (checksum && is_hex(c)) return other(lower_hex ? "0123456789abcdef" : "0123456789ABCDEF");
      if (is_digit(c)) return other("0123456789");
      if (is_upper(c)) return other("ABCDEFGHIJKLMNOPQRSTUVWXYZ");
      if (is_lower(c)) return other("abcdefghijklmnopqrstuvwxyz");
    }
    return static_cast<std::uint8_t>(c ^ (1U << rng.below(8)));
  }

  void process(Time now, WireFrame&& frame) {
    const std::uint64_t n = ++frames_seen;
    faults_at_frame = faults;
    const std::size_t count = profile.rules.size();
    Bytes bytes = std::move(frame.raw);

    // A stall chosen by this frame holds the frame itself too.
    for (std::size_t i = 0; i < count; ++i) {
      if (!is<Stall>(i) || profile.rules[i].trigger.at || !selected(i, frame, now, n)) continue;
      const Duration d = std::get<Stall>(profile.rules[i].action).duration;
      add_stall(now, now + d, false);
      emit(now, i, n, {}, {}, "nothing delivered for " + format_ms(d));
    }

    bool dropped = false;
    for (std::size_t i = 0; i < count && !dropped; ++i) {
      if (!is<Drop>(i) || std::get<Drop>(profile.rules[i].action).unit != DropUnit::frame) continue;
      if (!selected(i, frame, now, n)) continue;
      dropped = true;
      emit(now, i, n, bytes, {}, "frame dropped (" + (frame.kind.empty() ? "?" : frame.kind) + ")");
    }

    if (!dropped) frame_rules(now, n, frame, std::move(bytes));

    for (std::size_t i = 0; i < count && !broken; ++i) {
      if (!(is<Disconnect>(i) || is<Reset>(i)) || profile.rules[i].trigger.at) continue;
      if (selected(i, frame, now, n)) break_after_queue(now, i, n);
    }
  }

  void frame_rules(Time now, std::uint64_t n, const WireFrame& frame, Bytes bytes) {
    const std::size_t count = profile.rules.size();
    for (std::size_t i = 0; i < count; ++i) {
      if (!is<Corrupt>(i)) continue;
      const auto& c = std::get<Corrupt>(profile.rules[i].action);
      std::optional<ByteRange> range;
      if (c.target == CorruptTarget::checksum) range = protocol->checksum_field(bytes);
      if (c.target == CorruptTarget::field) range = protocol->field(bytes, c.field);
      if (c.target == CorruptTarget::random && !bytes.empty()) range = ByteRange{0, bytes.size()};
      if (!selected(i, frame, now, n, range.has_value())) continue;
      Bytes before = bytes;
      std::string detail;
      corrupt(c, bytes, *range, detail);
      emit(now, i, n, std::move(before), bytes, std::move(detail));
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (!is<Drop>(i)) continue;
      const auto& d = std::get<Drop>(profile.rules[i].action);
      if (d.unit != DropUnit::bytes || !selected(i, frame, now, n, !bytes.empty())) continue;
      const std::size_t k = std::min(bytes.size(), between(rng, d.count.min, d.count.max));
      const std::size_t at = between(rng, 0, bytes.size() - k);
      Bytes before = bytes;
      const auto first = bytes.begin() + static_cast<std::ptrdiff_t>(at);
      bytes.erase(first, first + static_cast<std::ptrdiff_t>(k));
      emit(now, i, n, std::move(before), bytes,
           std::to_string(k) + " bytes dropped at offset " + std::to_string(at));
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (!is<Duplicate>(i) || !selected(i, frame, now, n, !bytes.empty())) continue;
      const std::size_t copies = std::get<Duplicate>(profile.rules[i].action).copies;
      Bytes before = bytes;
      for (std::size_t c = 0; c < copies; ++c)
        append(bytes, before);
      emit(now, i, n, std::move(before), bytes,
           std::to_string(copies) + (copies == 1 ? " copy" : " copies") + " added");
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (!is<Garbage>(i) || !selected(i, frame, now, n)) continue;
      const auto& g = std::get<Garbage>(profile.rules[i].action);
      Bytes noise = g.fixed;
      if (noise.empty()) {
        noise.resize(between(rng, g.length.min, g.length.max));
        for (auto& b : noise)
          b = static_cast<std::uint8_t>(rng.below(256));
      }
      Bytes before = bytes;
      bytes.insert(bytes.begin(), noise.begin(), noise.end());
      emit(now, i, n, std::move(before), bytes,
           std::to_string(noise.size()) + " garbage bytes before the frame");
    }
    Duration delay{0};
    for (std::size_t i = 0; i < count; ++i) {
      if (!is<Delay>(i) || !selected(i, frame, now, n)) continue;
      const auto& d = std::get<Delay>(profile.rules[i].action);
      const Duration this_delay = d.base + between(rng, Duration{0}, d.jitter);
      delay += this_delay;
      emit(now, i, n, bytes, bytes, "delayed " + format_ms(this_delay));
    }
    std::optional<std::size_t> coalesce_rule;
    for (std::size_t i = 0; i < count; ++i) {
      if (is<Coalesce>(i) && selected(i, frame, now, n) && !coalesce_rule) coalesce_rule = i;
    }
    std::optional<std::size_t> fragment_rule;
    for (std::size_t i = 0; i < count; ++i) {
      if (is<Fragment>(i) && selected(i, frame, now, n) && !fragment_rule) fragment_rule = i;
    }

    if (!batch && coalesce_rule) {
      const auto& c = std::get<Coalesce>(profile.rules[*coalesce_rule].action);
      batch = Batch{};
      batch->rule = *coalesce_rule;
      batch->limit = c.count;
      if (c.window > Duration{0}) batch->deadline = now + c.window;
    }
    if (!batch) {
      write(now, n, std::move(bytes), delay, fragment_rule);
      return;
    }
    append(batch->bytes, bytes);
    ++batch->frames;
    batch->last_frame = n;
    batch->delay = std::max(batch->delay, delay);
    if (!batch->fragment_rule) batch->fragment_rule = fragment_rule;
    if (batch->limit != 0 && batch->frames >= batch->limit) release_batch(now, "count reached");
  }

  // When the incomplete frame the splitter holds goes out as it is.
  std::optional<Time> partial_release() const {
    if (!held_since || finished || broken) return std::nullopt;
    return *held_since + kPartialFrameHold;
  }

  void release_partial(Time at) {
    held_since.reset();
    splitter->finish(frames);
    take_frames(at);
  }

  void note_held(Time now) {
    if (splitter->buffered() > 0) {
      held_since = now;
    } else {
      held_since.reset();
    }
  }

  void take_frames(Time now) {
    auto pending = std::move(frames);
    frames.clear();
    for (auto& f : pending) {
      if (broken) break;
      process(now, std::move(f));
    }
  }
};

// ---------------------------------------------------------------- FaultInjector

FaultInjector::FaultInjector(Direction direction, std::shared_ptr<const ProtocolAdapter> protocol,
                             FaultProfile profile, std::uint64_t seed, FaultEventSink sink,
                             Time start)
    : state_(std::make_unique<State>(direction, std::move(protocol), seed, std::move(sink))) {
  state_->last_now = start;
  state_->install(std::move(profile));
}

FaultInjector::~FaultInjector() = default;
FaultInjector::FaultInjector(FaultInjector&&) noexcept = default;
FaultInjector& FaultInjector::operator=(FaultInjector&&) noexcept = default;

void FaultInjector::push(Time now, protocol::ByteView bytes) {
  auto& s = *state_;
  s.advance(now);
  if (s.broken || s.finished) return;
  ++s.pushes;
  if (s.transparent) {
    s.pass_through(now, bytes);
    return;
  }
  s.splitter->feed(bytes, s.frames);
  s.take_frames(now);
  s.note_held(now);
}

void FaultInjector::finish(Time now) {
  auto& s = *state_;
  s.advance(now);
  if (s.broken || s.finished) return;
  ++s.pushes;
  s.held_since.reset();
  s.splitter->finish(s.frames);
  if (s.transparent) {
    s.frames_seen += s.frames.size();  // its bytes went out as they came
    s.frames.clear();
  }
  s.take_frames(now);
  if (s.batch && !s.broken) s.release_batch(now, "sender closed");
  s.finished = true;
}

void FaultInjector::poll(Time now, std::vector<InjectorOutput>& out) {
  auto& s = *state_;
  s.advance(now);
  while (!s.queue.empty() && s.queue.front().due <= now) {
    auto& p = s.queue.front();
    if (p.bytes) {
      out.emplace_back(Delivery{std::move(*p.bytes)});
    } else {
      out.emplace_back(LinkBreak{p.reset});
    }
    s.queue.pop_front();
  }
}

std::optional<Time> FaultInjector::next_due() const {
  const auto& s = *state_;
  std::optional<Time> next;
  const auto consider = [&](Time t) {
    if (!next || t < *next) next = t;
  };
  if (!s.queue.empty()) consider(s.queue.front().due);
  if (const auto hold = s.partial_release()) consider(*hold);
  if (s.batch && s.batch->deadline) consider(*s.batch->deadline);
  // Once the sender has closed, timed rules no longer keep the link alive.
  if (!s.broken && !s.finished) {
    for (std::size_t i = 0; i < s.profile.rules.size(); ++i) {
      if (s.rule_state[i].armed) consider(*s.profile.rules[i].trigger.at);
    }
  }
  return next;
}

void FaultInjector::set_profile(FaultProfile profile) {
  state_->install(std::move(profile));
}

const FaultProfile& FaultInjector::profile() const {
  return state_->profile;
}

bool FaultInjector::refuse_connection(Time now) const {
  auto& s = *state_;
  for (std::size_t i = 0; i < s.profile.rules.size(); ++i) {
    if (!s.rule_state[i].applies || !s.is<Refuse>(i)) continue;
    const auto& rule = s.profile.rules[i];
    const Time begin = rule.trigger.at.value_or(Time{0});
    const Time end = begin + std::get<Refuse>(rule.action).duration;
    if (now < begin || now >= end || !rule.window.contains(now)) continue;
    s.emit(now, i, 0, {}, {}, "connection refused until " + format_ms(end));
    return true;
  }
  return false;
}

std::uint64_t FaultInjector::seed() const {
  return state_->seed;
}
std::uint64_t FaultInjector::frames_seen() const {
  return state_->frames_seen;
}
std::uint64_t FaultInjector::faults_injected() const {
  return state_->faults;
}

}  // namespace hil::link
