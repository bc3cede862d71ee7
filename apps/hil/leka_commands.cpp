// hil encode leka / hil decode leka.

#include "apps/hil/cli_common.hpp"

namespace hil::apps {

void register_leka(CommandSet& /*commands*/) {}

}  // namespace hil::apps
