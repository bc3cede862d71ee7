// leka-client: the Leka robot's command line. The work is in app.cpp.

#include "apps/leka-client/app.hpp"

int main(int argc, char** argv) {
  const auto parsed = hil::apps::leka_client::parse_arguments(argc, argv);
  if (!parsed.options) return parsed.exit_code;
  return hil::apps::leka_client::run(*parsed.options);
}
