#pragma once
// The Arduino client's frame log: the common log of client/common/ with an
// entry per frame sent and received, its UTC time, raw text and SEQ.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "client/common/comm_log.hpp"

namespace hil::client::arduino {

using client::LogFormat;
using client::LogKind;
using client::to_string;

/// "2026-11-22T06:07:51.123Z": UTC, ISO-8601, millisecond precision.
std::string iso8601_utc(std::int64_t utc_us);

struct LogEntry {
  LogKind kind = LogKind::tx;  ///< tx or rx
  /// Wall-clock time in microseconds since the Unix epoch (UTC).
  std::int64_t utc_us = 0;
  std::string raw;  ///< the bytes as text, exactly as on the wire
  std::optional<std::uint8_t> seq;
  friend bool operator==(const LogEntry&, const LogEntry&) = default;

  static constexpr std::string_view kCsvHeader = "time,direction,seq,raw,hex\n";
  /// txt: "<time> TX seq=01 ^01|PING|*11$ [5E 30 ...]"; csv: the header's
  /// fields; ndjson: {"time","direction","raw","hex","seq"}.
  std::string line(LogFormat format) const;
};

/// Every method may be called from any thread.
using CommLog = client::EntryLog<LogEntry>;

}  // namespace hil::client::arduino
