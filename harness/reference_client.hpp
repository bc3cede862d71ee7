#pragma once
// The built-in reference client of each car as a scenario drives it: the
// car's session on an endpoint, its events written to the timeline as
// client records, and operator actions carried out one at a time through
// the car's operator runner. Uses only the executor and transports of the
// context it is given, so the same object serves virtual and real time.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "client/arduino/core.hpp"
#include "client/logi/core.hpp"
#include "client/wr8/core.hpp"
#include "harness/reference_settings.hpp"
#include "harness/scenario_client.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"
#include "mocks/car.hpp"

namespace hil::harness {

/// The car's reference client on `endpoint`, writing client records to
/// `timeline`, its library's defaults changed by `settings` (names to values
/// that reference_setting_problem() accepts; a bad one is a programmer
/// error and throws std::invalid_argument), speaking the car's profile
/// `profile` (empty: the default; an unknown one throws
/// protocol::ProfileError). `context` and `timeline` must outlive it.
std::unique_ptr<ScenarioClient> make_reference_client(
    mocks::CarKind car, link::TransportContext& context, link::Endpoint endpoint,
    RunTimeline& timeline, const nlohmann::json& settings = nlohmann::json::object(),
    std::string_view profile = {});

/// hil's LOGI reference client as make_reference_client() makes it, on
/// `core`, which may be of a class derived from client::logi::LogiClientCore
/// (a test's, with a rule broken on purpose).
std::unique_ptr<ScenarioClient> make_logi_reference_client(
    link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
    std::unique_ptr<client::logi::LogiClientCore> core);

/// hil's WR8 reference client as make_reference_client() makes it for the
/// default (`document`) profile, on `core`, which may be of a class derived
/// from client::wr8::Wr8ClientCore (a test's, with a rule broken on
/// purpose); `core`'s config carries the settings.
std::unique_ptr<ScenarioClient> make_wr8_reference_client(
    link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
    std::unique_ptr<client::wr8::Wr8ClientCore> core);

/// hil's Arduino reference client as make_reference_client() makes it, on
/// `core`, which may be of a class derived from
/// client::arduino::ArduinoClientCore (a test's, with a rule broken on
/// purpose); `core`'s config carries the settings and the dialect.
std::unique_ptr<ScenarioClient> make_arduino_reference_client(
    link::TransportContext& context, link::Endpoint endpoint, RunTimeline& timeline,
    std::unique_ptr<client::arduino::ArduinoClientCore> core);

}  // namespace hil::harness
