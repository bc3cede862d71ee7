// Routes files: the example shipped in scenarios/proxy, and every mistake
// reported at its line and column.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config/error.hpp"
#include "control/routes_config.hpp"
#include "link/faults/profile_yaml.hpp"

namespace hil::control {
namespace {

using ::testing::HasSubstr;

std::filesystem::path source_root() {
#ifdef HIL_SOURCE_DIR
  return HIL_SOURCE_DIR;
#else
  // tests/control/routes_config_test.cpp, two folders below the root.
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path();
#endif
}

// The ConfigError the text raises.
config::ConfigError routes_error(const std::string& yaml) {
  try {
    parse_routes_text(yaml, "routes.yaml");
  } catch (const config::ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << yaml;
  return config::ConfigError("", 0, 0, "");
}

TEST(RoutesFile, TheExampleLoadsWithItsFaultsAndToxics) {
  const auto path = source_root() / "scenarios" / "proxy" / "routes-example.yaml";
  const auto routes = load_routes_file(path.string());
  ASSERT_EQ(routes.size(), 2u);

  const auto& logi = routes[0];
  EXPECT_EQ(logi.name, "logi-car");
  EXPECT_EQ(logi.protocol, "logi");
  EXPECT_EQ(logi.listen, "127.0.0.1:9001");
  EXPECT_EQ(logi.upstream, "tcp://127.0.0.1:9000");
  EXPECT_TRUE(logi.enabled);
  EXPECT_EQ(logi.faults,
            link::load_fault_profile(
                (source_root() / "scenarios" / "faults" / "sticky-packets.yaml").string()));
  ASSERT_EQ(logi.toxics.size(), 1u);
  EXPECT_EQ(logi.toxics[0].type, "latency");
  EXPECT_EQ(logi.toxics[0].stream, link::Direction::to_client);
  EXPECT_EQ(logi.toxics[0].attributes["latency"], 100);
  EXPECT_EQ(logi.toxics[0].attributes["jitter"], 10);

  const auto& board = routes[1];
  EXPECT_EQ(board.name, "arduino-board");
  EXPECT_EQ(board.profile, "firmware");
  EXPECT_FALSE(board.enabled);
  ASSERT_EQ(board.faults.rules.size(), 1u);
  EXPECT_EQ(board.faults.rules[0].kind(), link::FaultKind::delay);
  ASSERT_EQ(board.toxics.size(), 1u);
  EXPECT_EQ(board.toxics[0].name, "bad-checksums");
  EXPECT_EQ(board.toxics[0].type, "corrupt");
  EXPECT_DOUBLE_EQ(board.toxics[0].toxicity, 0.5);
}

TEST(RoutesFile, InlineRulesMayBeABareList) {
  const auto routes = parse_routes_text(R"(routes:
  - name: car
    upstream: 127.0.0.1:9000
    faults:
      - {kind: drop, match: STAT}
)",
                                        "routes.yaml");
  ASSERT_EQ(routes.size(), 1u);
  EXPECT_EQ(routes[0].protocol, "raw");
  EXPECT_EQ(routes[0].listen, "");
  EXPECT_EQ(routes[0].faults.rules.size(), 1u);
}

TEST(RoutesFile, EachMistakeIsReportedAtItsLine) {
  struct Case {
    std::string yaml;
    int line;
    int column;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"route:\n  - name: car\n", 1, 1, "unknown key 'route'"},
      {"routes:\n  - name: car\n    upstrem: 127.0.0.1:9000\n", 3, 5, "did you mean 'upstream'?"},
      {"routes:\n  - name: car\n    listen: 127.0.0.1:1\n", 2, 5, "'upstream' is missing"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    listen: nope://x\n", 4, 13,
       "listen: "},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    protocol: logo\n", 4, 15,
       "unknown protocol 'logo'"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    protocol: logi\n"
       "    profile: nightly\n",
       5, 14, "profile: "},
      {"routes:\n  - name: car\n    upstream: rfc2217://127.0.0.1:4000\n", 3, 15, "RFC 2217"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    enabled: maybe\n", 4, 14,
       "true or false"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n  - name: car\n"
       "    upstream: 127.0.0.1:9001\n",
       4, 11, "taken by an earlier route"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    faults: no-such.yaml\n", 4, 13,
       "no fault profile at"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    faults:\n"
       "      - {kind: dorp}\n",
       5, 16, "dorp"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    toxics:\n"
       "      - {type: latency, attributes: {latency: -5}}\n",
       5, 47, "toxic 1: attributes.latency"},
      {"routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    toxics:\n"
       "      - type: latency\n      - type: latency\n",
       6, 9, "taken by toxic 1"},
      {"routes: [1, 2\n", 2, 0, "not valid YAML"},
  };
  for (const auto& c : cases) {
    const auto e = routes_error(c.yaml);
    EXPECT_EQ(e.file(), "routes.yaml");
    EXPECT_EQ(e.line(), c.line) << c.yaml << e.what();
    if (c.column != 0) EXPECT_EQ(e.column(), c.column) << c.yaml << e.what();
    EXPECT_THAT(e.what(), HasSubstr(c.says)) << c.yaml;
  }
}

TEST(RoutesFile, AFaultProfilePathIsReadRelativeToTheRoutesFile) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("hil-routes-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "faults");
  std::ofstream(dir / "faults" / "drop.yaml") << "rules:\n  - kind: drop\n    match: MV\n";
  std::ofstream(dir / "routes.yaml")
      << "routes:\n  - name: car\n    upstream: 127.0.0.1:9000\n    faults: faults/drop.yaml\n";
  const auto routes = load_routes_file((dir / "routes.yaml").string());
  ASSERT_EQ(routes.size(), 1u);
  ASSERT_EQ(routes[0].faults.rules.size(), 1u);
  EXPECT_EQ(routes[0].faults.rules[0].trigger.match, "MV");

  // A mistake in the profile is reported in the profile's file.
  std::ofstream(dir / "faults" / "drop.yaml") << "rules:\n  - kind: drop\n    mtch: MV\n";
  try {
    load_routes_file((dir / "routes.yaml").string());
    ADD_FAILURE() << "no error";
  } catch (const config::ConfigError& e) {
    EXPECT_THAT(e.file(), HasSubstr("drop.yaml"));
    EXPECT_EQ(e.line(), 3);
  }
  EXPECT_THROW(load_routes_file((dir / "missing.yaml").string()), config::ConfigError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hil::control
