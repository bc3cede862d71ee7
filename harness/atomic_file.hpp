#pragma once
// Writes a file (a report, JUnit XML, hil mock's list of ports) so that a
// reader (CI, a person, a script, a crash) sees either the old file or the
// whole new one, never a half-written one.

#include <string>
#include <string_view>

namespace hil::harness {

/// Writes `bytes` to a temporary file in `path`'s folder, flushes it to the
/// disk (fsync), then renames it over `path` (and fsyncs the folder so the
/// rename survives a power cut). Throws std::runtime_error naming the path
/// and the reason when any step fails; the temporary file is removed then
/// and `path` is left as it was.
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace hil::harness
