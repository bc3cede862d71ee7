#include "link/faults/profile_yaml.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

namespace hil::link {
namespace {

using namespace std::chrono_literals;
using testing::HasSubstr;

/// The message of the config::ConfigError the text raises ("" if none).
std::string error_of(const std::string& yaml) {
  try {
    parse_fault_profile_text(yaml, "faults.yaml");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(FaultProfileYaml, ReadsEveryKindWithItsKeys) {
  const auto p = parse_fault_profile_text(R"(
description: every kind once
rules:
  - kind: fragment
    name: small pieces
    sizes: [1, 4]
    gap: [0ms, 5ms]
  - kind: coalesce
    count: 3
    window: 200ms
  - kind: corrupt
    target: checksum
    direction: to_client
    probability: 0.1
  - kind: corrupt
    field: value
    at_frame: 4
  - kind: drop
    match: "FB:ST"
    first: 1
  - kind: drop
    unit: bytes
    count: [1, 3]
    every: 10
  - kind: duplicate
    copies: 2
    from: 1s
    to: 2.5s
  - kind: garbage
    hex: "DE AD"
  - kind: delay
    delay: 100ms
    jitter: 20ms
  - kind: stall
    at: 3s
    for: 500ms
  - kind: bandwidth
    baud: 9600
  - kind: disconnect
    at: 10s
  - kind: reset
    at_frame: 50
  - kind: refuse
    at: 0s
    for: 2s
)",
                                          "faults.yaml");
  ASSERT_EQ(p.rules.size(), 14U);
  const auto& frag = std::get<Fragment>(p.rules[0].action);
  EXPECT_EQ(p.rules[0].name, "small pieces");
  EXPECT_EQ(frag.piece_bytes, (ByteCountRange{1, 4}));
  EXPECT_EQ(frag.gap, (DurationRange{0ms, 5ms}));
  EXPECT_EQ(std::get<Coalesce>(p.rules[1].action).count, 3U);
  EXPECT_EQ(std::get<Coalesce>(p.rules[1].action).window, Duration{200ms});
  EXPECT_EQ(std::get<Corrupt>(p.rules[2].action).target, CorruptTarget::checksum);
  EXPECT_EQ(p.rules[2].direction, DirectionFilter::to_client);
  EXPECT_EQ(p.rules[2].trigger.probability, 0.1);
  EXPECT_EQ(std::get<Corrupt>(p.rules[3].action).target, CorruptTarget::field);
  EXPECT_EQ(std::get<Corrupt>(p.rules[3].action).field, "value");
  EXPECT_EQ(p.rules[3].trigger.at_frame, 4U);
  EXPECT_EQ(p.rules[4].trigger.match, "FB:ST");
  EXPECT_EQ(p.rules[4].trigger.first, 1U);
  EXPECT_EQ(std::get<Drop>(p.rules[5].action).unit, DropUnit::bytes);
  EXPECT_EQ(std::get<Drop>(p.rules[5].action).count, (ByteCountRange{1, 3}));
  EXPECT_EQ(p.rules[5].trigger.every, 10U);
  EXPECT_EQ(std::get<Duplicate>(p.rules[6].action).copies, 2U);
  EXPECT_EQ(p.rules[6].window.from, Time{1s});
  EXPECT_EQ(p.rules[6].window.to, Time{2500ms});
  EXPECT_EQ(std::get<Garbage>(p.rules[7].action).fixed, (protocol::Bytes{0xDE, 0xAD}));
  EXPECT_EQ(std::get<Delay>(p.rules[8].action).base, Duration{100ms});
  EXPECT_EQ(std::get<Delay>(p.rules[8].action).jitter, Duration{20ms});
  EXPECT_EQ(std::get<Stall>(p.rules[9].action).duration, Duration{500ms});
  EXPECT_EQ(p.rules[9].trigger.at, Time{3s});
  EXPECT_EQ(std::get<Bandwidth>(p.rules[10].action).bytes_per_second, 960U);
  EXPECT_EQ(p.rules[11].kind(), FaultKind::disconnect);
  EXPECT_EQ(p.rules[12].kind(), FaultKind::reset);
  EXPECT_EQ(std::get<Refuse>(p.rules[13].action).duration, Duration{2s});
  EXPECT_NO_THROW(validate(p));
}

TEST(FaultProfileYaml, AListOfRulesOrNothingIsAProfileToo) {
  EXPECT_EQ(parse_fault_profile_text("- kind: drop\n", "x.yaml").rules.size(), 1U);
  EXPECT_TRUE(parse_fault_profile_text("rules: []\n", "x.yaml").rules.empty());
  EXPECT_TRUE(parse_fault_profile_text("", "x.yaml").rules.empty());
}

TEST(FaultProfileYaml, EmbeddedInAScenarioNode) {
  const YAML::Node scenario =
      YAML::Load("name: lost feedback\nfaults:\n  rules:\n    - kind: drop\n      first: 1\n");
  const auto p = parse_fault_profile(scenario["faults"], "scenario.yaml");
  ASSERT_EQ(p.rules.size(), 1U);
  EXPECT_EQ(p.rules[0].trigger.first, 1U);
}

// Found by the fault_profile fuzz target: a map without 'rules' escaped as
// YAML::InvalidNode instead of a config::ConfigError, and loading rewrote the
// node it was given.
TEST(FaultProfileYaml, AMapWithoutRulesIsRefusedAndTheNodeIsLeftAlone) {
  EXPECT_EQ(error_of("description: only words\n"),
            "faults.yaml:1:1: a fault profile needs 'rules: [...]'");
  YAML::Node scenario = YAML::Load("faults:\n  rules:\n    - kind: drop\n");
  YAML::Node faults = scenario["faults"];
  ASSERT_EQ(parse_fault_profile(faults, "scenario.yaml").rules.size(), 1U);
  EXPECT_TRUE(faults.IsMap());
  EXPECT_TRUE(scenario["faults"]["rules"].IsSequence());
}

TEST(FaultProfileYaml, ErrorsNameFileLineColumnAndWhatWasExpected) {
  EXPECT_EQ(error_of("rules:\n  - kind: drop\n  - kind: fragment\n    sizes: [5, 2]\n"),
            "faults.yaml:4:12: rule 2 (fragment): 'sizes' must be [min, max] with 1 <= min <= max, "
            "or one "
            "number");
  EXPECT_EQ(error_of("rules:\n  - kind: delay\n    delay: 100\n"),
            "faults.yaml:3:12: rule 1 (delay): 'delay' must be a duration with a unit, like 250ms "
            "or 1.5s "
            "(units: ns, us, ms, s)");
}

TEST(FaultProfileYaml, UnknownKeysAreErrorsSoTyposCannotDisableAFault) {
  const auto e = error_of("rules:\n  - kind: drop\n    frist: 1\n");
  EXPECT_THAT(e, testing::StartsWith("faults.yaml:3:5: rule 1 (drop): unknown key 'frist'"));
  EXPECT_THAT(e, HasSubstr("first"));
  EXPECT_THAT(error_of("rule:\n  - kind: drop\n"),
              testing::StartsWith("faults.yaml:1:1: unknown key 'rule'"));
  EXPECT_THAT(error_of("- kind: bandwidth\n  baud: 9600\n  first: 3\n"),
              testing::StartsWith("faults.yaml:3:3: rule 1 (bandwidth): unknown key 'first'"));
}

TEST(FaultProfileYaml, EachProblemIsReported) {
  /// A mistaken profile and a part of the error it must raise.
  struct Case {
    std::string yaml;
    std::string error_part;
  };
  const std::vector<Case> cases = {
      {"- kind: dorp\n", "1:9: rule 1: unknown kind 'dorp'"},
      {"- drop\n", "rule 1: must be a map"},
      {"- name: x\n", "'kind' is missing"},
      {"- kind: drop\n  probability: 1.5\n", "2:16: rule 1 (drop): 'probability' must be"},
      {"- kind: drop\n  direction: up\n", "'direction' must be to_car, to_client or both"},
      {"- kind: drop\n  first: 0\n", "'first' must be a whole number >= 1"},
      {"- kind: drop\n  count: 3\n", "'count' goes with 'unit: bytes'"},
      {"- kind: stall\n  for: 1s\n", "needs 'at' or a frame trigger"},
      {"- kind: stall\n  at: 1s\n", "'for' is missing"},
      {"- kind: coalesce\n", "needs 'count' (frames) or 'window' (time)"},
      {"- kind: coalesce\n  count: 1\n", "'count' must be a whole number >= 2"},
      {"- kind: corrupt\n  target: field\n", "target 'field' needs 'field: NAME'"},
      {"- kind: garbage\n  hex: zz\n", "'hex' must be bytes in hex"},
      {"- kind: delay\n  jitter: 5ms\n", "'delay' is missing"},
      {"- kind: drop\n  at: 1s\n", "unknown key 'at'"},
      {"- kind: drop\n  from: 2s\n  to: 1s\n", "'to' must be after 'from'"},
      {"- kind: drop\n  first: 1\n  first: 2\n", "given twice"},
      {"- kind: [drop\n", "not valid YAML"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.yaml);
    EXPECT_THAT(error_of(c.yaml), HasSubstr(c.error_part));
  }
}

TEST(FaultProfileYaml, LimitDataAndSlowCloseTakeTheirKeysAndNoTriggers) {
  const auto p = parse_fault_profile_text(R"(
- kind: limit_data
  direction: to_client
  bytes: 1024
  from: 1s
- kind: slow_close
  delay: 1.5s
)",
                                          "faults.yaml");
  ASSERT_EQ(p.rules.size(), 2U);
  EXPECT_EQ(p.rules[0].kind(), FaultKind::limit_data);
  EXPECT_EQ(std::get<LimitData>(p.rules[0].action).bytes, 1024U);
  EXPECT_EQ(p.rules[0].direction, DirectionFilter::to_client);
  EXPECT_EQ(p.rules[0].window.from, Time{1s});
  EXPECT_EQ(std::get<SlowClose>(p.rules[1].action).delay, Duration{1500ms});

  const std::vector<std::pair<std::string, std::string>> cases = {
      {"- kind: limit_data\n", "1:3: rule 1 (limit_data): 'bytes' is missing"},
      {"- kind: limit_data\n  bytes: 0\n",
       "2:10: rule 1 (limit_data): 'bytes' must be a whole number >= 1"},
      {"- kind: limit_data\n  bytes: 10\n  first: 1\n", "unknown key 'first'"},
      {"- kind: slow_close\n", "'delay' is missing"},
      {"- kind: slow_close\n  delay: 500\n",
       "2:10: rule 1 (slow_close): 'delay' must be a duration"},
      {"- kind: slow_close\n  delay: 1s\n  at: 2s\n", "unknown key 'at'"},
  };
  for (const auto& [yaml, part] : cases) {
    SCOPED_TRACE(yaml);
    EXPECT_THAT(error_of(yaml), HasSubstr(part));
  }
}

TEST(FaultProfileYaml, OneRuleAndTheKeysOfAKind) {
  const auto rule = parse_fault_rule(YAML::Load("{kind: drop, first: 2}"), "api");
  EXPECT_EQ(rule.kind(), FaultKind::drop);
  EXPECT_EQ(rule.trigger.first, 2U);
  EXPECT_THROW(parse_fault_rule(YAML::Load("{kind: drop, frist: 2}"), "api"), config::ConfigError);
  EXPECT_EQ(rule_keys(FaultKind::limit_data),
            (std::vector<std::string>{"bytes", "direction", "from", "kind", "name", "to"}));
}

TEST(FaultProfileYaml, MissingFileSaysSo) {
  try {
    load_fault_profile("/nonexistent/faults.yaml");
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "/nonexistent/faults.yaml: cannot read the file: No such file or directory");
    EXPECT_EQ(e.line(), 0);
  }
}

TEST(FaultProfileYaml, ForDirectionKeepsTheRulesForItAndNamesThemStably) {
  const auto p = parse_fault_profile_text(R"(
- kind: drop
  direction: to_car
- kind: delay
  delay: 1ms
- kind: duplicate
  name: dup
  direction: to_client
)",
                                          "x.yaml");
  const auto car = for_direction(p, Direction::to_car);
  const auto client = for_direction(p, Direction::to_client);
  ASSERT_EQ(car.rules.size(), 2U);
  EXPECT_EQ(car.rules[0].name, "#1");
  EXPECT_EQ(car.rules[1].name, "#2");
  ASSERT_EQ(client.rules.size(), 2U);
  EXPECT_EQ(client.rules[0].name, "#2");
  EXPECT_EQ(client.rules[1].name, "dup");
}

TEST(FaultProfileYaml, EveryExampleProfileLoads) {
  const std::filesystem::path dir = std::filesystem::path(HIL_SOURCE_DIR) / "scenarios" / "faults";
  std::size_t loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    FaultProfile p;
    EXPECT_NO_THROW(p = load_fault_profile(entry.path().string()));
    EXPECT_FALSE(p.rules.empty());
    ++loaded;
  }
  EXPECT_GE(loaded, 5U);
}

}  // namespace
}  // namespace hil::link
