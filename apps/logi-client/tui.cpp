#include "apps/logi-client/tui.hpp"

#include <cstdio>

namespace hil::apps::logi_client {

int run_tui(const TuiOptions&) {
  std::fputs("logi-client: the terminal UI is not built yet; use --script or actions\n", stderr);
  return 2;
}

}  // namespace hil::apps::logi_client
