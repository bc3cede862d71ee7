#pragma once
// A client's communication log written to a file, its format chosen by the
// file name's extension. The LOGI and WR8 clients share one log class; the
// Arduino and Leka clients each have their own.

#include <cstdint>
#include <string>
#include <string_view>

#include "client/arduino/comm_log.hpp"
#include "client/common/comm_log.hpp"
#include "client/leka/comm_log.hpp"

namespace hil::apps {

enum class LogFileFormat : std::uint8_t { text, csv, ndjson };

/// .csv: CSV; .ndjson, .jsonl or .json: one JSON object a line; else text.
LogFileFormat log_format_of(std::string_view path);

/// Whether the name ends in .txt, .csv or .ndjson, the extensions a
/// program that checks --log before it starts accepts.
bool has_log_extension(std::string_view path);

std::string export_log(const client::CommLog& log, LogFileFormat format);

/// Writes `text` to `path` (replacing it); false if it cannot.
bool write_text_file(const std::string& path, std::string_view text);

/// The log in the format of the path's extension; false if it cannot be written.
bool save_log(const client::CommLog& log, const std::string& path);
bool save_log(const client::arduino::CommLog& log, const std::string& path);
bool save_log(const client::leka::CommLog& log, const std::string& path);

}  // namespace hil::apps
