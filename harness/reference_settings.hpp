#pragma once
// The settings a scenario may give a car's reference client
// (`client: {reference: {settings: {max_retries: 0}}}`): their names and
// what they take, checked when the file loads, and the client configs
// they make, each option checked by the client library's own rules.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "client/arduino/core.hpp"
#include "client/leka/core.hpp"
#include "client/logi/core.hpp"
#include "client/wr8/core.hpp"
#include "client/wr8/svgui_core.hpp"
#include "mocks/car.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::harness {

/// One option of a car's reference client that a scenario may set
/// (`client: {reference: {settings: {max_retries: 0}}}`).
struct ReferenceSetting {
  std::string name;   ///< "max_retries"
  std::string takes;  ///< what a value looks like: "a duration (800ms)"
  std::string what;   ///< what it changes, for people
};

/// The options the car's reference client takes in profile `profile`
/// (empty: the default), in a fixed order.
std::vector<ReferenceSetting> reference_settings(mocks::CarKind car, std::string_view profile = {});

/// Why `value` (a text, or an array of texts for a list) cannot be the
/// option `name` of the car's reference client in `profile`; nullopt when
/// it can.
std::optional<std::string> reference_setting_problem(mocks::CarKind car, const std::string& name,
                                                     const nlohmann::json& value,
                                                     std::string_view profile = {});

/// The real-program WR8 version (svgui-2019, svgui-head) a car's client
/// speaks in `profile`; nullopt for every other car and profile.
std::optional<protocol::wr8::svgui::Version> svgui_version(mocks::CarKind car,
                                                           std::string_view profile);

/// Each client's library defaults with `settings` (names to values that
/// reference_setting_problem() accepts) applied; a bad one is a programmer
/// error and throws std::invalid_argument.
client::logi::ClientConfig logi_client_config(const nlohmann::json& settings);
client::wr8::ClientConfig wr8_client_config(const nlohmann::json& settings);
client::wr8::SvguiConfig svgui_client_config(const nlohmann::json& settings);
/// The Arduino client also speaks the dialect of the car's `profile`
/// (protocol/common/car_profile.hpp; empty: the default).
client::arduino::ClientConfig arduino_client_config(const nlohmann::json& settings,
                                                    std::string_view profile = {});
client::leka::ClientConfig leka_client_config(const nlohmann::json& settings);

}  // namespace hil::harness
