#include "client/common/comm_log.hpp"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "base/enum_names.hpp"

namespace hil::client {

LogFormat log_format_for(std::string_view path) {
  if (path.ends_with(".csv")) return LogFormat::csv;
  if (path.ends_with(".ndjson") || path.ends_with(".jsonl") || path.ends_with(".json"))
    return LogFormat::ndjson;
  return LogFormat::txt;
}

bool write_log_file(const std::string& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  return out && out.write(text.data(), static_cast<std::streamsize>(text.size())) && out.flush();
}

std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

constexpr auto kLogKindNames =
    base::enum_names<LogKind>({LogKind::tx, "TX"}, {LogKind::rx, "RX"},
                              {LogKind::parse_error, "ERR"}, {LogKind::note, "NOTE"});

std::string_view to_string(LogKind kind) {
  return kLogKindNames.name(kind);
}

namespace {

std::string time_ms(link::Time at) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", link::to_ms(at));
  return buf;
}

// Every field quoted, as a spreadsheet reads the LOGI and WR8 logs.
std::string quoted_csv(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

// Raw bytes may be anything the wire carried; JSON wants valid UTF-8, so
// bytes outside printable ASCII are written as \xNN.
std::string printable(std::string_view s) {
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7F) {
      out += ch;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
  }
  return out;
}

}  // namespace

std::string LogEntry::line(LogFormat format) const {
  switch (format) {
    case LogFormat::txt: {
      char head[48];
      std::snprintf(head, sizeof head, "%12.3f ms %-4s ", link::to_ms(at),
                    std::string(to_string(kind)).c_str());
      std::string out = head + printable(raw);
      if (!raw.empty() && !description.empty()) out += "  ";
      return out + description + '\n';
    }
    case LogFormat::csv:
      return time_ms(at) + "," + std::string(to_string(kind)) + "," + quoted_csv(printable(raw)) +
             "," + quoted_csv(description) + "\r\n";
    case LogFormat::ndjson: {
      nlohmann::json j;
      j["time_ms"] = link::to_ms(at);
      j["kind"] = std::string(to_string(kind));
      j["raw"] = printable(raw);
      j["description"] = printable(description);
      return j.dump() + "\n";
    }
  }
  return {};
}

}  // namespace hil::client
