#include "link/time.hpp"

#include <cstdio>

namespace hil::link {

std::string format_ms(Duration d) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3f ms", to_ms(d));
  return buf;
}

std::int64_t wall_time_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace hil::link
