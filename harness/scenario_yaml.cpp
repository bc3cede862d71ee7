#include "harness/scenario_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <utility>

#include "base/enum_names.hpp"
#include "harness/emulated_car.hpp"
#include "harness/scenario_parts.hpp"
#include "link/capture/probe_capture.hpp"
#include "mocks/avr/firmware_source.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::harness {

namespace fs = std::filesystem;

namespace scenario_parts {

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return std::string(text.substr(first, last - first + 1));
}

constexpr auto kCarTitles = base::enum_names<mocks::CarKind>(
    {mocks::CarKind::logi, "LOGI"}, {mocks::CarKind::wr8, "WR8"},
    {mocks::CarKind::arduino, "Arduino"}, {mocks::CarKind::leka, "Leka"});

std::string car_title(mocks::CarKind car) {
  return std::string(kCarTitles.name(car, "car"));
}

}  // namespace scenario_parts

namespace {

using namespace scenario_parts;

const Keys kTopKeys = {"name",          "description", "tags",     "car",     "profile",
                       "reply_latency", "world",       "seed",     "timeout", "settle",
                       "at_end",        "variables",   "faults",   "client",  "setup",
                       "steps",         "teardown",    "schedule", "expect"};

const Keys kCarKeys = {"kind", "replay", "unmatched", "firmware"};
const Keys kFirmwareKeys = {"sketch", "elf", "pins", "startup"};

constexpr auto kAtEndNames = base::enum_names<AtEnd>(
    {AtEnd::at_rest, "at_rest"}, {AtEnd::moving, "moving"}, {AtEnd::any, "any"});

/// Reads a scenario file top-down; each part goes to the reader of its
/// concept (harness/scenario_parts.hpp).
class ScenarioReader : public config::Reader {
 public:
  ScenarioReader(std::string file, const std::map<std::string, std::string>& overrides,
                 const LoadOptions& options)
      : config::Reader(file), overrides_(overrides) {
    facts_.file = std::move(file);
    facts_.dir = fs::path(facts_.file).parent_path();
    facts_.allow_outside_paths = options.allow_outside_paths;
  }

  Scenario load(std::string_view text) {
    const YAML::Node root = parse(text);
    if (!root.IsMap()) {
      fail(root.Mark(),
           "a scenario is a map with at least 'name', 'car' and 'steps' (see docs/scenarios.md)");
    }
    check_keys(root, kTopKeys, "the scenario");
    Scenario scenario;
    scenario.file = facts_.file;
    scenario.variables = expand_variables(facts_, root, overrides_);
    read_header(root, scenario);
    if (auto n = root["faults"]) scenario.faults = read_faults(facts_, n, "'faults'");
    if (auto n = root["client"]) scenario.client = read_client(facts_, n);
    collect_all_step_texts(root);
    if (auto n = root["setup"]) scenario.setup = read_steps(facts_, n, "setup", "setup step ");
    const auto main_steps = required(root, "steps", "the scenario");
    scenario.steps = read_steps(facts_, main_steps, "steps", "step ");
    if (auto n = root["teardown"])
      scenario.teardown = read_steps(facts_, n, "teardown", "teardown step ");
    if (auto n = root["schedule"]) scenario.schedule = read_schedule(facts_, n);
    if (auto n = root["expect"]) scenario.expectations = read_expectations(facts_, n);
    if (firmware_source_) {
      check_emulated_board(root, scenario);
      scenario.firmware = resolve_firmware();
    }
    return scenario;
  }

 private:
  /// name, description, tags, car, profile, world, seed and the run's times.
  void read_header(const YAML::Node& root, Scenario& scenario) {
    const auto name = required(root, "name", "the scenario");
    scenario.name = scalar(name, "'name'");
    if (trim(scenario.name).empty()) fail(name, "'name' must not be empty");
    if (auto n = root["description"]) scenario.description = scalar(n, "'description'");
    if (auto n = root["tags"]) {
      if (!n.IsSequence()) fail(n, "'tags' must be a list of words, like [logi, safety]");
      for (const auto& t : n)
        scenario.tags.push_back(scalar(t, "a tag"));
    }
    const auto car_node = required(root, "car", "the scenario");
    // `car: logi`, or `car: {kind: logi, replay: FILE, unmatched: silent}`,
    // or `car: {kind: arduino, firmware: {sketch: FILE}}`.
    if (car_node.IsMap()) check_keys(car_node, kCarKeys, "'car'");
    const auto car = car_node.IsMap() ? required(car_node, "kind", "'car'") : car_node;
    const std::string car_text = scalar(car, "'car'");
    const auto kind = mocks::parse_car_kind(car_text);
    if (!kind) {
      fail(car, "unknown car '" + car_text + "' (expected " + mocks::kCarKindNames.list(" or ") +
                    ")" + config::did_you_mean(car_text, mocks::kCarKindNames.names()));
    }
    scenario.car = facts_.car = *kind;
    if (auto n = root["profile"]) {
      scenario.profile = facts_.profile = scalar(n, "'profile'");
      if (const auto problem = protocol::car_profile_problem(car_text, scenario.profile);
          !problem.empty()) {
        fail(n, "'profile': " + problem);
      }
    }
    if (car_node.IsMap()) {
      read_firmware(car_node, scenario);
      read_replay(root, car_node, scenario);
    }
    if (auto n = root["world"]) scenario.world = read_existing_file(facts_, n, "world file");
    if (auto n = root["seed"]) scenario.seed = whole(n, "'seed'", 0);
    if (auto n = root["timeout"]) {
      scenario.timeout = duration(n, "'timeout'");
      if (scenario.timeout.count() == 0) fail(n, "'timeout' must be more than 0s");
    }
    if (auto n = root["settle"]) scenario.settle = duration(n, "'settle'");
    if (auto n = root["reply_latency"]) scenario.reply_latency = duration(n, "'reply_latency'");
    if (auto n = root["at_end"]) scenario.at_end = at_end(n);
  }

  /// `replay: FILE` and `unmatched:` in a `car:` map: the capture read,
  /// of this car, its profile the scenario's.
  void read_replay(const YAML::Node& root, const YAML::Node& car, Scenario& scenario) {
    const auto file = car["replay"];
    if (!file) {
      if (car["unmatched"]) fail(car["unmatched"], "'unmatched' needs 'replay' in 'car'");
      return;
    }
    mocks::ReplaySpec replay;
    replay.path = read_existing_file(facts_, file, "capture file");
    try {
      replay.capture = std::make_shared<const link::Capture>(link::read_capture(replay.path));
    } catch (const link::CaptureError& e) {
      fail(file, std::string("the capture cannot be read: ") + e.what());
    }
    const auto& header = replay.capture->header;
    const std::string car_text(mocks::to_string(scenario.car));
    if (header.car != car_text) {
      fail(file, "'" + file.Scalar() + "' is a capture of a " + header.car + " car, not of a " +
                     car_text + " car");
    }
    if (const auto problem = protocol::car_profile_problem(header.car, header.profile);
        !problem.empty()) {
      fail(file, "the capture's profile: " + problem);
    }
    const std::string recorded(protocol::find_car_profile(header.car, header.profile).name);
    if (scenario.profile.empty()) {
      scenario.profile = facts_.profile = recorded;
    } else if (protocol::find_car_profile(car_text, scenario.profile).name != recorded) {
      fail(root["profile"], "'profile' " + scenario.profile + " differs from the capture's, " +
                                recorded + " (leave 'profile' out to play the capture)");
    }
    if (auto n = car["unmatched"]) {
      const std::string word = scalar(n, "'unmatched'");
      const auto parsed = mocks::parse_unmatched(word);
      if (!parsed) fail(n, "'unmatched' must be mock or silent, got '" + word + "'");
      replay.unmatched = *parsed;
    }
    scenario.replay = std::move(replay);
  }

  /// `firmware: {sketch: FILE, pins: FILE}` (or `elf:`) in a `car:` map:
  /// the files found; the sketch is built at the end of the load, once the
  /// rest of the file has been checked.
  void read_firmware(const YAML::Node& car, const Scenario& scenario) {
    const auto n = car["firmware"];
    if (!n) return;
    if (scenario.car != mocks::CarKind::arduino) {
      fail(n, "'firmware' runs on the emulated Arduino board, and this scenario's car is " +
                  car_title(scenario.car) + " (docs/firmware.md)");
    }
    if (car["replay"]) {
      fail(n,
           "'firmware' and 'replay' do not go together: the car either runs the firmware or "
           "plays the capture");
    }
    const std::string usage =
        "'firmware' is a map: {sketch: FILE.ino} or {elf: FILE.elf}, with an optional pins: FILE";
    if (!n.IsMap()) fail(n, usage);
    check_keys(n, kFirmwareKeys, "'firmware'");
    const std::string image = one_key(n, {"sketch", "elf"}, [](const auto&, const auto&) {
      return std::string("'firmware' takes 'sketch' or 'elf', not both");
    });
    if (image.empty()) fail(n, usage);
    mocks::avr::FirmwareSource source;
    if (image == "sketch") {
      source.sketch = read_existing_file(facts_, n["sketch"], "sketch");
    } else {
      source.elf = read_existing_file(facts_, n["elf"], "firmware image");
    }
    if (auto pins = n["pins"]) source.pins = read_existing_file(facts_, pins, "pin map file");
    if (auto startup = n["startup"]) {
      source.startup_delay = duration(startup, "'startup'");
      if (*source.startup_delay > std::chrono::seconds(10))
        fail(startup, "'startup' is at most 10s (the time from the port opening to the sketch)");
    }
    firmware_.emplace(n);
    firmware_source_ = std::move(source);
  }

  /// With `firmware:`, what the emulated board cannot do is an error where
  /// the scenario asks for it: a behaviour that changes the firmware's own
  /// answers, or a reply latency.
  void check_emulated_board(const YAML::Node& root, const Scenario& scenario) const {
    const std::string why =
        ", and the firmware (car: firmware:) runs on the emulated board as it is: only send and "
        "close act on it (docs/firmware.md)";
    if (const auto u = first_unplayable_step(scenario)) {
      // At the step's `car:` where the file has it, else at its list.
      const YAML::Node list = root[u->list];
      YAML::Node at = list;
      if (list && list.IsSequence() && u->index < list.size()) {
        const YAML::Node item = list[u->index];
        at = item.IsMap() && item["car"] ? item["car"] : item;
      }
      fail(at ? at : root, u->prefix + std::to_string(u->index + 1) + ": " +
                               behaviour_phrase(*u->action) + " needs the behavioural mock" + why);
    }
    if (auto n = root["reply_latency"]) {
      fail(n,
           "'reply_latency' has no effect on the firmware (car: firmware:): the emulated "
           "board's answers take the chip's own time");
    }
  }

  /// The firmware read by read_firmware(), built and checked.
  mocks::AvrConfig resolve_firmware() const {
    const mocks::avr::FirmwareSource& source = *firmware_source_;
    const YAML::Node& firmware = *firmware_;
    const YAML::Node image = firmware[source.sketch.empty() ? "elf" : "sketch"];
    try {
      return mocks::avr::resolve_firmware(source);
    } catch (const mocks::avr::SketchBuildError& e) {
      fail(image, source.sketch.empty() ? std::string("the firmware image: ") + e.what()
                                        : std::string("the sketch does not build: ") + e.what());
    } catch (const config::ConfigError& e) {
      // A pin map file's own error is at its own line; one without a
      // position (a file that cannot be read) is at `pins:`.
      if (e.line() > 0) throw;
      fail(firmware["pins"] ? firmware["pins"] : image, "the pin map: " + e.message());
    } catch (const std::invalid_argument& e) {
      fail(image, std::string("the firmware cannot run on the emulated board: ") + e.what());
    }
  }

  /// `at_end: moving`: how the car must be once the client has stopped.
  AtEnd at_end(const YAML::Node& n) const {
    const std::string word = scalar(n, "'at_end'");
    if (const auto parsed = kAtEndNames.parse(word)) return *parsed;
    fail(n, "'at_end' must be " + kAtEndNames.list(" or ") + ", got '" + word + "'" +
                config::did_you_mean(word, kAtEndNames.names()));
  }

  /// Step texts first: step matchers anywhere refer to them.
  void collect_all_step_texts(const YAML::Node& root) {
    collect_step_texts(facts_, root["setup"]);
    collect_step_texts(facts_, root["steps"]);
    collect_step_texts(facts_, root["teardown"]);
    if (auto n = root["schedule"]; n && n.IsSequence()) {
      for (const auto& item : n) {
        if (!item.IsMap()) continue;
        for (const auto& key : kStepKeys) {
          if (item[key]) facts_.step_texts.push_back(step_text(item, key));
        }
      }
    }
  }

  std::map<std::string, std::string> overrides_;
  ScenarioFacts facts_;
  std::optional<YAML::Node> firmware_;  // the `firmware:` map, when the car has one
  std::optional<mocks::avr::FirmwareSource> firmware_source_;
};

}  // namespace

std::string scenario_root(const std::string& scenario_file) {
  return fs::absolute(fs::path(scenario_file))
      .lexically_normal()
      .parent_path()
      .parent_path()
      .string();
}

Scenario parse_scenario_text(std::string_view yaml, const std::string& file_name,
                             const std::map<std::string, std::string>& overrides,
                             const LoadOptions& options) {
  return ScenarioReader(file_name, overrides, options).load(yaml);
}

Scenario load_scenario(const std::string& path, const std::map<std::string, std::string>& overrides,
                       const LoadOptions& options) {
  return parse_scenario_text(config::read_file(path, "scenario file"), path, overrides, options);
}

}  // namespace hil::harness
