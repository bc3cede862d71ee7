#pragma once
// A thread-safe record of every frame the Leka client sent and every line the
// robot sent back, exportable as text, CSV or NDJSON.

#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/common/bytes.hpp"

namespace hil::client::leka {

enum class LogDirection : std::uint8_t { tx, rx };
std::string_view to_string(LogDirection d);  ///< "TX" or "RX"

enum class LogFormat : std::uint8_t { txt, csv, ndjson };

struct LogEntry {
  LogDirection direction = LogDirection::tx;
  std::int64_t utc_us = 0;  ///< wall-clock microseconds since the Unix epoch
  protocol::Bytes raw;      ///< exactly the bytes on the wire
  std::string note;         ///< the commands (TX) or the line (RX), for a person
  friend bool operator==(const LogEntry&, const LogEntry&) = default;
};

class CommLog {
 public:
  void add(LogEntry entry);
  std::vector<LogEntry> entries() const;
  std::size_t size() const;
  void clear();

  /// txt: "<utc_us> TX <note> [2A 2B ...]" per line; csv: header then
  /// utc_us,direction,note,hex; ndjson: one object per line.
  std::string to_string(LogFormat format) const;
  /// false when the file cannot be written.
  bool save(const std::string& path, LogFormat format) const;

 private:
  mutable std::mutex mutex_;
  std::vector<LogEntry> entries_;
};

}  // namespace hil::client::leka
