#pragma once
// Binds the client core of the real smart_vehicle_gui dialects to a hil
// transport (tcp://, pty:// or mem://) under either driver, as Wr8Session
// does for the document's dialect.

#include <array>
#include <cstdint>
#include <memory>

#include "client/common/connecting_session.hpp"
#include "client/wr8/svgui_core.hpp"

namespace hil::client::wr8 {

class SvguiSession : public ConnectingSession<SvguiClientCore, SvguiEvent, OpenConnection,
                                              SendBytes, CloseConnection> {
 public:
  /// `context` must outlive the session. Events go to `sink` on the executor.
  SvguiSession(link::TransportContext& context, link::Endpoint endpoint, SvguiConfig config = {},
               EventSink sink = {}, std::shared_ptr<CommLog> log = std::make_shared<CommLog>())
      : ConnectingSession(context, std::move(endpoint), std::move(sink),
                          SvguiClientCore(std::move(config), std::move(log))) {}

  SubmitResult forward(std::int32_t distance_cm) {
    return feed([&](Time t) { return mutable_core().forward(t, distance_cm); });
  }
  SubmitResult wheels(std::int32_t angle_deg) {
    return feed([&](Time t) { return mutable_core().wheels(t, angle_deg); });
  }
  SubmitResult signals() {
    return feed([&](Time t) { return mutable_core().signals(t); });
  }
  SubmitResult settings(const std::array<std::int32_t, 4>& values) {
    return feed([&](Time t) { return mutable_core().settings(t, values); });
  }
  Refusal control(double x_axis, double y_axis) {
    return feed([&](Time t) { return mutable_core().control(t, x_axis, y_axis); });
  }
  Refusal release_control() {
    return feed([&](Time t) { return mutable_core().release_control(t); });
  }
  SubmitResult set(const svgui::Set& values) {
    return feed([&](Time t) { return mutable_core().set(t, values); });
  }
  SubmitResult set_request() {
    return feed([&](Time t) { return mutable_core().set_request(t); });
  }
};

}  // namespace hil::client::wr8
