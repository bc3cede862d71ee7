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

}  // namespace hil::harness
