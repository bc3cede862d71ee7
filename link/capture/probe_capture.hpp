#pragma once
// A probe capture (`hil conform probe`): what a probe sent and what came back, exchange by
// exchange, with times. On disk it is an NDJSON wire log (docs/capture.md)
// with three more records: `probe` (first: the probe's version, the car,
// the profile, the target), and `exchange` / `exchange_end` around each
// exchange's records. Only `sent` records towards the car and `delivered`
// records towards the client appear: what the probe wrote, and what
// reached it.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "link/capture/wire_log.hpp"
#include "link/link.hpp"

namespace hil::link {

/// What an exchange of a probe tests, for the report's grouping and for
/// the checks that apply to it.
enum class ExchangeKind : std::uint8_t {
  command,    ///< a valid command; the answer is compared frame by frame
  boundary,   ///< a valid command at the edge of a field's range
  error,      ///< a frame the car should refuse or ignore
  framing,    ///< a valid frame cut or joined differently on the wire
  telemetry,  ///< no writes: the car's own frames and their period
  connect,    ///< the connection is opened (closed and opened again) first
  stop,       ///< the probe's closing stop
};
std::string_view to_string(ExchangeKind kind);
std::optional<ExchangeKind> parse_exchange_kind(std::string_view text);

struct CaptureEvent {
  enum class Kind : std::uint8_t {
    sent,      ///< the probe wrote `bytes`
    received,  ///< `bytes` arrived from the car
    opened,    ///< the connection opened
    closed,    ///< the connection ended; `by` says who ended it
  };
  Kind kind = Kind::sent;
  Time at{0};  ///< since the probe started
  Bytes bytes;
  LinkClose::By by = LinkClose::By::hil;

  friend bool operator==(const CaptureEvent&, const CaptureEvent&) = default;
};

struct CapturedExchange {
  std::string name;
  std::string what;
  ExchangeKind kind = ExchangeKind::command;
  Time start{0};
  Time end{0};
  std::vector<CaptureEvent> events;

  friend bool operator==(const CapturedExchange&, const CapturedExchange&) = default;
};

/// The `probe` record: which probe made the capture, of what.
struct CaptureHeader {
  std::string probe_version;  ///< "logi-probe/1"
  std::string car;            ///< "logi", "wr8", "arduino" or "leka"
  std::string profile;        ///< the profile the probe's frames were written in
  std::string target;         ///< the URI probed ("mock:<profile>" for a check's own run)
  std::int64_t started_wall_us = 0;

  friend bool operator==(const CaptureHeader&, const CaptureHeader&) = default;
};

struct Capture {
  CaptureHeader header;
  std::vector<CapturedExchange> exchanges;

  friend bool operator==(const Capture&, const Capture&) = default;
};

/// A capture file that cannot be read; what() names the file, the line and
/// what was wrong.
class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Builds a Capture as a probe runs and, with a wire log, appends every
/// event to it as it happens (so a probe cut short keeps what it saw).
class CaptureRecorder {
 public:
  explicit CaptureRecorder(CaptureHeader header, std::shared_ptr<WireLog> log = nullptr);

  void begin_exchange(Time at, std::string name, ExchangeKind kind, std::string what);
  void end_exchange(Time at);
  void opened(Time at, const std::string& client, const std::string& car);
  void sent(Time at, protocol::ByteView bytes);
  void received(Time at, protocol::ByteView bytes);
  void closed(Time at, const LinkClose& close);

  const Capture& capture() const { return capture_; }
  Capture take() { return std::move(capture_); }

 private:
  CapturedExchange* current();

  Capture capture_;
  std::shared_ptr<WireLog> log_;
  bool in_exchange_ = false;
};

/// Opens `path` for a capture (creating or truncating it), its frames cut
/// by `protocol`, and returns the wire log to give a CaptureRecorder.
/// Throws CaptureError when it cannot.
std::shared_ptr<WireLog> open_capture_log(const std::filesystem::path& path,
                                          std::shared_ptr<const ProtocolAdapter> protocol);

/// Reads a capture written through a CaptureRecorder. Throws CaptureError.
Capture read_capture(const std::filesystem::path& path);

}  // namespace hil::link
