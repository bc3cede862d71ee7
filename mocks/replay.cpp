#include "mocks/replay.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "base/enum_names.hpp"
#include "mocks/car.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::mocks {

namespace {

constexpr auto kUnmatchedNames =
    base::enum_names<Unmatched>({Unmatched::mock, "mock"}, {Unmatched::silent, "silent"});

std::string key_of(ByteView bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

using link::CapturedExchange;
using link::CaptureEvent;
using link::ExchangeKind;

// The kinds of the car's frames in the telemetry exchanges.
std::set<std::string> telemetry_kinds_of(const link::Capture& capture,
                                         const link::ProtocolAdapter& adapter) {
  std::set<std::string> kinds;
  for (const auto& exchange : capture.exchanges) {
    if (exchange.kind != ExchangeKind::telemetry) continue;
    auto splitter = adapter.splitter_for(link::Direction::to_client, false);
    std::vector<link::WireFrame> frames;
    for (const auto& e : exchange.events) {
      if (e.kind == CaptureEvent::Kind::opened)
        splitter = adapter.splitter_for(link::Direction::to_client, false);
      if (e.kind == CaptureEvent::Kind::received) splitter->feed(e.bytes, frames);
    }
    for (const auto& f : frames)
      if (f.valid && !f.kind.empty()) kinds.insert(f.kind);
  }
  return kinds;
}

// A splitter that also tells when each frame's first byte arrived: a
// serial car's reply takes its line time to arrive, which the replay's own
// line adds again, so recorded times count from a frame's first byte.
class TimedSplitter {
 public:
  struct Frame {
    link::WireFrame frame;
    Time first_byte{0};
  };

  explicit TimedSplitter(std::unique_ptr<link::FrameSplitter> splitter)
      : splitter_(std::move(splitter)) {}

  std::vector<Frame> feed(Time at, ByteView bytes) {
    const bool held = splitter_->buffered() > 0;
    std::vector<link::WireFrame> frames;
    splitter_->feed(bytes, frames);
    std::vector<Frame> out;
    for (std::size_t i = 0; i < frames.size(); ++i)
      out.push_back({std::move(frames[i]), i == 0 && held ? started_ : at});
    if (splitter_->buffered() > 0 && !(held && frames.empty())) started_ = at;
    return out;
  }

 private:
  std::unique_ptr<link::FrameSplitter> splitter_;
  Time started_{0};  // when the bytes held began to arrive
};

// One request of an exchange while it is being indexed.
struct OpenRequest {
  std::size_t answer = 0;  // in ReplayIndex::answers
  Time written{0};         // when its last byte was written
  std::size_t write = 0;   // which write completed it (frames written together share it)
  bool valid = false;
  std::optional<std::string> seq;  // its sequence field, where the protocol has one
  bool answered = false;
};

// Cuts the exchanges into requests and their answers. A reply belongs to
// one of the requests of the latest write before it in the same exchange:
// the one with the same sequence number where the protocol has them
// (Arduino), else the first valid one still unanswered, else the first
// unanswered one, else the last.
class AnswerIndexer {
 public:
  AnswerIndexer(const link::ProtocolAdapter& adapter, const std::set<std::string>& telemetry,
                std::vector<RecordedAnswer>& answers)
      : adapter_(adapter), telemetry_(telemetry), answers_(answers) {
    reset();
  }

  void exchange(const CapturedExchange& exchange) {
    requests_.clear();
    std::size_t write = 0;
    for (const auto& e : exchange.events) {
      switch (e.kind) {
        case CaptureEvent::Kind::closed:
          // The car ended the connection after a request: part of its answer.
          if (e.by == link::LinkClose::By::car && !requests_.empty()) {
            OpenRequest& to = requests_.back();
            answers_[to.answer].close_after = std::max(Duration{0}, e.at - to.written);
          }
          reset();
          requests_.clear();
          break;
        case CaptureEvent::Kind::opened:
          reset();
          requests_.clear();
          break;
        case CaptureEvent::Kind::sent:
          ++write;
          sent(e, write);
          break;
        case CaptureEvent::Kind::received:
          received(e);
          break;
      }
    }
  }

 private:
  void reset() {
    to_car_ = adapter_.splitter_for(link::Direction::to_car, false);
    to_client_ =
        std::make_unique<TimedSplitter>(adapter_.splitter_for(link::Direction::to_client, false));
  }

  std::optional<std::string> seq_of(ByteView frame) const {
    const auto range = adapter_.field(frame, "seq");
    if (!range) return std::nullopt;
    return key_of(frame.subspan(range->first, range->second - range->first));
  }

  void sent(const CaptureEvent& e, std::size_t write) {
    std::vector<link::WireFrame> frames;
    to_car_->feed(e.bytes, frames);
    for (auto& f : frames) {
      auto seq = seq_of(f.raw);
      answers_.push_back({std::move(f.raw), f.valid ? std::move(f.kind) : std::string(), {}, {}});
      requests_.push_back({answers_.size() - 1, e.at, write, f.valid, std::move(seq)});
    }
  }

  OpenRequest& request_for(ByteView reply) {
    const std::size_t write = requests_.back().write;
    const auto first = std::find_if(requests_.begin(), requests_.end(),
                                    [&](const OpenRequest& r) { return r.write == write; });
    const auto find = [&](auto&& test) { return std::find_if(first, requests_.end(), test); };
    if (const auto seq = seq_of(reply)) {
      auto it = find([&](const OpenRequest& r) { return !r.answered && r.seq == seq; });
      if (it == requests_.end()) it = find([&](const OpenRequest& r) { return r.seq == seq; });
      if (it != requests_.end()) return *it;
    }
    auto it = find([](const OpenRequest& r) { return !r.answered && r.valid; });
    if (it == requests_.end()) it = find([](const OpenRequest& r) { return !r.answered; });
    return it == requests_.end() ? requests_.back() : *it;
  }

  void received(const CaptureEvent& e) {
    for (auto& [f, first_byte] : to_client_->feed(e.at, e.bytes)) {
      if (f.valid && telemetry_.count(f.kind) != 0) continue;
      if (requests_.empty()) continue;  // before any request of the exchange
      OpenRequest& to = request_for(f.raw);
      to.answered = true;
      answers_[to.answer].replies.push_back(
          {std::move(f.raw), std::max(Duration{0}, first_byte - to.written)});
    }
  }

  const link::ProtocolAdapter& adapter_;
  const std::set<std::string>& telemetry_;
  std::vector<RecordedAnswer>& answers_;
  std::unique_ptr<link::FrameSplitter> to_car_;
  std::unique_ptr<TimedSplitter> to_client_;
  std::vector<OpenRequest> requests_;
};

Duration median_gap(const std::vector<std::pair<Duration, Bytes>>& frames) {
  if (frames.size() < 2) return Duration{0};
  std::vector<Duration> gaps;
  for (std::size_t i = 1; i < frames.size(); ++i)
    gaps.push_back(frames[i].first - frames[i - 1].first);
  std::sort(gaps.begin(), gaps.end());
  return gaps[gaps.size() / 2];
}

// The telemetry on the connection that was open during the first telemetry
// exchange, from that connection's opening (or from the capture's start
// when its opening was not recorded) to its end.
std::vector<TelemetryStream> telemetry_streams(const link::Capture& capture,
                                               const link::ProtocolAdapter& adapter,
                                               const std::set<std::string>& kinds) {
  const auto& xs = capture.exchanges;
  const auto first_telemetry = std::find_if(xs.begin(), xs.end(), [](const CapturedExchange& x) {
    return x.kind == ExchangeKind::telemetry;
  });
  if (first_telemetry == xs.end() || kinds.empty()) return {};
  // Where the connection opened: the last `opened` at or before the
  // telemetry exchange's first received frame.
  std::size_t from_exchange = 0;
  std::size_t from_event = 0;
  Time origin = xs.front().start;
  const auto last = static_cast<std::size_t>(first_telemetry - xs.begin());
  for (std::size_t x = 0; x <= last; ++x) {
    const auto& events = xs[x].events;
    for (std::size_t i = 0; i < events.size(); ++i) {
      if (x == last && events[i].kind == CaptureEvent::Kind::received) break;
      if (events[i].kind == CaptureEvent::Kind::opened) {
        from_exchange = x;
        from_event = i;
        origin = events[i].at;
      }
    }
  }
  std::map<std::string, TelemetryStream> streams;
  TimedSplitter splitter(adapter.splitter_for(link::Direction::to_client, false));
  bool ended = false;
  for (std::size_t x = from_exchange; x < xs.size() && !ended; ++x) {
    const auto& events = xs[x].events;
    for (std::size_t i = x == from_exchange ? from_event : 0; i < events.size(); ++i) {
      const auto& e = events[i];
      const bool other_connection =
          e.kind == CaptureEvent::Kind::closed ||
          (e.kind == CaptureEvent::Kind::opened && !(x == from_exchange && i == from_event));
      if (other_connection) {
        ended = true;
        break;
      }
      if (e.kind != CaptureEvent::Kind::received) continue;
      for (auto& [f, first_byte] : splitter.feed(e.at, e.bytes)) {
        if (!f.valid || kinds.count(f.kind) == 0) continue;
        auto& stream = streams[f.kind];
        stream.kind = f.kind;
        stream.frames.emplace_back(std::max(Duration{0}, first_byte - origin), std::move(f.raw));
      }
    }
  }
  std::vector<TelemetryStream> out;
  for (auto& [kind, stream] : streams) {
    stream.median_period = median_gap(stream.frames);
    out.push_back(std::move(stream));
  }
  return out;
}

}  // namespace

std::string_view to_string(Unmatched unmatched) {
  return kUnmatchedNames.name(unmatched);
}

std::optional<Unmatched> parse_unmatched(std::string_view text) {
  return kUnmatchedNames.parse(text);
}

ReplayIndex index_capture(const link::Capture& capture) {
  const auto adapter = link::protocol_adapter(capture.header.car, capture.header.profile);
  ReplayIndex index;
  index.telemetry_kinds = telemetry_kinds_of(capture, *adapter);
  AnswerIndexer indexer(*adapter, index.telemetry_kinds, index.answers);
  for (const auto& exchange : capture.exchanges) {
    if (exchange.kind != ExchangeKind::telemetry) indexer.exchange(exchange);
  }
  index.telemetry = telemetry_streams(capture, *adapter, index.telemetry_kinds);
  return index;
}

namespace {

// The capture's car as a CarKind, checked against the kind asked for.
void check_car(const link::Capture& capture, CarKind kind) {
  if (capture.header.car != to_string(kind)) {
    throw std::invalid_argument("the capture is of a " + capture.header.car + " car (probe " +
                                capture.header.probe_version + "), not " +
                                std::string(to_string(kind)));
  }
}

const link::Capture& checked(const std::shared_ptr<const link::Capture>& capture, CarKind kind) {
  if (!capture) throw std::invalid_argument("a replay needs a capture");
  check_car(*capture, kind);
  return *capture;
}

}  // namespace

ReplayFirmware::ReplayFirmware(sim::World& world, sim::Vehicle& vehicle, CarKind kind,
                               std::shared_ptr<const link::Capture> capture, Unmatched unmatched,
                               const FirmwareConfigs& configs,
                               std::function<void(const std::string&)> log)
    : Firmware(
          world, vehicle, to_string(kind),
          protocol::find_car_profile(to_string(kind), checked(capture, kind).header.profile).name),
      capture_(std::move(capture)),
      index_(index_capture(*capture_)),
      unmatched_(unmatched),
      log_(std::move(log)) {
  for (std::size_t i = 0; i < index_.answers.size(); ++i) {
    const auto& a = index_.answers[i];
    by_bytes_[key_of(a.request)].push_back(i);
    if (!a.kind.empty()) by_kind_.emplace(a.kind, i);  // the first of each kind stays
  }
  adapter_ = adapter();
  used_.assign(index_.answers.size(), false);
  next_frame_.assign(index_.telemetry.size(), 0);
  if (unmatched_ == Unmatched::mock) {
    // The capture's profile, with the reply latency the caller chose, if any.
    FirmwareConfigs inner = configs;
    apply_profile(inner, kind, profile());
    if (configs.reply_latency) inner.reply_latency = configs.reply_latency;
    inner_ = make_firmware(kind, world, vehicle, inner);
  }
}

ReplayFirmware::~ReplayFirmware() = default;

std::string ReplayFirmware::summary() const {
  return "replay " + std::to_string(used_count_) + "/" + std::to_string(index_.answers.size()) +
         " matched, " + std::to_string(replay_stats_.unmatched) + " unmatched";
}

void ReplayFirmware::on_connect(Time now) {
  requests_ = adapter_->splitter_for(link::Direction::to_car, true);
  pending_.clear();
  close_due_.reset();
  connected_at_ = now;
  std::fill(next_frame_.begin(), next_frame_.end(), 0);
  if (inner_) {
    inner_output_ = adapter_->splitter_for(link::Direction::to_client, false);
    inner_->connect(now);
    inner_->take_output();  // what the inner car says on connection is not the recorded car's
  }
}

void ReplayFirmware::on_disconnect(Time now) {
  connected_at_.reset();
  pending_.clear();
  close_due_.reset();
  if (inner_) inner_->disconnect(now);
}

void ReplayFirmware::on_bytes(Time now, ByteView bytes) {
  if (!requests_) return;
  std::vector<link::WireFrame> frames;
  requests_->feed(bytes, frames);
  for (const auto& f : frames)
    answer(now, f);
}

const RecordedAnswer* ReplayFirmware::recording_for(const link::WireFrame& frame, bool& exact) {
  const auto key = key_of(frame.raw);
  if (const auto it = by_bytes_.find(key); it != by_bytes_.end()) {
    // The same bytes again get the recordings in turn, then the last again:
    // a client that repeats the probe's sequence gets the car's sequence.
    std::size_t& seen = bytes_seen_[key];
    const std::size_t i = it->second[std::min(seen, it->second.size() - 1)];
    ++seen;
    exact = true;
    if (!used_[i]) {
      used_[i] = true;
      ++used_count_;
    }
    return &index_.answers[i];
  }
  if (!frame.valid || frame.kind.empty()) return nullptr;
  const auto it = by_kind_.find(frame.kind);
  if (it == by_kind_.end()) return nullptr;
  exact = false;
  if (!used_[it->second]) {
    used_[it->second] = true;
    ++used_count_;
  }
  return &index_.answers[it->second];
}

void ReplayFirmware::answer(Time now, const link::WireFrame& frame) {
  if (frame.valid) {
    count_frame_in();
  } else {
    count_bad_frame();
  }
  const std::string kind = frame.valid ? frame.kind : std::string();
  take_command(now, kind, [&] {
    bool exact = false;
    if (const auto* recorded = recording_for(frame, exact)) {
      ++(exact ? replay_stats_.exact : replay_stats_.same_kind);
      for (const auto& reply : recorded->replies) {
        pending_.emplace(
            now + reply.latency,
            exact ? reply.bytes : with_request_seq(frame.raw, recorded->request, reply.bytes));
      }
      if (recorded->close_after) {
        const Time due = now + *recorded->close_after;
        if (!close_due_ || due < *close_due_) close_due_ = due;
      }
      return;
    }
    ++replay_stats_.unmatched;
    if (log_) {
      std::string what = protocol::escape(frame.raw);
      if (!frame.text.empty()) what += " (" + frame.text + ")";
      log_("replay: no recording for " + what +
           (inner_ ? "; the " + std::string(profile()) + " mock answers" : "; left unanswered"));
    }
    if (inner_) hand_to_inner(now, frame);
  });
}

Bytes ReplayFirmware::with_request_seq(ByteView request, ByteView recorded_request,
                                       const Bytes& reply) const {
  if (protocol() != "arduino") return reply;
  const auto want = adapter_->field(request, "seq");
  const auto have = adapter_->field(reply, "seq");
  const auto recorded = adapter_->field(recorded_request, "seq");
  if (!want || !have || !recorded) return reply;
  // Only a reply that echoed its request's SEQ echoes this one's.
  const auto field = [](ByteView frame, link::ByteRange range) {
    return key_of(frame.subspan(range.first, range.second - range.first));
  };
  if (field(reply, *have) != field(recorded_request, *recorded)) return reply;
  // The body between '^' and '*', its SEQ the request's, framed again with
  // its checksum.
  std::string body(reply.begin() + 1, reply.end() - 4);
  body.replace(have->first - 1, have->second - have->first,
               std::string(request.begin() + static_cast<std::ptrdiff_t>(want->first),
                           request.begin() + static_cast<std::ptrdiff_t>(want->second)));
  const std::string framed = protocol::arduino::frame_body(body);
  return {framed.begin(), framed.end()};
}

void ReplayFirmware::hand_to_inner(Time now, const link::WireFrame& frame) {
  inner_->receive(now, frame.raw);
  forward_inner(now);
}

void ReplayFirmware::forward_inner(Time now) {
  (void)now;
  if (!inner_ || !inner_output_) return;
  const Bytes out = inner_->take_output();
  if (!out.empty()) {
    std::vector<link::WireFrame> frames;
    inner_output_->feed(out, frames);
    for (const auto& f : frames) {
      if (f.valid && index_.telemetry_kinds.count(f.kind) != 0) continue;
      send(ByteView(f.raw));
    }
  }
  if (const auto close = inner_->take_close()) request_close(*close);
}

void ReplayFirmware::send_due(Time now) {
  while (!pending_.empty() && pending_.begin()->first <= now) {
    send(ByteView(pending_.begin()->second));
    pending_.erase(pending_.begin());
  }
  if (close_due_ && *close_due_ <= now) {
    close_due_.reset();
    request_close(link::CloseMode::graceful);
  }
  if (!connected_at_) return;
  for (std::size_t s = 0; s < index_.telemetry.size(); ++s) {
    const auto& stream = index_.telemetry[s];
    const auto n = stream.frames.size();
    for (;;) {
      const std::size_t i = next_frame_[s];
      if (i >= n && stream.median_period == Duration{0}) break;
      const Duration offset = i < n
                                  ? stream.frames[i].first
                                  : stream.frames[n - 1].first +
                                        stream.median_period * static_cast<std::int64_t>(i - n + 1);
      if (*connected_at_ + offset > now) break;
      if (!telemetry_muted(now)) {
        send(ByteView(stream.frames[i % n].second));
        ++replay_stats_.telemetry;
      }
      ++next_frame_[s];
    }
  }
}

void ReplayFirmware::on_tick(Time now) {
  if (inner_) {
    const auto due = inner_->next_wakeup();
    if (due && *due <= now) inner_->wake(now);
    forward_inner(now);
  }
  send_due(now);
}

std::optional<Time> ReplayFirmware::next_telemetry() const {
  if (!connected_at_) return std::nullopt;
  link::Earliest next;
  for (std::size_t s = 0; s < index_.telemetry.size(); ++s) {
    const auto& stream = index_.telemetry[s];
    const auto n = stream.frames.size();
    const std::size_t i = next_frame_[s];
    if (i < n) {
      next.consider(*connected_at_ + stream.frames[i].first);
    } else if (stream.median_period > Duration{0}) {
      next.consider(*connected_at_ + stream.frames[n - 1].first +
                    stream.median_period * static_cast<std::int64_t>(i - n + 1));
    }
  }
  return next.time();
}

std::optional<Time> ReplayFirmware::next_tick() const {
  link::Earliest next;
  if (!pending_.empty()) next.consider(pending_.begin()->first);
  next.consider(close_due_);
  next.consider(next_telemetry());
  if (inner_) next.consider(inner_->next_wakeup());
  return next.time();
}

}  // namespace hil::mocks
