// hil encode wr8 / hil decode wr8.

#include "apps/hil/cli_common.hpp"

namespace hil::apps {

void register_wr8(CommandSet& /*commands*/) {}

}  // namespace hil::apps
