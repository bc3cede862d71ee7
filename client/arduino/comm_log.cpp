#include "client/arduino/comm_log.hpp"

#include <cstdio>
#include <ctime>

#include <nlohmann/json.hpp>

#include "protocol/common/bytes.hpp"

namespace hil::client::arduino {

std::string iso8601_utc(std::int64_t utc_us) {
  // Floor division, so times before 1970 still get a valid fraction.
  std::int64_t seconds = utc_us / 1'000'000;
  std::int64_t micros = utc_us % 1'000'000;
  if (micros < 0) {
    micros += 1'000'000;
    seconds -= 1;
  }
  const auto t = static_cast<std::time_t>(seconds);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>(micros / 1000));
  return buffer;
}

namespace {

std::string seq_text(const std::optional<std::uint8_t>& seq) {
  if (!seq) return "";
  char buffer[3];
  std::snprintf(buffer, sizeof buffer, "%02X", *seq);
  return buffer;
}

}  // namespace

std::string LogEntry::line(LogFormat format) const {
  const std::string time = iso8601_utc(utc_us);
  const std::string direction(to_string(kind));
  const std::string hex = protocol::to_hex(protocol::to_bytes(raw));
  switch (format) {
    case LogFormat::txt:
      return time + ' ' + direction + " seq=" + (seq ? seq_text(seq) : "--") + ' ' +
             protocol::escape(protocol::to_bytes(raw)) + " [" + hex + "]\n";
    case LogFormat::csv:
      return time + ',' + direction + ',' + seq_text(seq) + ',' + csv_field(raw) + ',' + hex + '\n';
    case LogFormat::ndjson: {
      nlohmann::json j = {{"time", time}, {"direction", direction}, {"raw", raw}, {"hex", hex}};
      j["seq"] = seq ? nlohmann::json(*seq) : nlohmann::json(nullptr);
      return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + '\n';
    }
  }
  return {};
}

}  // namespace hil::client::arduino
