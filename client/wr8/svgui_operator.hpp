#pragma once
// The operator's words for the real smart_vehicle_gui programs' dialects
// (forward 30, wheels -10, control 0.2 0.5, set steering-p=1.5, ...): parsing
// a line or a script of profile svgui-2019 or svgui-head into typed actions,
// and a runner that carries them out on an SvguiSession under either driver
// (docs/clients/wr8-client.md). The shared words (connect, disconnect, wait,
// wait-data) are the document vocabulary's.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "client/wr8/operator.hpp"
#include "client/wr8/svgui_session.hpp"
#include "link/executor.hpp"

namespace hil::client::wr8 {

namespace op {
/// v2019 TASK 1: drive forward.
struct Forward {
  std::int32_t distance_cm = 0;
  friend bool operator==(const Forward&, const Forward&) = default;
};
/// v2019 TASK 2: turn the wheels.
struct Wheels {
  std::int32_t angle_deg = 0;
  friend bool operator==(const Wheels&, const Wheels&) = default;
};
/// v2019 TASK 3: flash the turn signals.
struct Signals {
  friend bool operator==(const Signals&, const Signals&) = default;
};
/// v2019 SETTINGS: p, i, d and servo zero, all four (the packet has no
/// room for fewer).
struct Settings2019 {
  std::array<std::int32_t, 4> values{};
  friend bool operator==(const Settings2019&, const Settings2019&) = default;
};
/// head CONTROL held from now on: x steering, y engine, each -1..1.
struct Control {
  double x_axis = 0;
  double y_axis = 0;
  friend bool operator==(const Control&, const Control&) = default;
};
/// head: CONTROL 0 0 once, and no more repetition.
struct ControlOff {
  friend bool operator==(const ControlOff&, const ControlOff&) = default;
};
/// head SET: the named values (index into svgui::kSetNames); the rest come
/// from the vehicle's last read-back.
struct Set {
  std::vector<std::pair<std::size_t, double>> values;
  friend bool operator==(const Set&, const Set&) = default;
};
/// head SET-REQUEST: read the settings back.
struct SetRequest {
  friend bool operator==(const SetRequest&, const SetRequest&) = default;
};
}  // namespace op

using SvguiAction = std::variant<op::Connect, op::Disconnect, op::Wait, op::WaitData, op::Forward,
                                 op::Wheels, op::Signals, op::Settings2019, op::Control,
                                 op::ControlOff, op::Set, op::SetRequest>;

/// The words `version`'s profile takes, for help and errors.
std::string_view svgui_vocabulary(svgui::Version version);

/// The action as a line the parser reads back ("forward 30", "control 0.5 -1").
std::string to_text(const SvguiAction& action);

using ParsedSvguiLine = client::ParseResult<SvguiAction>;

/// Parses one line of `version`'s vocabulary. Never throws on input. A word
/// of another profile is an error naming the profile.
ParsedSvguiLine parse_svgui_line(std::string_view line, svgui::Version version);

struct SvguiScriptStep {
  int line = 0;
  SvguiAction action;
};

struct SvguiScript {
  std::vector<SvguiScriptStep> steps;
  std::vector<client::ScriptError> errors;  ///< every bad line, in order
};

SvguiScript parse_svgui_script(std::string_view text, std::string file, svgui::Version version);

using SvguiActionResult = BasicActionResult<SvguiAction>;

/// "steering-p=1.5 steering-i=0 ..." for the twelve values of a SET.
std::string format_set(const svgui::Set& set);

/// Carries out actions one at a time on an SvguiSession. The session's
/// event sink must pass every event to `on_event`. The request an action
/// waits for is kept with its kind and task, and its COI (0 in head).
class SvguiRunner final
    : public ActionRunner<SvguiRunner, SvguiSession, SvguiAction, std::optional<RequestEvent>> {
 public:
  SvguiRunner(link::Executor& executor, SvguiSession& session, RunnerOptions options = {})
      : ActionRunner(executor, session, options) {}

  /// Feed every session event here (from the session's sink).
  void on_event(Time now, const SvguiEvent& event);

  /// Starts `action`; `done` is called once when it ends (maybe at once).
  /// Programmer error (std::logic_error) while another action runs.
  void execute(SvguiAction action, Done done);

 private:
  void start_request(SubmitResult submitted, RequestKind kind, proto::TaskCode task);
  void start_set(const op::Set& set);
  void on_request(const RequestEvent& r);
};

}  // namespace hil::client::wr8
