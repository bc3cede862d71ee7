#pragma once
// A recorded car as a mock: a firmware that answers each client frame with
// what a real car answered to the same request in a probe capture
// (`hil conform probe`, link/capture/probe_capture.hpp), after the same
// latency, and sends the car's unsolicited frames (telemetry) on the
// recorded schedule. A request the capture has no answer for goes to the
// capture's profile's own mock firmware, or is left unanswered
// (docs/mocks.md, "Replaying a recorded car").

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "link/capture/probe_capture.hpp"
#include "mocks/firmware.hpp"

namespace hil::mocks {

enum class CarKind : std::uint8_t;
struct FirmwareConfigs;

/// What a replayed car does with a client frame the capture has no answer for.
enum class Unmatched : std::uint8_t {
  mock,    ///< the mock firmware of the capture's profile answers it
  silent,  ///< nothing answers it
};
std::string_view to_string(Unmatched unmatched);
std::optional<Unmatched> parse_unmatched(std::string_view text);

/// A car replayed from a capture: `CarOptions::replay`, a scenario's
/// `car: {replay: FILE}`, `hil mock CAR --replay FILE`.
struct ReplaySpec {
  /// The capture's file, for messages (and to read it when `capture` is
  /// not given).
  std::string path;
  /// The capture already read; null: read from `path` when the car is built.
  std::shared_ptr<const link::Capture> capture;
  Unmatched unmatched = Unmatched::mock;
  /// Told one line per client frame the capture has no answer for.
  std::function<void(const std::string&)> log;
};

/// One recorded answer: a frame the car sent `latency` after the request's
/// last byte was written.
struct RecordedReply {
  Bytes bytes;
  Duration latency{0};
};

/// The answer to one request as the car gave it: its frames, none when the
/// car ignored the request.
struct RecordedAnswer {
  Bytes request;
  std::string kind;  ///< the request's frame kind; empty for a frame that did not decode
  std::vector<RecordedReply> replies;
  /// The car closed the connection this long after the request.
  std::optional<Duration> close_after;
};

/// The car's frames of one telemetry kind on the recorded connection.
struct TelemetryStream {
  std::string kind;
  /// Each frame and its time since the connection opened.
  std::vector<std::pair<Duration, Bytes>> frames;
  /// The median time between two frames; zero with fewer than two frames
  /// (then the stream ends with the recording).
  Duration median_period{0};
};

/// The capture as the replay uses it.
struct ReplayIndex {
  /// Every request in recorded order, with its answer.
  std::vector<RecordedAnswer> answers;
  /// Frame kinds the car sent unprompted (received in telemetry exchanges).
  std::set<std::string> telemetry_kinds;
  std::vector<TelemetryStream> telemetry;
};

/// Cuts a capture into requests and answers with the frame splitters of
/// its car and profile. Throws protocol::ProfileError for a profile the car
/// does not have.
ReplayIndex index_capture(const link::Capture& capture);

struct ReplayStats {
  std::uint64_t exact = 0;      ///< client frames answered with the recording of the same bytes
  std::uint64_t same_kind = 0;  ///< ... with the first recording of the same kind
  std::uint64_t unmatched = 0;  ///< client frames with no recording
  std::uint64_t telemetry = 0;  ///< unprompted frames sent from the recording
};

class ReplayFirmware final : public Firmware {
 public:
  /// `kind` must be the capture's car (std::invalid_argument otherwise);
  /// `configs` are the settings of the mock that answers what the capture
  /// has no recording for, before the capture's profile is applied to them
  /// (their reply latency, when set, stays).
  ReplayFirmware(sim::World& world, sim::Vehicle& vehicle, CarKind kind,
                 std::shared_ptr<const link::Capture> capture, Unmatched unmatched,
                 const FirmwareConfigs& configs, std::function<void(const std::string&)> log = {});
  ~ReplayFirmware() override;

  /// "replay 12/41 matched, 2 unmatched": how many of the capture's
  /// recorded requests the client's frames have met (exactly or by kind),
  /// and how many client frames had no recording.
  std::string summary() const override;

  const ReplayIndex& index() const { return index_; }
  const ReplayStats& replay_stats() const { return replay_stats_; }
  Unmatched unmatched_policy() const { return unmatched_; }
  const link::CaptureHeader& header() const { return capture_->header; }

 protected:
  void on_connect(Time now) override;
  void on_disconnect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;

 private:
  void answer(Time now, const link::WireFrame& frame);
  /// The recorded answer for `frame`, or null.
  const RecordedAnswer* recording_for(const link::WireFrame& frame, bool& exact);
  /// An Arduino reply carries its request's SEQ: a recorded reply that
  /// echoed its recorded request's SEQ, given to a request with another,
  /// gets the request's, and its checksum again.
  Bytes with_request_seq(ByteView request, ByteView recorded_request, const Bytes& reply) const;
  void hand_to_inner(Time now, const link::WireFrame& frame);
  /// The inner firmware's answers since the last look, its telemetry dropped.
  void forward_inner(Time now);
  void send_due(Time now);
  std::optional<Time> next_telemetry() const;

  std::shared_ptr<const link::Capture> capture_;
  ReplayIndex index_;
  Unmatched unmatched_;
  std::function<void(const std::string&)> log_;
  std::shared_ptr<const link::ProtocolAdapter> adapter_;
  std::unique_ptr<Firmware> inner_;
  std::unique_ptr<link::FrameSplitter> requests_;             // the client's bytes
  std::unique_ptr<link::FrameSplitter> inner_output_;         // the inner firmware's
  std::map<std::string, std::vector<std::size_t>> by_bytes_;  // request bytes -> its answers
  std::map<std::string, std::size_t> by_kind_;                // request kind -> its first answer
  std::map<std::string, std::size_t> bytes_seen_;  // request bytes -> times answered exactly
  std::vector<bool> used_;                         // answers met so far
  std::size_t used_count_ = 0;
  std::multimap<Time, Bytes> pending_;  // recorded replies waiting for their latency
  std::optional<Time> close_due_;       // a recorded close waiting for its time
  std::optional<Time> connected_at_;
  std::vector<std::size_t> next_frame_;  // per telemetry stream: frames sent this connection
  ReplayStats replay_stats_;
};

}  // namespace hil::mocks
