#include "apps/common/version.hpp"

#include "hil_source_commit.h"  // generated: HIL_SOURCE_COMMIT

#ifndef HIL_VERSION
#error "HIL_VERSION comes from apps/common/CMakeLists.txt"
#endif

namespace hil::apps {

std::string_view project_version() {
  return HIL_VERSION;
}

std::string_view source_commit() {
  return HIL_SOURCE_COMMIT;
}

std::string version_line(std::string_view program) {
  std::string line(program);
  line += ' ';
  line += project_version();
  line += " (commit ";
  line += source_commit();
  line += ')';
  return line;
}

}  // namespace hil::apps
