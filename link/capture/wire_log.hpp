#pragma once
// The NDJSON wire log: one JSON object per line for every byte that crosses
// a link (both directions, before and after faults), every fault and the
// open and close, with link time and wall time. Schema in docs/capture.md.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "link/capture/capture_file.hpp"
#include "link/link.hpp"

namespace hil::link {

struct WireLogOptions {
  /// The "link" field of every record, so several links can share one file.
  std::string link_id = "link";
  /// Cuts the bytes into frames for the "frames" field; null writes no
  /// "frames" (raw bytes only).
  std::shared_ptr<const ProtocolAdapter> protocol;
  /// Source of "wall_us"; wall_time_us() when empty. Tests pin it.
  std::function<std::int64_t()> wall_clock_us;
  /// `append` (the default) adds to the file, so several links may share
  /// it; `truncate` starts it empty (a probe capture is one file per run).
  CaptureFile::Mode mode = CaptureFile::Mode::append;
};

/// A LinkObserver that appends one NDJSON record per event to a file. Each
/// record is handed to the kernel with one write(2) on an O_APPEND file
/// before the callback returns, so a crash of hil loses nothing already
/// logged, and several WireLogs (one per link) may append to the same path
/// without tearing each other's lines.
class WireLog final : public LinkObserver {
 public:
  /// Opens `path` for appending, creating it if needed. Returns null and
  /// sets `ec` when it cannot.
  static std::shared_ptr<WireLog> open(const std::filesystem::path& path, WireLogOptions options,
                                       std::error_code& ec);
  ~WireLog() override;
  WireLog(const WireLog&) = delete;
  WireLog& operator=(const WireLog&) = delete;

  void on_open(Time at, const std::string& client, const std::string& car) override;
  void on_sent(Time at, Direction d, protocol::ByteView bytes) override;
  void on_delivered(Time at, Direction d, protocol::ByteView bytes) override;
  void on_fault(const FaultEvent& event) override;
  void on_half_close(Time at, Direction d) override;
  void on_close(Time at, const LinkClose& close) override;
  /// A record of a kind the link itself never writes (a probe's `exchange`
  /// markers): `link`, `event`, `t_ms` and `wall_us`, then `fields`.
  void on_note(Time at, const char* event, const nlohmann::ordered_json& fields);

  /// The first write error, if any; later records are still attempted.
  std::error_code error() const { return file_.error(); }
  std::uint64_t records_written() const { return records_written_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  WireLog(std::filesystem::path path, CaptureFile file, WireLogOptions options);
  // Ordered, so every line reads link, event, t_ms, wall_us first.
  nlohmann::ordered_json record(const char* event, Time at) const;
  void on_bytes(const char* event, std::size_t kind_index, Time at, Direction d,
                protocol::ByteView bytes);
  void write_line(const nlohmann::ordered_json& record);
  /// The partial frames still held for `dirs` (both stages), as the
  /// "unfinished" field lists them; the splitters are left empty.
  nlohmann::ordered_json unfinished(std::initializer_list<Direction> dirs);

  std::filesystem::path path_;
  CaptureFile file_;
  WireLogOptions options_;
  // [0] sent, [1] delivered; each indexed by Direction. Separate splitters
  // because faults make the two streams differ (a fragment cut before a
  // fault must not glue onto bytes after it).
  std::unique_ptr<FrameSplitter> splitters_[2][2];
  std::uint64_t records_written_ = 0;
};

/// The bytes of a capture as JSON fields: {"bytes": n} plus "text" when
/// every byte is printable ASCII, tab, CR or LF (the JSON string holds them
/// exactly), else "hex" (spaced uppercase). Shared with reports.
void put_bytes(nlohmann::json& record, protocol::ByteView bytes);
void put_bytes(nlohmann::ordered_json& record, protocol::ByteView bytes);

/// A decoded frame's text as a person may read it: the authentication
/// string of a WR8 AUTH (kind "AUTH") replaced by asterisks, every other
/// frame unchanged. The wire log's "frames" use it; the raw "text"/"hex"
/// of the record still hold every byte (that is the capture).
std::string masked_frame_text(std::string_view kind, std::string text);

/// The bytes a record's "text" or "hex" field holds; empty when it has
/// neither.
protocol::Bytes bytes_of(const nlohmann::json& record);

/// The adapter that frames a wire log's bytes as they were framed when it
/// was written: protocol_adapter() of its open record's "protocol" and
/// "profile" (a record with no "profile" gets the protocol's default). A
/// WR8 log of profile svgui-2019 or svgui-head is cut by the length byte,
/// a `document` one is not. Throws std::invalid_argument for a record that
/// is not an open record or names no protocol hil knows, and
/// protocol::ProfileError for a profile the protocol does not have.
std::shared_ptr<const ProtocolAdapter> adapter_of_log(const nlohmann::json& open_record);

/// Every record of a wire log, in file order. A final line with no newline
/// that does not parse (a writer killed mid-line, or still writing) is
/// skipped; any other line that does not parse throws std::runtime_error
/// naming the file and line. A missing file throws too.
std::vector<nlohmann::json> read_wire_log(const std::filesystem::path& path);

}  // namespace hil::link
