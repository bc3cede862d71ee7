#include "harness/timeline_recorder.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "link/capture/wire_log.hpp"

namespace hil::harness {

// ------------------------------------------------------------ fields

namespace {

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

/// Whole decimal numbers without a leading zero, with or without a
/// fraction: "0", "50", "-3", "1.5", "0.25"; not "030", "1.", "1e3".
bool is_decimal(std::string_view t) {
  std::size_t i = 0;
  if (i < t.size() && t[i] == '-') ++i;
  const std::size_t first = i;
  while (i < t.size() && is_digit(t[i]))
    ++i;
  const std::size_t digits = i - first;
  if (digits == 0 || (digits > 1 && t[first] == '0')) return false;
  if (i == t.size()) return true;
  if (t[i] != '.') return false;
  const std::size_t fraction = ++i;
  while (i < t.size() && is_digit(t[i]))
    ++i;
  return i > fraction && i == t.size();
}

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || is_digit(c) || c == '_' || c == '-';
}

}  // namespace

nlohmann::json field_value(std::string_view text) {
  if (!is_decimal(text)) return std::string(text);
  if (text.find('.') == std::string_view::npos) {
    std::int64_t whole = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), whole);
    if (ec == std::errc() && end == text.data() + text.size()) return whole;
    return std::string(text);  // too long for a number: the digits are what counts
  }
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec == std::errc() && end == text.data() + text.size()) return value;
  return std::string(text);
}

nlohmann::json message_fields(std::string_view message) {
  auto fields = nlohmann::json::object();
  std::size_t i = 0;
  const std::size_t n = message.size();
  // A quoted run ends at the next quote no backslash escapes.
  const auto closing_quote = [&](std::size_t open) {
    std::size_t j = open + 1;
    while (j < n && message[j] != '"')
      j += message[j] == '\\' ? std::size_t{2} : std::size_t{1};
    return std::min(j, n);
  };
  while (i < n) {
    if (message[i] == ' ') {
      ++i;
      continue;
    }
    if (message[i] == '"') {  // a quoted word that names nothing (Leka's reply "...")
      i = closing_quote(i) + 1;
      continue;
    }
    std::size_t j = i;
    if (message[j] == '+') ++j;  // LOGI's keys the profile does not know: "+BAT=87"
    const std::size_t name_at = j;
    while (j < n && is_name_char(message[j]))
      ++j;
    if (j == name_at || j >= n || message[j] != '=') {
      while (i < n && message[i] != ' ')
        ++i;
      continue;
    }
    const std::string name(message.substr(name_at, j - name_at));
    ++j;
    nlohmann::json value;
    if (j < n && message[j] == '"') {
      const std::size_t end = closing_quote(j);
      value = field_value(message.substr(j + 1, end - j - 1));
      i = end + 1;
    } else {
      std::size_t end = j;
      while (end < n && message[end] != ' ')
        ++end;
      value = field_value(message.substr(j, end - j));
      i = end;
    }
    if (!fields.contains(name)) fields[name] = std::move(value);
  }
  return fields;
}

// ------------------------------------------------------------ RunTimeline

void RunTimeline::add(RecordKind kind, nlohmann::json data) {
  add_at(clock_.now(), kind, std::move(data));
}

void RunTimeline::add_at(Time at, RecordKind kind, nlohmann::json data) {
  if (closed_) return;
  if (dispatching_) {
    // The record a listener holds lives in the timeline's vector, which
    // this would move; and the order of records would no longer be the
    // order things happened in.
    throw std::logic_error("a timeline listener added a '" + std::string(kind.name()) +
                           "' record itself; it must post that work instead");
  }
  timeline_.add(at, kind, std::move(data));
  if (listeners_.empty()) return;
  // Listeners may come and go while they run: each one listening when the
  // record came is told, unless it has gone by its turn.
  const Record& record = timeline_.records().back();
  snapshot_.assign(listeners_.begin(), listeners_.end());
  dispatching_ = true;
  try {
    for (const auto& [id, listener] : snapshot_) {
      if (listeners_.count(id) != 0) (*listener)(record);
    }
  } catch (...) {
    dispatching_ = false;
    snapshot_.clear();
    throw;
  }
  dispatching_ = false;
  snapshot_.clear();
}

RunTimeline::ListenerId RunTimeline::listen(Listener listener) {
  const ListenerId id = next_id_++;
  listeners_.emplace(id, std::make_shared<Listener>(std::move(listener)));
  return id;
}

void RunTimeline::unlisten(ListenerId id) {
  listeners_.erase(id);
}

// ------------------------------------------------------------ WireRecorder

namespace {

constexpr std::size_t kSent = 0;
constexpr std::size_t kDelivered = 1;
constexpr const char* kStageNames[2] = {"sent", "delivered"};

std::size_t index_of(link::Direction d) {
  return static_cast<std::size_t>(d);
}

// "bad_checksum: expected 3F, got 40" -> "bad_checksum".
std::string error_kind(const std::string& text) {
  const auto colon = text.find(':');
  return colon == std::string::npos ? text : text.substr(0, colon);
}

}  // namespace

WireRecorder::WireRecorder(RunTimeline& timeline,
                           std::shared_ptr<const link::ProtocolAdapter> protocol)
    : timeline_(timeline), protocol_(std::move(protocol)) {
  reset_splitters();
}

void WireRecorder::reset_splitters() {
  for (std::size_t stage : {kSent, kDelivered}) {
    for (const auto d : {link::Direction::to_car, link::Direction::to_client}) {
      splitters_[stage][index_of(d)] =
          protocol_ ? protocol_->splitter_for(d) : link::protocol_adapter("raw")->splitter();
    }
  }
}

void WireRecorder::on_open(Time at, const std::string& client, const std::string& car) {
  reset_splitters();
  timeline_.add_at(at, WireKind::open, {{"client", client}, {"car", car}});
}

void WireRecorder::on_sent(Time at, link::Direction d, protocol::ByteView bytes) {
  on_bytes(kSent, at, d, bytes);
}

void WireRecorder::on_delivered(Time at, link::Direction d, protocol::ByteView bytes) {
  on_bytes(kDelivered, at, d, bytes);
}

void WireRecorder::on_bytes(std::size_t stage, Time at, link::Direction d,
                            protocol::ByteView bytes) {
  std::vector<link::WireFrame> frames;
  splitters_[stage][index_of(d)]->feed(bytes, frames);
  write_frames(stage, at, d, frames);
}

void WireRecorder::write_frames(std::size_t stage, Time at, link::Direction d,
                                std::vector<link::WireFrame>& frames) {
  for (auto& f : frames) {
    nlohmann::json data;
    data["dir"] = std::string(link::to_string(d));
    data["stage"] = kStageNames[stage];
    data["frame"] = f.kind;
    link::put_bytes(data, f.raw);
    data["valid"] = f.valid;
    if (f.valid) {
      if (!f.text.empty()) {
        auto fields = message_fields(f.text);
        if (!fields.empty()) data["fields"] = std::move(fields);
        data["message"] = f.text;
      }
    } else {
      data["error"] = error_kind(f.text);
      data["detail"] = f.text;
    }
    timeline_.add_at(at, WireKind::frame, std::move(data));
  }
}

void WireRecorder::on_fault(const link::FaultEvent& event) {
  nlohmann::json data{{"dir", std::string(link::to_string(event.direction))},
                      {"rule", event.rule},
                      {"detail", event.detail}};
  if (event.frame != 0) data["frame_number"] = event.frame;
  timeline_.add_at(event.at, event.kind, std::move(data));
}

void WireRecorder::on_close(Time at, const link::LinkClose& close) {
  // What a stream held when it ended is a frame too (truncated).
  for (std::size_t stage : {kSent, kDelivered}) {
    for (const auto d : {link::Direction::to_car, link::Direction::to_client}) {
      std::vector<link::WireFrame> frames;
      splitters_[stage][index_of(d)]->finish(frames);
      write_frames(stage, at, d, frames);
    }
  }
  timeline_.add_at(at, WireKind::close,
                   {{"by", std::string(link::to_string(close.by))},
                    {"reason", close.reason},
                    {"mode", close.mode == link::CloseMode::reset ? "reset" : "graceful"}});
  reset_splitters();
}

}  // namespace hil::harness
