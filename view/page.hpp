#pragma once
// The live view's page: one self-contained HTML file (drawing, panel, SSE
// client), served as it is.

#include <string_view>

namespace hil::view {

std::string_view live_view_page();

}  // namespace hil::view
