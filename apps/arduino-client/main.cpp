// arduino-client: the Arduino robot's command line. The work is in app.cpp.

#include "apps/arduino-client/app.hpp"

int main(int argc, char** argv) {
  const auto parsed = hil::apps::arduino_client::parse_arguments(argc, argv);
  if (!parsed.options) return parsed.exit_code;
  return hil::apps::arduino_client::run(*parsed.options);
}
