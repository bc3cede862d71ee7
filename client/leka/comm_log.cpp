#include "client/leka/comm_log.hpp"

#include <cstdio>

namespace hil::client::leka {

namespace {

// A JSON string of the note, every byte outside printable ASCII as \u00XX.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  char buf[8];
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c >= 0x7F) {
      std::snprintf(buf, sizeof buf, "\\u%04X", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

}  // namespace

std::string LogEntry::line(LogFormat format) const {
  const std::string time = std::to_string(utc_us);
  const std::string direction(to_string(kind));
  const std::string hex = protocol::to_hex(raw);
  switch (format) {
    case LogFormat::txt:
      return time + ' ' + direction + ' ' + note + " [" + hex + "]\n";
    case LogFormat::csv:
      return time + ',' + direction + ',' + csv_field(note) + ',' + hex + '\n';
    case LogFormat::ndjson:
      return "{\"utc_us\":" + time + ",\"direction\":\"" + direction +
             "\",\"note\":" + json_string(note) + ",\"hex\":\"" + hex + "\"}\n";
  }
  return {};
}

}  // namespace hil::client::leka
