#pragma once
// A client's communication log written to a file, its format chosen by the
// file name's extension (client::log_format_for).

#include <string>
#include <string_view>

#include "client/common/comm_log.hpp"

namespace hil::apps {

/// Whether the name ends in .txt, .csv or .ndjson, the extensions a
/// program that checks --log before it starts accepts.
bool has_log_extension(std::string_view path);

/// The log in the format of the path's extension; false if it cannot be written.
template <class Entry, std::size_t MaxEntries>
bool save_log(const client::EntryLog<Entry, MaxEntries>& log, const std::string& path) {
  return log.save(path, client::log_format_for(path));
}

}  // namespace hil::apps
