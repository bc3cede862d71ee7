#include "conform/compare.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

#include "base/text.hpp"
#include "link/protocol_adapter.hpp"

namespace hil::conform {

namespace {

struct TimedFrame {
  Time at{0};
  link::WireFrame frame;
  bool telemetry = false;
};

// One side's frames and events, exchange by exchange. The bytes of a
// connection are cut by one splitter across exchanges, so an answer that
// arrives after its window still forms its frame (in the exchange where it
// completes).
struct SideFrames {
  std::vector<std::vector<TimedFrame>> frames;  // per exchange
  std::vector<std::size_t> closes;              // per exchange: closes by the car
};

bool is_telemetry(const Probe& probe, std::string_view kind) {
  return std::any_of(probe.telemetry_kinds.begin(), probe.telemetry_kinds.end(),
                     [&](const std::string& t) { return !t.empty() && kind.starts_with(t); });
}

SideFrames cut(const Capture& capture, const Probe& probe, const link::ProtocolAdapter& adapter) {
  SideFrames side;
  auto splitter = adapter.splitter_for(link::Direction::to_client);
  std::vector<link::WireFrame> out;
  for (const auto& exchange : capture.exchanges) {
    auto& frames = side.frames.emplace_back();
    auto& closes = side.closes.emplace_back(0);
    auto take = [&](Time at) {
      for (auto& f : out) {
        const bool telemetry = is_telemetry(probe, f.kind);
        frames.push_back({at, std::move(f), telemetry});
      }
      out.clear();
    };
    for (const auto& event : exchange.events) {
      switch (event.kind) {
        case CaptureEvent::Kind::received:
          splitter->feed(event.bytes, out);
          take(event.at);
          break;
        case CaptureEvent::Kind::closed:
          splitter->finish(out);
          take(event.at);
          if (event.by == link::LinkClose::By::car) ++closes;
          break;
        case CaptureEvent::Kind::opened:
          splitter = adapter.splitter_for(link::Direction::to_client);
          break;
        case CaptureEvent::Kind::sent:
          break;
      }
    }
  }
  return side;
}

bool is_text(const protocol::Bytes& raw) {
  return !raw.empty() && std::all_of(raw.begin(), raw.end(), [](std::uint8_t b) {
    return (b >= 0x20 && b < 0x7F) || b == '\r' || b == '\n' || b == '\t';
  });
}

// A frame for a person: a text frame (LOGI, Arduino, a Leka robot's line)
// as its text with CR and LF escaped; a binary one as its kind and hex.
std::string frame_text(const link::ProtocolAdapter& adapter, const link::WireFrame& frame) {
  std::string text;
  if (adapter.text_frames() || is_text(frame.raw)) {
    text = escape_controls(std::string(frame.raw.begin(), frame.raw.end()));
  } else {
    text = frame.kind.empty() ? std::string("?") : frame.kind;
    text += " " + protocol::to_hex(frame.raw);
  }
  if (!frame.valid) text += " (invalid)";
  return text;
}

// A frame as its shape: for a text frame, its bytes with the checksum left
// out and each run of digits as one '#'; for a binary one, its length.
std::string shape_of(const link::ProtocolAdapter& adapter, const link::WireFrame& frame) {
  std::string shape = frame.kind + (frame.valid ? "|valid|" : "|invalid|");
  if (!adapter.text_frames()) return shape + std::to_string(frame.raw.size());
  const auto checksum = adapter.checksum_field(frame.raw);
  bool in_digits = false;
  for (std::size_t i = 0; i < frame.raw.size(); ++i) {
    if (checksum && i >= checksum->first && i < checksum->second) continue;
    const char c = static_cast<char>(frame.raw[i]);
    const bool digit = std::isdigit(static_cast<unsigned char>(c)) != 0;
    if (digit && in_digits) continue;
    shape.push_back(digit ? '#' : c);
    in_digits = digit;
  }
  return shape;
}

std::optional<Duration> median_period(const std::vector<Time>& times) {
  if (times.size() < 2) return std::nullopt;
  std::vector<Duration> gaps;
  for (std::size_t i = 1; i < times.size(); ++i)
    gaps.push_back(times[i] - times[i - 1]);
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2),
                   gaps.end());
  return gaps[gaps.size() / 2];
}

Duration allowed(Duration abs, double rel, Duration reference) {
  const auto scaled = std::chrono::duration_cast<Duration>(reference * rel);
  return std::max(abs, scaled);
}

std::string ms_text(Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f ms", link::to_ms(d));
  return buf;
}

class ExchangeComparer {
 public:
  ExchangeComparer(const Probe& probe, const link::ProtocolAdapter& adapter,
                   const Tolerances& tolerances)
      : probe_(probe), adapter_(adapter), tolerances_(tolerances) {}

  ExchangeComparison compare(const Exchange& exchange, const CapturedExchange* car_exchange,
                             const std::vector<TimedFrame>& car, std::size_t car_closes,
                             const CapturedExchange* mock_exchange,
                             const std::vector<TimedFrame>& mock, std::size_t mock_closes) {
    ExchangeComparison row;
    row.name = exchange.name;
    row.what = exchange.what;
    row.kind = exchange.kind;
    if (!car_exchange || !mock_exchange) {
      row.differences.push_back(std::string("not in the ") + (car_exchange ? "mock's" : "car's") +
                                " capture (the probe stopped before it)");
      return row;
    }
    const bool telemetry_exchange = exchange.kind == ExchangeKind::telemetry;
    row.car = answer_of(*car_exchange, car, car_closes, telemetry_exchange);
    row.mock = answer_of(*mock_exchange, mock, mock_closes, telemetry_exchange);
    compare_frames(exchange, answers(car), answers(mock), row);
    if (row.car.closes != row.mock.closes) {
      row.differences.push_back(closes_text("the car", row.car.closes) + ", " +
                                closes_text("the mock", row.mock.closes));
    }
    if (row.car.latency && row.mock.latency)
      compare_latency(*row.car.latency, *row.mock.latency, row);
    if (telemetry_exchange) {
      compare_periods(row);
      compare_telemetry_shapes(car, mock, row);
    }
    return row;
  }

 private:
  static std::vector<const TimedFrame*> answers(const std::vector<TimedFrame>& frames) {
    std::vector<const TimedFrame*> out;
    for (const auto& f : frames) {
      if (!f.telemetry) out.push_back(&f);
    }
    return out;
  }

  static std::string closes_text(const std::string& who, std::size_t closes) {
    if (closes == 0) return who + " kept the connection open";
    return who + " closed the connection" +
           (closes > 1 ? " " + std::to_string(closes) + " times" : "");
  }

  Answer answer_of(const CapturedExchange& exchange, const std::vector<TimedFrame>& frames,
                   std::size_t closes, bool telemetry_exchange) const {
    Answer answer;
    answer.closes = closes;
    std::map<std::string, std::vector<Time>> telemetry;
    for (const auto& f : frames) {
      if (f.telemetry) {
        telemetry[f.frame.kind].push_back(f.at);
        if (!telemetry_exchange) continue;
      }
      answer.frames.push_back(frame_text(adapter_, f.frame));
      if (!answer.latency && !f.telemetry) answer.latency = latency_to(exchange, f.at);
    }
    if (telemetry_exchange) {
      for (const auto& kind : probe_.telemetry_kinds) {
        for (const auto& [seen, times] : telemetry) {
          if (seen.starts_with(kind)) answer.periods.emplace_back(seen, median_period(times));
        }
      }
    }
    return answer;
  }

  // From the last write at or before `at` in this exchange (or its start).
  static std::optional<Duration> latency_to(const CapturedExchange& exchange, Time at) {
    std::optional<Time> last_write;
    for (const auto& event : exchange.events) {
      if (event.kind == CaptureEvent::Kind::sent && event.at <= at) last_write = event.at;
    }
    if (!last_write) return std::nullopt;
    return at - *last_write;
  }

  void compare_frames(const Exchange& exchange, const std::vector<const TimedFrame*>& car,
                      const std::vector<const TimedFrame*>& mock, ExchangeComparison& row) const {
    if (car.size() != mock.size()) {
      row.differences.push_back("the car answered " + count_text(car.size()) + ", the mock " +
                                count_text(mock.size()));
    }
    const std::size_t n = std::min(car.size(), mock.size());
    for (std::size_t i = 0; i < n; ++i) {
      const auto& a = car[i]->frame;
      const auto& b = mock[i]->frame;
      const bool same =
          exchange.physical ? shape_of(adapter_, a) == shape_of(adapter_, b) : a.raw == b.raw;
      if (same) continue;
      row.differences.push_back("frame " + std::to_string(i + 1) + ": the car sent " +
                                frame_text(adapter_, a) + ", the mock " + frame_text(adapter_, b) +
                                (exchange.physical ? " (compared by shape)" : ""));
    }
    if (car.size() != mock.size()) {
      const auto& longer = car.size() > mock.size() ? car : mock;
      const char* who = car.size() > mock.size() ? "only the car sent " : "only the mock sent ";
      for (std::size_t i = n; i < longer.size(); ++i)
        row.differences.push_back(who + frame_text(adapter_, longer[i]->frame));
    }
  }

  static std::string count_text(std::size_t n) {
    if (n == 0) return "nothing";
    return std::to_string(n) + (n == 1 ? " frame" : " frames");
  }

  void compare_latency(Duration car, Duration mock, ExchangeComparison& row) const {
    const auto limit = allowed(tolerances_.latency_abs, tolerances_.latency_rel, car);
    const auto gap = car > mock ? car - mock : mock - car;
    if (gap <= limit) return;
    row.differences.push_back("answered after " + ms_text(car) + " by the car, " + ms_text(mock) +
                              " by the mock (allowed: " + ms_text(limit) + " apart)");
  }

  // The first frame of each telemetry kind both sides sent, by shape: a car
  // whose STAT has other fields differs even when its period is right.
  void compare_telemetry_shapes(const std::vector<TimedFrame>& car,
                                const std::vector<TimedFrame>& mock,
                                ExchangeComparison& row) const {
    std::map<std::string, const link::WireFrame*> firsts;
    for (const auto& f : car) {
      if (f.telemetry) firsts.emplace(f.frame.kind, &f.frame);
    }
    std::set<std::string> done;
    for (const auto& f : mock) {
      if (!f.telemetry || !done.insert(f.frame.kind).second) continue;
      const auto it = firsts.find(f.frame.kind);
      if (it == firsts.end() || shape_of(adapter_, *it->second) == shape_of(adapter_, f.frame))
        continue;
      row.differences.push_back(f.frame.kind + ": the car sent " +
                                frame_text(adapter_, *it->second) + ", the mock " +
                                frame_text(adapter_, f.frame) + " (compared by shape)");
    }
  }

  void compare_periods(ExchangeComparison& row) const {
    std::map<std::string, std::pair<std::optional<Duration>, std::optional<Duration>>> kinds;
    for (const auto& [kind, period] : row.car.periods)
      kinds[kind].first = period;
    for (const auto& [kind, period] : row.mock.periods)
      kinds[kind].second = period;
    for (const auto& [kind, periods] : kinds) {
      const auto& [car, mock] = periods;
      if (!car && !mock) continue;
      if (!car || !mock) {
        row.differences.push_back(kind + ": a period of " + ms_text(car ? *car : *mock) +
                                  " from the " + (car ? "car" : "mock") + ", none from the " +
                                  (car ? "mock" : "car"));
        continue;
      }
      const auto limit = allowed(tolerances_.period_abs, tolerances_.period_rel, *car);
      const auto gap = *car > *mock ? *car - *mock : *mock - *car;
      if (gap > limit) {
        row.differences.push_back(kind + " every " + ms_text(*car) + " from the car, every " +
                                  ms_text(*mock) + " from the mock (allowed: " + ms_text(limit) +
                                  " apart)");
      }
    }
  }

  const Probe& probe_;
  const link::ProtocolAdapter& adapter_;
  const Tolerances& tolerances_;
};

}  // namespace

std::string Answer::summary() const {
  std::string text;
  for (const auto& f : frames) {
    if (!text.empty()) text += "  ";
    text += f;
  }
  if (closes > 0) text += text.empty() ? "(closed)" : "  (closed)";
  return text.empty() ? "(silent)" : text;
}

std::size_t Comparison::matches() const {
  return static_cast<std::size_t>(std::count_if(
      exchanges.begin(), exchanges.end(), [](const ExchangeComparison& e) { return e.matches(); }));
}

Comparison compare(const Capture& car, const Capture& mock, const Probe& probe,
                   std::string mock_profile, const Tolerances& tolerances) {
  const auto adapter = link::protocol_adapter(mocks::to_string(probe.car), probe.profile);
  const auto car_side = cut(car, probe, *adapter);
  const auto mock_side = cut(mock, probe, *adapter);
  ExchangeComparer comparer(probe, *adapter, tolerances);
  Comparison result;
  result.mock_profile = std::move(mock_profile);
  static const std::vector<TimedFrame> kNone;
  for (std::size_t i = 0; i < probe.exchanges.size(); ++i) {
    const auto& exchange = probe.exchanges[i];
    auto side = [&](const Capture& c) -> const CapturedExchange* {
      if (i >= c.exchanges.size() || c.exchanges[i].name != exchange.name) return nullptr;
      return &c.exchanges[i];
    };
    const auto* a = side(car);
    const auto* b = side(mock);
    result.exchanges.push_back(
        comparer.compare(exchange, a, a ? car_side.frames[i] : kNone, a ? car_side.closes[i] : 0, b,
                         b ? mock_side.frames[i] : kNone, b ? mock_side.closes[i] : 0));
  }
  return result;
}

}  // namespace hil::conform
