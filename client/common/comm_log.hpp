#pragma once
// A client's communication log: every frame sent and received (and, for
// LOGI and WR8, every parse error and note), shared between the client core
// and a UI thread, exported as text, CSV or NDJSON. One log type serves
// every family; each family's entry says how it reads in each format.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "link/time.hpp"

namespace hil::client {

/// The formats a log is exported in.
enum class LogFormat : std::uint8_t { txt, csv, ndjson };
/// The format a file name asks for: .csv, .ndjson/.jsonl/.json, anything else txt.
LogFormat log_format_for(std::string_view path);
/// Writes `text` to `path`, replacing it; false when it cannot be written.
bool write_log_file(const std::string& path, std::string_view text);
/// A CSV field, quoted as RFC 4180 asks only when it holds , " CR or LF.
std::string csv_field(std::string_view text);

enum class LogKind : std::uint8_t {
  tx,           ///< a frame the client sent
  rx,           ///< a frame the client received
  parse_error,  ///< received bytes that were not a valid frame (dropped)
  note,         ///< a connection change or a dispatcher decision, for context
};
std::string_view to_string(LogKind kind);  ///< "TX", "RX", "ERR", "NOTE"

/// Thread-safe: a core appends from the network thread while a UI reads.
/// `Entry` has `static constexpr std::string_view kCsvHeader` (with its line
/// end, empty for none) and `std::string line(LogFormat) const` (one line,
/// with its line end). Beyond `max_entries` the oldest tenth is let go.
template <class Entry, std::size_t DefaultMaxEntries = std::numeric_limits<std::size_t>::max()>
class EntryLog {
 public:
  explicit EntryLog(std::size_t max_entries = DefaultMaxEntries) : max_entries_(max_entries) {}

  void add(Entry entry) {
    std::lock_guard lock(mutex_);
    entries_.push_back(std::move(entry));
    if (entries_.size() > max_entries_) {
      // Drop a tenth at once so a full log does not shift on every frame.
      const std::size_t n = max_entries_ / 10 > 0 ? max_entries_ / 10 : 1;
      entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(n));
      dropped_ += n;
    }
  }
  /// A copy of every entry still held, oldest first.
  std::vector<Entry> entries() const {
    std::lock_guard lock(mutex_);
    return entries_;
  }
  /// Entries with index >= `from` (indices count every entry ever added), so
  /// a UI can poll for what is new.
  std::vector<Entry> since(std::uint64_t from) const {
    std::lock_guard lock(mutex_);
    const std::uint64_t first = from > dropped_ ? from - dropped_ : 0;
    if (first >= entries_.size()) return {};
    return {entries_.begin() + static_cast<std::ptrdiff_t>(first), entries_.end()};
  }
  /// Entries still held.
  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return entries_.size();
  }
  /// Entries ever added (dropped ones included).
  std::uint64_t total() const {
    std::lock_guard lock(mutex_);
    return dropped_ + entries_.size();
  }
  void clear() {
    std::lock_guard lock(mutex_);
    dropped_ += entries_.size();
    entries_.clear();
  }

  /// The entries held, in `format`.
  std::string to_string(LogFormat format) const {
    std::string out;
    if (format == LogFormat::csv) out += Entry::kCsvHeader;
    for (const auto& e : entries())
      out += e.line(format);
    return out;
  }
  /// Writes to_string(format) to `path`; false when it cannot be written.
  bool save(const std::string& path, LogFormat format) const {
    return write_log_file(path, to_string(format));
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;
  std::uint64_t dropped_ = 0;  // oldest entries let go to stay within max_entries_
  std::size_t max_entries_;
};

/// An entry of the LOGI and WR8 clients' log.
struct LogEntry {
  link::Time at{0};
  LogKind kind = LogKind::note;
  std::string raw;  ///< the bytes as on the wire: text for LOGI, hex for WR8 (empty for notes)
  std::string description;  ///< parsed meaning or the error, for a person
  friend bool operator==(const LogEntry&, const LogEntry&) = default;

  /// Fields time_ms,kind,raw,description, quoted as RFC 4180 asks.
  static constexpr std::string_view kCsvHeader = "time_ms,kind,raw,description\r\n";
  /// txt: "   12.345 ms TX   LOGI:SP:050:D7#  SetSpeed percent=50"; csv: the
  /// header's fields; ndjson: {"time_ms":..,"kind":"TX","raw":..,"description":..}.
  std::string line(LogFormat format) const;
};

/// The LOGI and WR8 clients' log, at most 100 000 entries by default.
using CommLog = EntryLog<LogEntry, 100'000>;

}  // namespace hil::client
