#include "apps/common/log_file.hpp"

#include <fstream>

namespace hil::apps {

LogFileFormat log_format_of(std::string_view path) {
  if (path.ends_with(".csv")) return LogFileFormat::csv;
  if (path.ends_with(".ndjson") || path.ends_with(".jsonl") || path.ends_with(".json"))
    return LogFileFormat::ndjson;
  return LogFileFormat::text;
}

bool has_log_extension(std::string_view path) {
  return path.ends_with(".txt") || path.ends_with(".csv") || path.ends_with(".ndjson");
}

std::string export_log(const client::CommLog& log, LogFileFormat format) {
  switch (format) {
    case LogFileFormat::csv:
      return log.export_csv();
    case LogFileFormat::ndjson:
      return log.export_ndjson();
    case LogFileFormat::text:
      break;
  }
  return log.export_text();
}

bool write_text_file(const std::string& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  return out && out.write(text.data(), static_cast<std::streamsize>(text.size())) && out.flush();
}

bool save_log(const client::CommLog& log, const std::string& path) {
  return write_text_file(path, export_log(log, log_format_of(path)));
}

namespace {
// Both car-specific log classes spell the formats alike.
template <class Log, class Format>
bool save_own_log(const Log& log, const std::string& path) {
  switch (log_format_of(path)) {
    case LogFileFormat::csv:
      return log.save(path, Format::csv);
    case LogFileFormat::ndjson:
      return log.save(path, Format::ndjson);
    case LogFileFormat::text:
      break;
  }
  return log.save(path, Format::txt);
}
}  // namespace

bool save_log(const client::arduino::CommLog& log, const std::string& path) {
  return save_own_log<client::arduino::CommLog, client::arduino::LogFormat>(log, path);
}

bool save_log(const client::leka::CommLog& log, const std::string& path) {
  return save_own_log<client::leka::CommLog, client::leka::LogFormat>(log, path);
}

}  // namespace hil::apps
