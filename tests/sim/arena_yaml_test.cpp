#include "sim/arena_yaml.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>

namespace hil::sim {
namespace {

using testing::HasSubstr;
using testing::StartsWith;

const std::filesystem::path kWorlds = std::filesystem::path(HIL_SOURCE_DIR) / "scenarios/worlds";

/// The first field where the two arenas differ, "" when none does. Angles may
/// differ by 1e-12 rad (they pass through degrees); everything else is exact.
std::string difference(const Arena& a, const Arena& b) {
  std::ostringstream out;
  out.precision(17);
  auto same = [&](const std::string& field, const auto& x, const auto& y) {
    if (x == y) return true;
    out << field << ": " << x << " vs " << y;
    return false;
  };
  auto same_angle = [&](const std::string& field, double x, double y) {
    if (std::abs(x - y) <= 1e-12) return true;
    out << field << ": " << x << " vs " << y;
    return false;
  };
  auto same_point = [&](const std::string& field, Vec2 x, Vec2 y) {
    return same(field + ".x", x.x_m, y.x_m) && same(field + ".y", x.y_m, y.y_m);
  };
  if (!same("name", a.name, b.name) || !same("width", a.width_m, b.width_m) ||
      !same("height", a.height_m, b.height_m) || !same("walls", a.walls, b.walls) ||
      !same("wall_thickness", a.wall_thickness_m, b.wall_thickness_m) ||
      !same("start.x", a.start.x_m, b.start.x_m) || !same("start.y", a.start.y_m, b.start.y_m) ||
      !same_angle("start.heading", a.start.heading_rad, b.start.heading_rad) ||
      !same("obstacle count", a.obstacles.size(), b.obstacles.size()) ||
      !same("tape count", a.tapes.size(), b.tapes.size()) ||
      !same("tag count", a.tags.size(), b.tags.size())) {
    return out.str();
  }
  for (std::size_t i = 0; i < a.obstacles.size(); ++i) {
    const std::string at = "obstacles[" + std::to_string(i) + "]";
    if (!same(at + ".kind", a.obstacles[i].index(), b.obstacles[i].index())) return out.str();
    if (const auto* x = std::get_if<BoxObstacle>(&a.obstacles[i])) {
      const auto& y = std::get<BoxObstacle>(b.obstacles[i]);
      if (!same(at + ".name", x->name, y.name) || !same_point(at, x->center_m, y.center_m) ||
          !same(at + ".width", x->width_m, y.width_m) ||
          !same(at + ".height", x->height_m, y.height_m) ||
          !same_angle(at + ".angle", x->angle_rad, y.angle_rad)) {
        return out.str();
      }
    } else {
      const auto& x2 = std::get<CircleObstacle>(a.obstacles[i]);
      const auto& y = std::get<CircleObstacle>(b.obstacles[i]);
      if (!same(at + ".name", x2.name, y.name) || !same_point(at, x2.center_m, y.center_m) ||
          !same(at + ".radius", x2.radius_m, y.radius_m)) {
        return out.str();
      }
    }
  }
  for (std::size_t i = 0; i < a.tapes.size(); ++i) {
    const std::string at = "tapes[" + std::to_string(i) + "]";
    const Tape& x = a.tapes[i];
    const Tape& y = b.tapes[i];
    if (!same(at + ".name", x.name, y.name) || !same(at + ".width", x.width_m, y.width_m) ||
        !same(at + ".closed", x.closed, y.closed) ||
        !same(at + ".point count", x.points_m.size(), y.points_m.size())) {
      return out.str();
    }
    for (std::size_t k = 0; k < x.points_m.size(); ++k) {
      if (!same_point(at + ".points[" + std::to_string(k) + "]", x.points_m[k], y.points_m[k]))
        return out.str();
    }
  }
  for (std::size_t i = 0; i < a.tags.size(); ++i) {
    const std::string at = "tags[" + std::to_string(i) + "]";
    const RfidTag& x = a.tags[i];
    const RfidTag& y = b.tags[i];
    if (!same(at + ".id", x.id, y.id) || !same_point(at, x.position_m, y.position_m) ||
        !same(at + ".radius", x.radius_m, y.radius_m)) {
      return out.str();
    }
  }
  return "";
}

struct Failure {
  std::string what;
  int line = -1;
  int column = -1;
};

/// The config::ConfigError that reading `yaml` as "lab.yaml" raises.
Failure failure_of(const std::string& yaml) {
  try {
    parse_arena_text(yaml, "lab.yaml");
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.file(), "lab.yaml");
    return {e.what(), e.line(), e.column()};
  }
  ADD_FAILURE() << "no error for:\n" << yaml;
  return {};
}

/// Reading `yaml` fails at `line`:`column` with a message that contains `text`.
void expect_failure(const std::string& yaml, int line, int column, const std::string& text) {
  const Failure f = failure_of(yaml);
  EXPECT_EQ(f.line, line) << f.what;
  EXPECT_EQ(f.column, column) << f.what;
  EXPECT_THAT(f.what, HasSubstr(text));
}

/// A world text with one mistake: a part of the message reading it gives,
/// and where that points.
struct Mistake {
  std::string message_part;
  int line;
  int column;
  std::string yaml;
};

/// expect_failure for each mistake, each traced by its text.
void expect_failures(const std::vector<Mistake>& mistakes) {
  for (const auto& m : mistakes) {
    SCOPED_TRACE(m.yaml);
    expect_failure(m.yaml, m.line, m.column, m.message_part);
  }
}

// A valid arena for the error tests to add one mistake to. Lines 1-2.
const std::string kBase =
    "size_m: [4, 3]\n"
    "start: {x_m: 1, y_m: 1}\n";

std::vector<std::filesystem::path> world_files() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(kWorlds)) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// --- The example worlds ---------------------------------------------------

TEST(ArenaYaml, WarehouseFileIsTheBuiltInArena) {
  const Arena file = load_arena((kWorlds / "warehouse.yaml").string());
  EXPECT_EQ(difference(file, default_warehouse_arena()), "");
}

TEST(ArenaYaml, EveryExampleWorldLoadsAndIsSound) {
  const auto files = world_files();
  ASSERT_GE(files.size(), 3u);
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const Arena arena = load_arena(path.string());
    EXPECT_EQ(validate(arena), std::vector<std::string>{});
    EXPECT_FALSE(arena.tapes.empty());
    EXPECT_FALSE(arena.tags.empty());
    // Every station is on a tape, where a line-following car can reach it.
    for (const auto& tag : arena.tags)
      EXPECT_TRUE(arena.on_tape(tag.position_m)) << tag.id;
    EXPECT_TRUE(arena.on_tape(arena.start.position()));
  }
}

TEST(ArenaYaml, CorridorHasTheParcelOnTheTapeBetweenTheStations) {
  const Arena arena = load_arena((kWorlds / "corridor.yaml").string());
  ASSERT_EQ(arena.obstacles.size(), 1u);
  const auto& parcel = std::get<BoxObstacle>(arena.obstacles[0]);
  EXPECT_TRUE(arena.on_tape(parcel.center_m));
  ASSERT_EQ(arena.tags.size(), 2u);
  EXPECT_EQ(arena.tags[0].id, "001");
  EXPECT_EQ(arena.tags[1].id, "002");
  EXPECT_LT(arena.tags[0].position_m.x_m, parcel.center_m.x_m);
  EXPECT_GT(arena.tags[1].position_m.x_m, parcel.center_m.x_m);
}

TEST(ArenaYaml, BuiltInArenaRoundTrips) {
  const Arena arena = default_warehouse_arena();
  EXPECT_EQ(difference(parse_arena_text(to_yaml(arena), "out.yaml"), arena), "");
}

TEST(ArenaYaml, EveryExampleWorldRoundTrips) {
  for (const auto& path : world_files()) {
    SCOPED_TRACE(path.string());
    const Arena arena = load_arena(path.string());
    const std::string text = to_yaml(arena);
    EXPECT_EQ(difference(parse_arena_text(text, "out.yaml"), arena), "") << text;
  }
}

RC_GTEST_PROP(ArenaYaml, AnySoundArenaRoundTrips, ()) {
  // Sizes and positions from integer ratios, so most have no short decimal
  // form and need every digit written out.
  auto metres = [](int max_units) {
    return *rc::gen::inRange(1, max_units + 1) / static_cast<double>(*rc::gen::inRange(1, 1000));
  };
  auto within = [](double extent) { return extent * (*rc::gen::inRange(0, 1'000'001) / 1e6); };
  auto degrees = [] { return *rc::gen::inRange(-720'000, 720'001) / 997.0; };
  auto text = [] { return *rc::gen::container<std::string>(rc::gen::inRange<char>(1, 127)); };
  Arena arena;
  arena.name = text();
  arena.width_m = std::min(1000.0, metres(100'000));
  arena.height_m = std::min(1000.0, metres(100'000));
  arena.walls = *rc::gen::arbitrary<bool>();
  arena.wall_thickness_m = metres(1000);
  arena.start = {within(arena.width_m), within(arena.height_m), deg_to_rad(degrees())};
  const int obstacles = *rc::gen::inRange(0, 4);
  for (int i = 0; i < obstacles; ++i) {
    const Vec2 centre{within(arena.width_m), within(arena.height_m)};
    if (*rc::gen::arbitrary<bool>()) {
      arena.obstacles.push_back(
          BoxObstacle{text(), centre, metres(5000), metres(5000), deg_to_rad(degrees())});
    } else {
      arena.obstacles.push_back(CircleObstacle{text(), centre, metres(5000)});
    }
  }
  const int tapes = *rc::gen::inRange(0, 3);
  for (int i = 0; i < tapes; ++i) {
    Tape tape;
    tape.name = text();
    tape.width_m = metres(100);
    tape.closed = *rc::gen::arbitrary<bool>();
    const int points = *rc::gen::inRange(3, 12);
    for (int k = 0; k < points; ++k)
      tape.points_m.push_back({within(arena.width_m), within(arena.height_m)});
    arena.tapes.push_back(std::move(tape));
  }
  const int tags = *rc::gen::inRange(0, 4);
  for (int i = 0; i < tags; ++i) {
    // Digits only, leading zeros kept: the ids YAML would read as numbers.
    const std::string id = std::to_string(i) +
                           std::string(*rc::gen::inRange<std::size_t>(0, 3), '0') +
                           std::to_string(*rc::gen::inRange(0, 1000));
    arena.tags.push_back(RfidTag{id, {within(arena.width_m), within(arena.height_m)}, metres(500)});
  }
  RC_PRE(validate(arena).empty());
  const std::string yaml = to_yaml(arena);
  RC_LOG() << yaml;
  RC_ASSERT(difference(parse_arena_text(yaml, "out.yaml"), arena) == "");
}

// --- Reading ---------------------------------------------------------------

TEST(ArenaYaml, ReadsEveryKeyWithUnitsAndDefaults) {
  const Arena arena = parse_arena_text(
      "size_m: [5.5, 2.25]\n"
      "walls: false\n"
      "wall_thickness_m: 0.1\n"
      "start: {x_m: 1.5, y_m: 0.5, heading_deg: 90}\n"
      "obstacles:\n"
      "  - box: {name: crate, x_m: 2, y_m: 1, width_m: 0.4, height_m: 0.2, angle_deg: -45}\n"
      "  - box: {x_m: 3, y_m: 1, width_m: 0.5, height_m: 0.5}\n"
      "  - circle: {name: pillar, x_m: 4, y_m: 2, radius_m: 0.1}\n"
      "tapes:\n"
      "  - points_m: [[0.5, 0.5], [5, 0.5]]\n"
      "  - name: ring\n"
      "    width_m: 0.05\n"
      "    closed: true\n"
      "    points_m: [[1, 1], [2, 1], [2, 2]]\n"
      "tags:\n"
      "  - {id: A7, x_m: 1, y_m: 0.5}\n"
      "  - {id: \"002\", x_m: 2, y_m: 0.5, radius_m: 0.08}\n",
      "worlds/lab.yaml");
  EXPECT_EQ(arena.name, "lab");  // the file's stem when the file names none
  EXPECT_EQ(arena.width_m, 5.5);
  EXPECT_EQ(arena.height_m, 2.25);
  EXPECT_FALSE(arena.walls);
  EXPECT_EQ(arena.wall_thickness_m, 0.1);
  EXPECT_EQ(arena.start.position(), (Vec2{1.5, 0.5}));
  EXPECT_NEAR(arena.start.heading_rad, std::numbers::pi / 2, 1e-15);
  ASSERT_EQ(arena.obstacles.size(), 3u);
  const auto& crate = std::get<BoxObstacle>(arena.obstacles[0]);
  EXPECT_EQ(crate.name, "crate");
  EXPECT_EQ(crate.center_m, (Vec2{2, 1}));
  EXPECT_EQ(crate.width_m, 0.4);
  EXPECT_EQ(crate.height_m, 0.2);
  EXPECT_NEAR(crate.angle_rad, -std::numbers::pi / 4, 1e-15);
  EXPECT_EQ(std::get<BoxObstacle>(arena.obstacles[1]).name, "");
  EXPECT_EQ(std::get<BoxObstacle>(arena.obstacles[1]).angle_rad, 0.0);
  const auto& pillar = std::get<CircleObstacle>(arena.obstacles[2]);
  EXPECT_EQ(pillar.name, "pillar");
  EXPECT_EQ(pillar.radius_m, 0.1);
  ASSERT_EQ(arena.tapes.size(), 2u);
  EXPECT_EQ(arena.tapes[0].name, "");
  EXPECT_EQ(arena.tapes[0].width_m, 0.03);
  EXPECT_FALSE(arena.tapes[0].closed);
  EXPECT_EQ(arena.tapes[1].width_m, 0.05);
  EXPECT_TRUE(arena.tapes[1].closed);
  EXPECT_EQ(arena.tapes[1].points_m.size(), 3u);
  ASSERT_EQ(arena.tags.size(), 2u);
  EXPECT_EQ(arena.tags[0].id, "A7");
  EXPECT_EQ(arena.tags[0].radius_m, 0.05);
  EXPECT_EQ(arena.tags[1].id, "002");
  EXPECT_EQ(arena.tags[1].radius_m, 0.08);
}

TEST(ArenaYaml, WallsAndHeadingDefaultWhenLeftOut) {
  const Arena arena = parse_arena_text(kBase, "lab.yaml");
  EXPECT_TRUE(arena.walls);
  EXPECT_EQ(arena.wall_thickness_m, 0.05);
  EXPECT_EQ(arena.start.heading_rad, 0.0);
  EXPECT_TRUE(arena.obstacles.empty());
  EXPECT_TRUE(arena.tapes.empty());
  EXPECT_TRUE(arena.tags.empty());
}

TEST(ArenaYaml, UnquotedTagIdKeepsItsLeadingZeros) {
  const Arena arena = parse_arena_text(kBase +
                                           "tags:\n"
                                           "  - {id: 001, x_m: 1, y_m: 1}\n"
                                           "  - id: 0010\n"
                                           "    x_m: 2\n"
                                           "    y_m: 1\n",
                                       "lab.yaml");
  ASSERT_EQ(arena.tags.size(), 2u);
  EXPECT_EQ(arena.tags[0].id, "001");
  EXPECT_EQ(arena.tags[1].id, "0010");
}

TEST(ArenaYaml, EmbeddedNodeReadsLikeAFile) {
  const YAML::Node scenario = YAML::Load("world:\n  size_m: [2, 2]\n  start: {x_m: 1, y_m: 9}\n");
  try {
    parse_arena(scenario["world"], "scenario.yaml");
    FAIL() << "start outside the arena was accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 3);  // positions count in the whole scenario file
    EXPECT_EQ(e.column(), 10);
    EXPECT_THAT(e.what(), StartsWith("scenario.yaml:3:10: start: "));
  }
}

// --- Errors: one test per kind of mistake, each at the offending node -----

TEST(ArenaYamlErrors, FileThatCannotBeRead) {
  const std::string path = (kWorlds / "no-such-world.yaml").string();
  try {
    load_arena(path);
    FAIL() << "a missing file loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(std::string(e.what()), path + ": cannot read the file: No such file or directory");
  }
  try {
    load_arena(kWorlds.string());
    FAIL() << "a directory loaded";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_THAT(e.what(), HasSubstr("directory"));
  }
}

TEST(ArenaYamlErrors, YamlSyntaxErrorHasTheParsersPosition) {
  Failure f = failure_of(kBase + "walls: true: false\n");
  EXPECT_EQ(f.line, 3);
  EXPECT_EQ(f.column, 12);
  EXPECT_THAT(f.what, StartsWith("lab.yaml:3:12: not valid YAML: "));

  // An unclosed bracket is found where the text ends.
  f = failure_of(kBase + "tags:\n  - {id: 001, x_m: 1, y_m: 1\n");
  EXPECT_EQ(f.line, 5);
  EXPECT_EQ(f.column, 1);
  EXPECT_THAT(f.what, StartsWith("lab.yaml:5:1: not valid YAML: "));
}

TEST(ArenaYamlErrors, TopLevelMustBeAMap) {
  expect_failure("- size_m: [4, 3]\n", 1, 1,
                 "arena: expected a map with keys name, obstacles, size_m");
  Failure f = failure_of("- size_m: [4, 3]\n");
  EXPECT_THAT(f.what, HasSubstr("got a list of 1"));

  f = failure_of("just text\n");
  EXPECT_EQ(f.line, 1);
  EXPECT_THAT(f.what, HasSubstr("got 'just text'"));

  // Nothing at all has no position to show.
  f = failure_of("# only a comment\n");
  EXPECT_EQ(f.line, 0);
  EXPECT_EQ(f.what,
            "lab.yaml: arena: expected a map with keys name, obstacles, size_m, start, "
            "tags, tapes, wall_thickness_m, walls, got nothing");
}

TEST(ArenaYamlErrors, UnknownKeysAreNamedWithTheAllowedOnes) {
  expect_failures({
      {"wall: unknown key 'wall' (allowed: name, obstacles, size_m, "
       "start, tags, tapes, wall_thickness_m, walls)",
       3, 1, kBase + "wall: false\n"},
      {"obstacles[1].circle.raduis_m: unknown key 'raduis_m' (allowed: "
       "name, radius_m, x_m, y_m)",
       5, 30,
       kBase + "obstacles:\n"
               "  - circle: {x_m: 1, y_m: 1, radius_m: 0.1}\n"
               "  - circle: {x_m: 1, y_m: 1, raduis_m: 0.1}\n"},
      {"tapes[0].colour: unknown key 'colour' (allowed: closed, name, "
       "points_m, width_m)",
       5, 5, kBase + "tapes:\n  - points_m: [[1, 1], [2, 1]]\n    colour: red\n"},
      {"start.heading_rad: unknown key 'heading_rad' (allowed: "
       "heading_deg, x_m, y_m)",
       2, 25, "size_m: [4, 3]\nstart: {x_m: 1, y_m: 1, heading_rad: 1}\n"},
  });
}

TEST(ArenaYamlErrors, KeyGivenTwice) {
  expect_failure(kBase + "walls: true\nwalls: false\n", 4, 1, "walls: key 'walls' is given twice");
}

TEST(ArenaYamlErrors, MissingRequiredKeysAreReportedAtTheirMap) {
  expect_failure("name: lab\nstart: {x_m: 1, y_m: 1}\n", 1, 1,
                 "size_m: missing; expected [width, height] in metres");

  Failure f = failure_of("size_m: [4, 3]\n");
  EXPECT_THAT(f.what, HasSubstr("start: missing"));

  expect_failure("size_m: [4, 3]\nstart: {y_m: 1}\n", 2, 8,
                 "start.x_m: missing; expected a number of metres");

  expect_failure(kBase + "tags:\n  - {x_m: 1, y_m: 1}\n", 4, 5, "tags[0].id: missing");

  expect_failure(kBase + "tapes:\n  - name: loop\n", 4, 5, "tapes[0].points_m: missing");
}

TEST(ArenaYamlErrors, WrongTypes) {
  // A list where a number belongs.
  expect_failure("size_m: [4, 3]\nstart: {x_m: [1], y_m: 1}\n", 2, 14,
                 "start.x_m: expected a number of metres, got a list of 1");

  // Text that is not a number, NaN and infinity.
  for (const char* value :
       {"one", ".nan", ".inf", "-.inf", "inf", "nan", "1e999", "1.5.2", "0x10"}) {
    SCOPED_TRACE(value);
    Failure f = failure_of("size_m: [4, 3]\nstart: {x_m: 1, y_m: " + std::string(value) + "}\n");
    EXPECT_EQ(f.line, 2);
    EXPECT_EQ(f.column, 22);
    EXPECT_THAT(f.what, HasSubstr("start.y_m: expected a number of metres, got '" +
                                  std::string(value) + "'"));
  }

  expect_failures({
      {"walls: expected true or false, got 'yes'", 3, 8, kBase + "walls: yes\n"},
      {"obstacles: expected a list, got a map", 4, 3,
       kBase + "obstacles:\n  box: {x_m: 1, y_m: 1, width_m: 1, height_m: 1}\n"},
      {"tags[0].id: expected the tag's id as text", 4, 10,
       kBase + "tags:\n  - {id: [1], x_m: 1, y_m: 1}\n"},
      {"size_m: expected [width, height] in metres, got '4'", 1, 9,
       "size_m: 4\nstart: {x_m: 1, y_m: 1}\n"},
      {"start: expected a map with keys heading_deg, x_m, y_m, got '1'", 2, 8,
       "size_m: [4, 3]\nstart: 1\n"},
  });
}

TEST(ArenaYamlErrors, SizesMustBePositive) {
  // Block style over several lines: the position is where -0.2 starts.
  const Failure f = failure_of(kBase +
                               "obstacles:\n"
                               "  - circle: {x_m: 1, y_m: 1, radius_m: 0.2}\n"
                               "  - circle:\n"
                               "      name: pillar\n"
                               "      x_m: 1\n"
                               "      y_m: 1\n"
                               "\n"
                               "\n"
                               "\n"
                               "      radius_m: -0.2\n");
  EXPECT_EQ(f.what,
            "lab.yaml:12:17: obstacles[1].circle.radius_m: expected a positive number of metres, "
            "got '-0.2'");
  EXPECT_EQ(f.line, 12);
  EXPECT_EQ(f.column, 17);

  expect_failures({
      {"size_m[1]: expected a positive", 1, 13, "size_m: [4, 0]\nstart: {x_m: 0, y_m: 0}\n"},
      {"size_m[0]: expected a positive", 1, 10, "size_m: [-4, 3]\nstart: {x_m: 0, y_m: 0}\n"},
      {"wall_thickness_m: expected a number of metres >= 0", 3, 19,
       kBase + "wall_thickness_m: -0.1\n"},
      {"obstacles[0].box.width_m: expected a positive", 4, 36,
       kBase + "obstacles:\n  - box: {x_m: 1, y_m: 1, width_m: 0, height_m: 1}\n"},
      {"obstacles[0].box.height_m: expected a positive", 4, 49,
       kBase + "obstacles:\n  - box: {x_m: 1, y_m: 1, width_m: 1, height_m: -1}\n"},
      {"tapes[0].width_m: expected a positive", 5, 14,
       kBase + "tapes:\n  - points_m: [[1, 1], [2, 1]]\n    width_m: 0\n"},
      {"tags[0].radius_m: expected a positive", 4, 39,
       kBase + "tags:\n  - {id: A, x_m: 1, y_m: 1, radius_m: 0}\n"},
  });
}

TEST(ArenaYamlErrors, ObstacleIsExactlyOneOfBoxOrCircle) {
  expect_failures({
      {"obstacles[0]: expected exactly one of 'box' or 'circle', got both", 4, 5,
       kBase + "obstacles:\n"
               "  - box: {x_m: 1, y_m: 1, width_m: 1, height_m: 1}\n"
               "    circle: {x_m: 1, y_m: 1, radius_m: 1}\n"},
      {"obstacles[0]: expected exactly one of 'box' or 'circle', got neither", 4, 5,
       kBase + "obstacles:\n  - {}\n"},
      {"obstacles[0].cylinder: unknown key 'cylinder' (allowed: box, circle)", 4, 5,
       kBase + "obstacles:\n  - cylinder: {x_m: 1, y_m: 1}\n"},
      {"obstacles[0]: expected a map with keys box, circle, got 'circle'", 4, 5,
       kBase + "obstacles:\n  - circle\n"},
  });
}

TEST(ArenaYamlErrors, TapePointsMustBePairs) {
  expect_failures({
      {"tapes[0].points_m[1]: expected an [x, y] pair of metres, got a list of 3", 4, 24,
       kBase + "tapes:\n  - points_m: [[1, 1], [2, 1, 0], [3, 1]]\n"},
      {"tapes[0].points_m[1]: expected an [x, y] pair of metres, got '2'", 4, 24,
       kBase + "tapes:\n  - points_m: [[1, 1], 2]\n"},
      {"tapes[0].points_m[1][1]: expected a number of metres, got 'y'", 4, 28,
       kBase + "tapes:\n  - points_m: [[1, 1], [2, y]]\n"},
      {"tapes[0].points_m: expected a list of [x, y] points", 4, 15,
       kBase + "tapes:\n  - points_m: {x: 1}\n"},
  });
}

// The checks of validate() run after reading and point at the part they name.
TEST(ArenaYamlErrors, PointOutsideTheArena) {
  expect_failure(kBase +
                     "tapes:\n"
                     "  - name: loop\n"
                     "    points_m:\n"
                     "      - [1, 1]\n"
                     "      - [4.5, 1]\n",
                 7, 9, "tapes[0].points_m[1]: lies outside the arena");
}

TEST(ArenaYamlErrors, TooFewTapePoints) {
  expect_failures({
      {"tapes[0].points_m: needs at least 2 points", 4, 15,
       kBase + "tapes:\n  - points_m: [[1, 1]]\n"},
      {"tapes[0].points_m: a closed tape needs 3 points", 5, 15,
       kBase + "tapes:\n  - closed: true\n    points_m: [[1, 1], [2, 2]]\n"},
  });
}

TEST(ArenaYamlErrors, DuplicateTagIdAtTheSecondId) {
  expect_failure(kBase +
                     "tags:\n"
                     "  - {id: 001, x_m: 1, y_m: 1}\n"
                     "  - {id: \"002\", x_m: 2, y_m: 1}\n"
                     "  - {id: \"001\", x_m: 3, y_m: 1}\n",
                 6, 10, "tags[2].id: id '001' is used twice");
}

TEST(ArenaYamlErrors, EmptyTagId) {
  expect_failure(kBase + "tags:\n  - {id: '', x_m: 1, y_m: 1}\n", 4, 10,
                 "tags[0].id: id must not be empty");
}

TEST(ArenaYamlErrors, TagOutsideTheArena) {
  expect_failure(kBase + "tags:\n  - {id: A, x_m: 1, y_m: -0.5}\n", 4, 5,
                 "tags[0]: lies outside the arena");
}

TEST(ArenaYamlErrors, ObstacleCentreOutsideTheArena) {
  expect_failure(kBase +
                     "obstacles:\n  - circle: {x_m: 1, y_m: 1, radius_m: 0.1}\n"
                     "  - box: {x_m: 5, y_m: 1, width_m: 1, height_m: 1}\n",
                 5, 10, "obstacles[1].box: centre lies outside the arena");
}

TEST(ArenaYamlErrors, StartOutsideTheArena) {
  const Failure f = failure_of("size_m: [4, 3]\nstart:\n  x_m: 1\n  y_m: 3.5\n");
  EXPECT_EQ(f.line, 3);
  EXPECT_EQ(f.column, 3);
  EXPECT_EQ(f.what, "lab.yaml:3:3: start: lies outside the arena");
}

TEST(ArenaYamlErrors, ArenaTooLarge) {
  expect_failure("size_m: [4, 1001]\nstart: {x_m: 1, y_m: 1}\n", 1, 9,
                 "size_m: at most 1000 m a side");
}

TEST(ArenaYamlErrors, ZeroWallThicknessOnlyWithoutWalls) {
  EXPECT_NO_THROW(parse_arena_text(kBase + "walls: false\nwall_thickness_m: 0\n", "lab.yaml"));
  expect_failure(kBase + "walls: true\nwall_thickness_m: 0\n", 4, 19,
                 "wall_thickness_m: must be positive");
}

TEST(ArenaYamlErrors, HostileInputsFailCleanly) {
  // Deep nesting, a self-referencing alias, and a huge number each end in
  // an config::ConfigError, never a crash or a hang.
  EXPECT_THAT(failure_of(std::string(100'000, '[') + std::string(100'000, ']')).what,
              HasSubstr("not valid YAML"));
  EXPECT_THAT(failure_of("&a [*a]\n").what, HasSubstr("expected a map"));
  EXPECT_THAT(failure_of("size_m: &a [*a, 1]\nstart: {x_m: 1, y_m: 1}\n").what,
              HasSubstr("size_m[0]: expected a positive number of metres, got a list of 2"));
  const Failure f = failure_of("size_m: [4, " + std::string(10'000, '9') + "]\n");
  EXPECT_THAT(f.what, HasSubstr("size_m[1]: expected a positive number of metres, got '999"));
  EXPECT_LT(f.what.size(), 200u);  // the value is shortened in the message
}

}  // namespace
}  // namespace hil::sim
