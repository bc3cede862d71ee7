#include "client/leka/comm_log.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

namespace hil::client::leka {

std::string_view to_string(LogDirection d) {
  return d == LogDirection::tx ? "TX" : "RX";
}

namespace {
std::string hex(const protocol::Bytes& raw) {
  std::string out;
  char buf[4];
  for (std::size_t i = 0; i < raw.size(); ++i) {
    std::snprintf(buf, sizeof buf, i == 0 ? "%02X" : " %02X", raw[i]);
    out += buf;
  }
  return out;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

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

void CommLog::add(LogEntry entry) {
  std::lock_guard lock(mutex_);
  entries_.push_back(std::move(entry));
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

std::string CommLog::to_string(LogFormat format) const {
  std::ostringstream out;
  if (format == LogFormat::csv) out << "utc_us,direction,note,hex\n";
  for (const auto& e : entries()) {
    switch (format) {
      case LogFormat::txt:
        out << e.utc_us << ' ' << leka::to_string(e.direction) << ' ' << e.note << " ["
            << hex(e.raw) << "]\n";
        break;
      case LogFormat::csv:
        out << e.utc_us << ',' << leka::to_string(e.direction) << ',' << csv_field(e.note) << ','
            << hex(e.raw) << '\n';
        break;
      case LogFormat::ndjson:
        out << "{\"utc_us\":" << e.utc_us << ",\"direction\":\"" << leka::to_string(e.direction)
            << "\",\"note\":" << json_string(e.note) << ",\"hex\":\"" << hex(e.raw) << "\"}\n";
        break;
    }
  }
  return out.str();
}

bool CommLog::save(const std::string& path, LogFormat format) const {
  std::ofstream file(path, std::ios::binary);
  if (!file) return false;
  file << to_string(format);
  return static_cast<bool>(file);
}

}  // namespace hil::client::leka
