#pragma once
// A thread-safe record of every frame the Arduino client sent and received,
// exportable as text, CSV or NDJSON for a person or a tool.

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hil::client::arduino {

enum class LogDirection : std::uint8_t { tx, rx };
std::string_view to_string(LogDirection d);  ///< "TX" or "RX"

enum class LogFormat : std::uint8_t { txt, csv, ndjson };

struct LogEntry {
  LogDirection direction = LogDirection::tx;
  /// Wall-clock time in microseconds since the Unix epoch (UTC).
  std::int64_t utc_us = 0;
  std::string raw;  ///< the bytes as text, exactly as on the wire
  std::optional<std::uint8_t> seq;
  friend bool operator==(const LogEntry&, const LogEntry&) = default;
};

/// "2026-11-22T06:07:51.123Z": UTC, ISO-8601, millisecond precision.
std::string iso8601_utc(std::int64_t utc_us);

/// Every method may be called from any thread.
class CommLog {
 public:
  void add(LogEntry entry);
  void tx(std::int64_t utc_us, std::string raw, std::optional<std::uint8_t> seq);
  void rx(std::int64_t utc_us, std::string raw, std::optional<std::uint8_t> seq);

  std::vector<LogEntry> entries() const;
  std::size_t size() const;
  void clear();

  /// txt: "<time> TX seq=01 ^01|PING|*11$ [5E 30 ...]" per line; csv: a header
  /// line then time,direction,seq,raw,hex; ndjson: one JSON object per line.
  std::string to_string(LogFormat format) const;
  /// Writes to_string(format) to `path`; false when the file cannot be written.
  bool save(const std::string& path, LogFormat format) const;
  /// The format a file name asks for: .csv, .json/.ndjson, anything else txt.
  static LogFormat format_for(std::string_view path);

 private:
  mutable std::mutex mutex_;
  std::vector<LogEntry> entries_;
};

}  // namespace hil::client::arduino
