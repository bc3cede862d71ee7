#pragma once
// A client's communication log: every frame sent and received and
// every parse error, shared between the client core and a UI thread.

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "link/time.hpp"

namespace hil::client {

enum class LogKind : std::uint8_t {
  tx,           ///< a frame the client sent
  rx,           ///< a frame the client received and decoded
  parse_error,  ///< received bytes that were not a valid frame (dropped)
  note,         ///< a connection change or a dispatcher decision, for context
};
std::string_view to_string(LogKind kind);  ///< "TX", "RX", "ERR", "NOTE"

struct LogEntry {
  link::Time at{0};
  LogKind kind = LogKind::note;
  std::string raw;  ///< the bytes as on the wire: text for LOGI, hex for WR8 (empty for notes)
  std::string description;  ///< parsed meaning or the error, for a person
  friend bool operator==(const LogEntry&, const LogEntry&) = default;
};

/// Thread-safe: the core appends from the network thread while a UI reads.
class CommLog {
 public:
  explicit CommLog(std::size_t max_entries = 100'000) : max_entries_(max_entries) {}

  void add(LogEntry entry);
  /// A copy of every entry still held, oldest first.
  std::vector<LogEntry> snapshot() const;
  /// Entries with index >= `from` (indices count every entry ever added), so
  /// a UI can poll for what is new.
  std::vector<LogEntry> since(std::uint64_t from) const;
  /// Entries ever added (dropped ones included).
  std::uint64_t total() const;
  void clear();

  /// One line per entry, e.g. "   12.345 ms TX   LOGI:SP:050:D7#  SetSpeed percent=50".
  std::string export_text() const;
  /// Header "time_ms,kind,raw,description", fields quoted as RFC 4180 asks.
  std::string export_csv() const;
  /// One JSON object per line: {"time_ms":..,"kind":"TX","raw":..,"description":..}.
  std::string export_ndjson() const;

 private:
  mutable std::mutex mutex_;
  std::vector<LogEntry> entries_;
  std::uint64_t dropped_ = 0;  // oldest entries let go to stay within max_entries_
  std::size_t max_entries_;
};

}  // namespace hil::client
