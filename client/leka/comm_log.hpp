#pragma once
// The Leka client's frame log: the common log of client/common/ with an
// entry per frame sent and per line the robot sent back.

#include <cstdint>
#include <string>
#include <string_view>

#include "client/common/comm_log.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::client::leka {

using client::LogFormat;
using client::LogKind;
using client::to_string;

struct LogEntry {
  LogKind kind = LogKind::tx;  ///< tx or rx
  std::int64_t utc_us = 0;     ///< wall-clock microseconds since the Unix epoch
  protocol::Bytes raw;         ///< exactly the bytes on the wire
  std::string note;            ///< the commands (TX) or the line (RX), for a person
  friend bool operator==(const LogEntry&, const LogEntry&) = default;

  static constexpr std::string_view kCsvHeader = "utc_us,direction,note,hex\n";
  /// txt: "<utc_us> TX <note> [2A 2B ...]"; csv: the header's fields;
  /// ndjson: {"utc_us","direction","note","hex"}.
  std::string line(LogFormat format) const;
};

using CommLog = client::EntryLog<LogEntry>;

}  // namespace hil::client::leka
