// hil encode arduino / hil decode arduino.

#include "apps/hil/cli_common.hpp"

namespace hil::apps {

void register_arduino(CommandSet& /*commands*/) {}

}  // namespace hil::apps
