#include "client/arduino/comm_log.hpp"

#include <ctime>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "protocol/common/bytes.hpp"

namespace hil::client::arduino {

std::string_view to_string(LogDirection d) {
  return d == LogDirection::tx ? "TX" : "RX";
}

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

void CommLog::add(LogEntry entry) {
  std::lock_guard lock(mutex_);
  entries_.push_back(std::move(entry));
}

void CommLog::tx(std::int64_t utc_us, std::string raw, std::optional<std::uint8_t> seq) {
  add({LogDirection::tx, utc_us, std::move(raw), seq});
}

void CommLog::rx(std::int64_t utc_us, std::string raw, std::optional<std::uint8_t> seq) {
  add({LogDirection::rx, utc_us, std::move(raw), seq});
}

std::vector<LogEntry> CommLog::entries() const {
  std::lock_guard lock(mutex_);
  return entries_;
}

std::size_t CommLog::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

void CommLog::clear() {
  std::lock_guard lock(mutex_);
  entries_.clear();
}

namespace {

std::string hex_of(const std::string& raw) {
  return protocol::to_hex(protocol::to_bytes(raw));
}

std::string seq_text(const std::optional<std::uint8_t>& seq) {
  if (!seq) return "";
  char buffer[3];
  std::snprintf(buffer, sizeof buffer, "%02X", *seq);
  return buffer;
}

// RFC 4180 quoting: raw frames may hold commas and quotes.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string CommLog::to_string(LogFormat format) const {
  const auto all = entries();
  std::ostringstream out;
  if (format == LogFormat::csv) out << "time,direction,seq,raw,hex\n";
  for (const auto& e : all) {
    const std::string time = iso8601_utc(e.utc_us);
    const std::string hex = hex_of(e.raw);
    switch (format) {
      case LogFormat::txt:
        out << time << ' ' << arduino::to_string(e.direction)
            << " seq=" << (e.seq ? seq_text(e.seq) : "--") << ' '
            << protocol::escape(protocol::to_bytes(e.raw)) << " [" << hex << "]\n";
        break;
      case LogFormat::csv:
        out << time << ',' << arduino::to_string(e.direction) << ',' << seq_text(e.seq) << ','
            << csv_field(e.raw) << ',' << hex << '\n';
        break;
      case LogFormat::ndjson: {
        nlohmann::json j = {{"time", time},
                            {"direction", arduino::to_string(e.direction)},
                            {"raw", e.raw},
                            {"hex", hex}};
        j["seq"] = e.seq ? nlohmann::json(*e.seq) : nlohmann::json(nullptr);
        out << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
        break;
      }
    }
  }
  return out.str();
}

bool CommLog::save(const std::string& path, LogFormat format) const {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) return false;
  file << to_string(format);
  return static_cast<bool>(file);
}

LogFormat CommLog::format_for(std::string_view path) {
  auto ends_with = [&](std::string_view s) {
    return path.size() >= s.size() && path.substr(path.size() - s.size()) == s;
  };
  if (ends_with(".csv")) return LogFormat::csv;
  if (ends_with(".json") || ends_with(".ndjson")) return LogFormat::ndjson;
  return LogFormat::txt;
}

}  // namespace hil::client::arduino
