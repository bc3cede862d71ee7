// wr8-client: the WR8 vehicle's command line. The work is in app.cpp and console.cpp.

#include "apps/wr8-client/app.hpp"

int main(int argc, char** argv) {
  const auto parsed = hil::apps::wr8_client::parse_arguments(argc, argv);
  if (!parsed.options) return parsed.exit_code;
  return hil::apps::wr8_client::run(*parsed.options);
}
