#include "apps/common/log_file.hpp"

namespace hil::apps {

bool has_log_extension(std::string_view path) {
  return path.ends_with(".txt") || path.ends_with(".csv") || path.ends_with(".ndjson");
}

}  // namespace hil::apps
