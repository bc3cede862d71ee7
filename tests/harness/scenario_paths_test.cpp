// Files a scenario names stay inside its root (the parent of its folder)
// unless hil run --allow-outside-paths: ../ escapes, absolute paths and
// symlinks that lead out are refused where they are written.

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "harness/scenario_yaml.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;

// A scenario library in a scratch folder:
//   <tmp>/outside.yaml            a fault profile outside the library
//   <tmp>/lib/faults/drop.yaml    a fault profile in the library
//   <tmp>/lib/logi/               where the scenarios are
//   <tmp>/lib/logi/out.yaml       a symlink to ../../outside.yaml
//   <tmp>/lib/logi/in.yaml        a symlink to ../faults/drop.yaml
class Library : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(tmp_ / "lib" / "faults");
    fs::create_directories(tmp_ / "lib" / "logi");
    write(tmp_ / "outside.yaml", kProfile);
    write(tmp_ / "lib" / "faults" / "drop.yaml", kProfile);
    fs::create_symlink("../../outside.yaml", tmp_ / "lib" / "logi" / "out.yaml");
    fs::create_symlink("../faults/drop.yaml", tmp_ / "lib" / "logi" / "in.yaml");
  }
  static void write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

  std::string scenario_file() const { return (tmp_ / "lib" / "logi" / "s.yaml").string(); }

  /// Loads a scenario naming `faults` as its fault profile; the error, or
  /// "" when it loads.
  std::string load(const std::string& faults, bool allow = false) const {
    const std::string yaml = "name: t\ncar: logi\nfaults: " + faults + "\nsteps: [connect]\n";
    try {
      parse_scenario_text(yaml, scenario_file(), {}, LoadOptions{allow});
      return "";
    } catch (const config::ConfigError& e) {
      return e.what();
    }
  }

  std::string root() const { return (tmp_ / "lib").string(); }

  static constexpr const char* kProfile = "rules:\n  - kind: drop\n    first: 1\n";
  test::ScratchDir scratch_{"hil-paths"};
  const fs::path& tmp_ = scratch_.path();
};

TEST_F(Library, TheRootIsTheParentOfTheScenariosFolder) {
  EXPECT_EQ(scenario_root(scenario_file()), root());
  // However the file is named.
  EXPECT_EQ(scenario_root((tmp_ / "lib" / "logi" / ".." / "logi" / "s.yaml").string()), root());
}

TEST_F(Library, FilesInsideTheRootLoad) {
  EXPECT_EQ(load("../faults/drop.yaml"), "");
  EXPECT_EQ(load("{file: ../faults/drop.yaml}"), "");
  EXPECT_EQ(load("in.yaml"), "");  // a symlink that stays inside
}

TEST_F(Library, ADotDotEscapeIsRefusedWithFileLineColumnThePathAndTheFlag) {
  EXPECT_EQ(load("../../outside.yaml"),
            scenario_file() +
                ":3:9: fault profile file '../../outside.yaml' is outside the scenario's root: a "
                "scenario may only name files inside " +
                root() +
                " (its folder's parent); pass --allow-outside-paths to hil run to allow it");
  // Refused by name, before the disk is looked at: a file that does not
  // exist out there is not reported as missing.
  EXPECT_NE(load("../../../nowhere.yaml").find("is outside the scenario's root"),
            std::string::npos);
}

TEST_F(Library, AnAbsolutePathIsRefusedEvenToAFileInside) {
  const std::string inside = (tmp_ / "lib" / "faults" / "drop.yaml").string();
  EXPECT_NE(load(inside).find(":3:9: fault profile file '" + inside + "' is an absolute path"),
            std::string::npos)
      << load(inside);
}

TEST_F(Library, ASymlinkLeadingOutIsRefused) {
  const std::string error = load("out.yaml");
  EXPECT_NE(error.find("fault profile file 'out.yaml' leads outside the scenario's root (to " +
                       fs::weakly_canonical(tmp_ / "outside.yaml").string() + ")"),
            std::string::npos)
      << error;
}

TEST_F(Library, TheFlagAllowsEveryKindOfOutsidePath) {
  EXPECT_EQ(load("../../outside.yaml", true), "");
  EXPECT_EQ(load((tmp_ / "outside.yaml").string(), true), "");
  EXPECT_EQ(load("out.yaml", true), "");
}

TEST_F(Library, WorldFilesFollowTheSameRule) {
  const std::string yaml = "name: t\ncar: logi\nworld: ../../w.yaml\nsteps: [connect]\n";
  try {
    parse_scenario_text(yaml, scenario_file());
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.column(), 8);
    EXPECT_NE(std::string(e.what()).find("world file '../../w.yaml' is outside"),
              std::string::npos);
  }
}

TEST_F(Library, FaultProfilesInStepsFollowTheSameRule) {
  const std::string yaml =
      "name: t\ncar: logi\nsteps:\n  - connect\n  - faults: {file: ../../outside.yaml}\n";
  try {
    parse_scenario_text(yaml, scenario_file());
    FAIL() << "loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 5);
    EXPECT_NE(std::string(e.what()).find("--allow-outside-paths"), std::string::npos);
  }
}

TEST(ScenarioLibrary, EveryShippedScenarioStaysInsideItsRoot) {
  // hil run scenarios/ loads all of them without the flag (the CLI test runs
  // them); here: every file a shipped scenario names is under scenarios/.
  std::size_t loaded = 0;
  for (const auto& entry :
       fs::recursive_directory_iterator(fs::path(HIL_SOURCE_DIR) / "scenarios")) {
    const auto& path = entry.path();
    if (path.extension() != ".yaml") continue;
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.find("\ncar:") == std::string::npos || text.find("\nsteps:") == std::string::npos)
      continue;
    EXPECT_NO_THROW(load_scenario(path.string())) << path;
    ++loaded;
  }
  EXPECT_GT(loaded, 40u);
}

}  // namespace
}  // namespace hil::harness
