#include "client/common/comm_log.hpp"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace hil::client {

std::string_view to_string(LogKind kind) {
  switch (kind) {
    case LogKind::tx:
      return "TX";
    case LogKind::rx:
      return "RX";
    case LogKind::parse_error:
      return "ERR";
    case LogKind::note:
      return "NOTE";
  }
  return "?";
}

void CommLog::add(LogEntry entry) {
  std::lock_guard lock(mutex_);
  entries_.push_back(std::move(entry));
  if (entries_.size() > max_entries_) {
    // Drop a tenth at once so a full log does not shift on every frame.
    const std::size_t n = std::max<std::size_t>(1, max_entries_ / 10);
    entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(n));
    dropped_ += n;
  }
}

std::vector<LogEntry> CommLog::snapshot() const {
  std::lock_guard lock(mutex_);
  return entries_;
}

std::vector<LogEntry> CommLog::since(std::uint64_t from) const {
  std::lock_guard lock(mutex_);
  const std::uint64_t first = from > dropped_ ? from - dropped_ : 0;
  if (first >= entries_.size()) return {};
  return {entries_.begin() + static_cast<std::ptrdiff_t>(first), entries_.end()};
}

std::uint64_t CommLog::total() const {
  std::lock_guard lock(mutex_);
  return dropped_ + entries_.size();
}

void CommLog::clear() {
  std::lock_guard lock(mutex_);
  dropped_ += entries_.size();
  entries_.clear();
}

namespace {

std::string time_ms(link::Time at) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", link::to_ms(at));
  return buf;
}

std::string csv_field(std::string_view s) {
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

std::string CommLog::export_text() const {
  std::string out;
  for (const auto& e : snapshot()) {
    char head[48];
    std::snprintf(head, sizeof head, "%12.3f ms %-4s ", link::to_ms(e.at),
                  std::string(to_string(e.kind)).c_str());
    out += head;
    out += printable(e.raw);
    if (!e.raw.empty() && !e.description.empty()) out += "  ";
    out += e.description;
    out += '\n';
  }
  return out;
}

std::string CommLog::export_csv() const {
  std::string out = "time_ms,kind,raw,description\r\n";
  for (const auto& e : snapshot()) {
    out += time_ms(e.at) + "," + std::string(to_string(e.kind)) + "," +
           csv_field(printable(e.raw)) + "," + csv_field(e.description) + "\r\n";
  }
  return out;
}

std::string CommLog::export_ndjson() const {
  std::string out;
  for (const auto& e : snapshot()) {
    nlohmann::json j;
    j["time_ms"] = link::to_ms(e.at);
    j["kind"] = std::string(to_string(e.kind));
    j["raw"] = printable(e.raw);
    j["description"] = printable(e.description);
    out += j.dump() + "\n";
  }
  return out;
}

}  // namespace hil::client
