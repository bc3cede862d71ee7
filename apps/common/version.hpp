#pragma once
// What --version prints, the same in hil and every client program: the
// project's version (project() in CMakeLists.txt) and the commit the
// programs were built from (cmake/hil_version.cmake).

#include <string>
#include <string_view>

namespace hil::apps {

/// The project's version: "0.1.0".
std::string_view project_version();

/// The commit the tree was built from: git describe's name for it
/// ("e3778f5", "e3778f5-dirty"), the cache variable HIL_SOURCE_COMMIT when
/// the build was given one, or "unknown" (a tree built without git).
std::string_view source_commit();

/// The --version line of `program`: "hil 0.1.0 (commit e3778f5)".
std::string version_line(std::string_view program);

}  // namespace hil::apps
