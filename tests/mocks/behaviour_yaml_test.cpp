// Scripted behaviours from YAML: every action, and errors that say where.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "mocks/behaviour_yaml.hpp"

namespace hil::mocks {
namespace {

using link::milliseconds;

TEST(BehaviourYaml, ReadsEveryAction) {
  const auto list = parse_behaviours_text(R"(
description: a car that misbehaves on the desk
behaviours:
  - name: refuse moves
    do: reject
    match: MV
    times: 3
    at: 5s
  - do: ignore
    match: ST
    for: 2s
    after: GS
    after_count: 2
  - do: mute-telemetry
    for: 1500ms
  - do: send
    text: "LOGI:FB:SP:1:B9#"
  - do: send
    hex: "2A 2B"
  - do: fault
    at: 10s
  - do: clear-fault
    at: 12s
  - do: close
    mode: reset
)",
                                          "desk.yaml");
  ASSERT_EQ(list.size(), 8u);
  EXPECT_EQ(list[0], (Behaviour{"refuse moves", When{link::Time(link::seconds(5)), "", 1},
                                Reject{"MV", 3}}));
  EXPECT_EQ(list[1], (Behaviour{"", When{std::nullopt, "GS", 2},
                                Ignore{"ST", std::nullopt, link::seconds(2)}}));
  EXPECT_EQ(list[2].action, Action(MuteTelemetry{milliseconds(1500)}));
  const std::string text = "LOGI:FB:SP:1:B9#";
  EXPECT_EQ(list[3].action, Action(SendBytes{protocol::Bytes(text.begin(), text.end())}));
  EXPECT_EQ(list[4].action, Action(SendBytes{{0x2A, 0x2B}}));
  EXPECT_EQ(list[5].action, Action(EnterFault{}));
  EXPECT_EQ(list[6].action, Action(ClearFault{}));
  EXPECT_EQ(list[7].action, Action(CloseConnection{link::CloseMode::reset}));
}

TEST(BehaviourYaml, ABareListAndAnEmptyFileAreAccepted) {
  EXPECT_EQ(parse_behaviours_text("- do: fault\n", "x.yaml").size(), 1u);
  EXPECT_TRUE(parse_behaviours_text("", "x.yaml").empty());
  EXPECT_TRUE(parse_behaviours_text("behaviours: []\n", "x.yaml").empty());
}

void expect_error(const std::string& yaml, const std::string& message) {
  try {
    parse_behaviours_text(yaml, "b.yaml");
    ADD_FAILURE() << "no error for:\n" << yaml;
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

// Found by the behaviour fuzz target: a map without 'behaviours' escaped as
// YAML::InvalidNode instead of a config::ConfigError, and loading rewrote the node
// it was given.
TEST(BehaviourYaml, AMapWithoutBehavioursIsRefusedAndTheNodeIsLeftAlone) {
  expect_error("description: only words\n", "b.yaml:1:1: 'behaviours' is missing");
  YAML::Node scenario = YAML::Load("behaviours:\n  behaviours:\n    - do: fault\n");
  YAML::Node node = scenario["behaviours"];
  ASSERT_EQ(parse_behaviours(node, "scenario.yaml").size(), 1u);
  EXPECT_TRUE(node.IsMap());
  EXPECT_TRUE(scenario["behaviours"]["behaviours"].IsSequence());
}

TEST(BehaviourYaml, ErrorsNameTheFileLineColumnAndWhatWasExpected) {
  expect_error("- do: explode\n",
               "b.yaml:1:7: behaviour 1: unknown action 'explode' (known: clear-fault, close, "
               "fault, ignore, mute-telemetry, reject, send)");
  expect_error("- do: reject\n  times: 0\n",
               "b.yaml:2:10: behaviour 1 (reject): 'times' must be a whole number >= 1");
  expect_error("- do: fault\n  at: 5\n",
               "b.yaml:2:7: behaviour 1 (fault): 'at' must be a duration with a unit, like 250ms "
               "or 1.5s (units: ns, us, ms, s)");
  expect_error("- do: mute-telemetry\n",
               "b.yaml:1:3: behaviour 1 (mute-telemetry): 'for' is missing (how long telemetry "
               "stops, like 3s)");
  expect_error("- do: send\n  text: a\n  hex: 2A\n",
               "b.yaml:1:3: behaviour 1 (send): give one of 'text' or 'hex'");
  expect_error("- do: close\n  mode: slam\n",
               "b.yaml:2:9: behaviour 1 (close): 'mode' must be graceful or reset");
  expect_error("- do: fault\n  times: 2\n",
               "b.yaml:2:3: behaviour 1 (fault): unknown key 'times' (this action takes: after, "
               "after_count, at, do, name)");
  expect_error("- do: fault\n  after_count: 2\n",
               "b.yaml:2:16: behaviour 1 (fault): 'after_count' needs 'after' (a frame kind)");
  expect_error("rules: []\n",
               "b.yaml:1:1: unknown key 'rules' (a behaviours file takes: behaviours, "
               "description)");
  expect_error("behaviours: [\n", "b.yaml:2:1: not valid YAML: end of sequence flow not found");
  expect_error("- 3\n", "b.yaml:1:3: behaviour 1: must be a map with at least 'do'");
}

TEST(BehaviourYaml, EveryShippedBehavioursFileLoads) {
  std::size_t files = 0;
  const std::filesystem::path folder =
      std::filesystem::path(HIL_SOURCE_DIR) / "scenarios" / "behaviours";
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".yaml") continue;
    ++files;
    EXPECT_FALSE(load_behaviours(entry.path().string()).empty()) << entry.path();
  }
  EXPECT_GE(files, 2u);
}

TEST(BehaviourYaml, AMissingFileIsAnError) {
  EXPECT_THROW(load_behaviours("/nonexistent/b.yaml"), config::ConfigError);
}

}  // namespace
}  // namespace hil::mocks
