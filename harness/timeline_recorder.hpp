#pragma once
// The live side of a run's timeline: records stamped with the executor's
// time as they happen, listeners that react to them (wait_until, steps
// scheduled on an event), and the link observer that turns the bytes on the
// wire into frame, fault, open and close records.

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "harness/timeline.hpp"
#include "link/link.hpp"
#include "link/protocol_adapter.hpp"

namespace hil::harness {

/// A value of a decoded frame's field as records and matchers hold it: a
/// decimal number ("50", "-3", "1.5") becomes a JSON number, anything else
/// ("0101", "BAD_V", "(0,0,255)") stays text, so "0101" keeps its digits.
nlohmann::json field_value(std::string_view text);

/// The `name=value` pairs of a decoded frame's message ("SetSpeed
/// percent=50" -> {"percent": 50}); a quoted value (info="OK 3") may hold
/// spaces and loses its quotes; of a name given twice the first is kept.
nlohmann::json message_fields(std::string_view message);

/// A Timeline being written during a run: every record gets the clock's time.
class RunTimeline {
 public:
  using Listener = std::function<void(const Record&)>;
  using ListenerId = std::uint64_t;

  /// `clock` must outlive the timeline.
  explicit RunTimeline(const link::Clock& clock) : clock_(clock) {}
  RunTimeline(const RunTimeline&) = delete;
  RunTimeline& operator=(const RunTimeline&) = delete;

  /// Appends a record at the clock's time and tells every listener. Ignored
  /// once closed (what a run's teardown of links reports is not part of it).
  void add(RecordKind kind, nlohmann::json data = nlohmann::json::object());
  void add_at(Time at, RecordKind kind, nlohmann::json data = nlohmann::json::object());

  /// Listeners see each record after it is in the timeline. They may add
  /// and remove listeners, but must not add records themselves (post the
  /// work instead), so records keep the order things happened in; a record
  /// added from a listener throws std::logic_error.
  ListenerId listen(Listener listener);
  void unlisten(ListenerId id);

  void close() { closed_ = true; }
  bool closed() const { return closed_; }
  Time now() const { return clock_.now(); }

  const Timeline& timeline() const { return timeline_; }
  Timeline take() { return std::move(timeline_); }

 private:
  const link::Clock& clock_;
  Timeline timeline_;
  std::map<ListenerId, std::shared_ptr<Listener>> listeners_;
  // The listeners of the record being told, kept to reuse its storage.
  std::vector<std::pair<ListenerId, std::shared_ptr<Listener>>> snapshot_;
  ListenerId next_id_ = 1;
  bool closed_ = false;
  bool dispatching_ = false;
};

/// Watches a link and writes what crosses it to the timeline: one wire
/// "frame" record per frame (cut by the car's protocol adapter, per
/// direction and stage), "open" and "close", and one fault record per
/// injected fault. One recorder serves every link of a server in turn.
class WireRecorder final : public link::LinkObserver {
 public:
  WireRecorder(RunTimeline& timeline, std::shared_ptr<const link::ProtocolAdapter> protocol);

  void on_open(Time at, const std::string& client, const std::string& car) override;
  void on_sent(Time at, link::Direction d, protocol::ByteView bytes) override;
  void on_delivered(Time at, link::Direction d, protocol::ByteView bytes) override;
  void on_fault(const link::FaultEvent& event) override;
  void on_close(Time at, const link::LinkClose& close) override;

 private:
  void on_bytes(std::size_t stage, Time at, link::Direction d, protocol::ByteView bytes);
  void write_frames(std::size_t stage, Time at, link::Direction d,
                    std::vector<link::WireFrame>& frames);
  void reset_splitters();

  RunTimeline& timeline_;
  std::shared_ptr<const link::ProtocolAdapter> protocol_;
  // [stage: sent, delivered][direction]: a fresh stream per link.
  std::array<std::array<std::unique_ptr<link::FrameSplitter>, 2>, 2> splitters_;
};

}  // namespace hil::harness
