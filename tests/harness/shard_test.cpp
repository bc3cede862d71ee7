// hil run --shard K/N: every selected scenario in exactly one shard, the
// shards' expected times near the mean, few files moved when one is added,
// and the same shards whatever the order the files came in.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "harness/scenario_yaml.hpp"
#include "harness/shard.hpp"

namespace hil::harness {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// `count` files of weights 1..20 s, in folders as a library has them.
std::vector<ShardItem> synthetic(std::size_t count, std::uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> weight(1, 20);
  std::vector<ShardItem> items;
  for (std::size_t i = 0; i < count; ++i) {
    const std::string key = (i % 3 == 0   ? "logi/"
                             : i % 3 == 1 ? "wr8/"
                                          : "arduino/") +
                            std::string("scenario-") + std::to_string(i) + ".yaml";
    items.push_back({key, "scenarios/" + key, weight(rng)});
  }
  return items;
}

// Shard number (0-based) of each item's path.
std::map<std::string, std::size_t> assignment(const std::vector<ShardItem>& items, int count) {
  std::map<std::string, std::size_t> out;
  const auto shards = shard_partition(items, count);
  for (std::size_t s = 0; s < shards.size(); ++s)
    for (const auto i : shards[s])
      out[items[i].path] = s;
  return out;
}

double mean_of(const std::vector<ShardItem>& items, int count) {
  double total = 0;
  for (const auto& i : items)
    total += i.weight_s;
  return total / count;
}

double max_load(const std::vector<ShardItem>& items, int count) {
  double worst = 0;
  for (const auto& shard : shard_partition(items, count)) {
    double load = 0;
    for (const auto i : shard)
      load += items[i].weight_s;
    worst = std::max(worst, load);
  }
  return worst;
}

TEST(ParseShard, TakesKOfN) {
  EXPECT_EQ(parse_shard("1/1"), (ShardSpec{1, 1}));
  EXPECT_EQ(parse_shard("3/4"), (ShardSpec{3, 4}));
  EXPECT_EQ(parse_shard("12/40"), (ShardSpec{12, 40}));
}

TEST(ParseShard, RefusesWhatIsNotKOfNAndSaysWhatWasExpected) {
  for (const char* bad : {"", "3", "0/4", "5/4", "1/0", "-1/4", "a/b", "1/4/2", "1 /4", "1/", "/4",
                          "1.5/4", "2/+4"}) {
    std::string error;
    EXPECT_FALSE(parse_shard(bad, &error)) << bad;
    EXPECT_NE(error.find("'" + std::string(bad) + "'"), std::string::npos) << error;
  }
  std::string error;
  parse_shard("5/4", &error);
  EXPECT_EQ(error, "'5/4' names shard 5 of only 4");
  parse_shard("x", &error);
  EXPECT_EQ(error, "'x' is not K/N (shard K of N, 1 <= K <= N, e.g. 2/4)");
}

TEST(ShardKey, IsThePathRelativeToTheFolderNamed) {
  EXPECT_EQ(shard_key("scenarios/logi/a.yaml", {"scenarios/logi"}), "a.yaml");
  EXPECT_EQ(shard_key("scenarios/logi/sub/a.yaml", {"scenarios/logi/"}), "sub/a.yaml");
  EXPECT_EQ(shard_key("scenarios/logi/a.yaml", {"scenarios"}), "logi/a.yaml");
  // Two checkouts in different places agree.
  EXPECT_EQ(shard_key("/home/ci/a/scenarios/logi/a.yaml", {"/home/ci/a/scenarios"}),
            shard_key("/builds/x/scenarios/logi/a.yaml", {"/builds/x/scenarios/"}));
  EXPECT_EQ(shard_key("scenarios/logi/a.yaml", {"./scenarios/../scenarios"}), "logi/a.yaml");
  // The deepest folder that holds the file.
  EXPECT_EQ(shard_key("s/logi/a.yaml", {"s", "s/logi"}), "a.yaml");
  // A file named itself: its path as written, or its name when absolute.
  EXPECT_EQ(shard_key("scenarios/logi/a.yaml", {"scenarios/logi/a.yaml"}), "scenarios/logi/a.yaml");
  EXPECT_EQ(shard_key("./x/../a.yaml", {"./x/../a.yaml"}), "a.yaml");
  EXPECT_EQ(shard_key("/abs/a.yaml", {"/abs/a.yaml"}), "a.yaml");
}

TEST(ExpectedDuration, CountsWaitsTimeoutsScheduleAndSettle) {
  const auto scenario = parse_scenario_text(R"(
name: timed
car: logi
timeout: 60s
settle: 2s
setup:
  - connect
steps:
  - press FWD
  - wait: 3s
  - wait_until: {received: "MV:STOP"}
    timeout: 4s
  - wait: 500ms
)",
                                            "timed.yaml");
  // Two actions of 100 ms, a quarter of the wait-until's timeout.
  EXPECT_EQ(expected_duration(scenario), 200ms + 3s + 1s + 500ms + 2s);

  auto scheduled = scenario;
  scheduled.schedule.push_back(
      {Anchor{std::nullopt, 1, 20s}, Step{0, "wait", WaitStep{1s}, {}, {}}});
  EXPECT_EQ(expected_duration(scheduled), 20s + 1s + 2s);

  auto capped = scenario;
  capped.timeout = 3s;
  EXPECT_EQ(expected_duration(capped), 3s + 2s);
}

TEST(ShardPartition, EveryFileInExactlyOneShard) {
  for (const std::size_t count : {0U, 1U, 2U, 5U, 17U, 99U, 250U}) {
    const auto items = synthetic(count);
    for (int n = 1; n <= 12; ++n) {
      const auto shards = shard_partition(items, n);
      ASSERT_EQ(shards.size(), static_cast<std::size_t>(n));
      std::vector<std::size_t> all;
      for (const auto& s : shards)
        all.insert(all.end(), s.begin(), s.end());
      std::sort(all.begin(), all.end());
      std::vector<std::size_t> want(count);
      std::iota(want.begin(), want.end(), 0);
      EXPECT_EQ(all, want) << count << " files, " << n << " shards";
      // shard_members is the same partition, one shard at a time.
      for (int k = 1; k <= n; ++k)
        EXPECT_EQ(shard_members(items, {k, n}), shards[static_cast<std::size_t>(k - 1)]);
    }
  }
}

TEST(ShardPartition, TheOrderGivenDoesNotMatter) {
  auto items = synthetic(120);
  std::mt19937 rng(3);
  for (const int n : {2, 3, 7}) {
    const auto want = assignment(items, n);
    for (int round = 0; round < 5; ++round) {
      std::shuffle(items.begin(), items.end(), rng);
      EXPECT_EQ(assignment(items, n), want) << n << " shards, round " << round;
    }
  }
}

TEST(ShardPartition, EqualWeightsSpreadEvenly) {
  std::vector<ShardItem> items;
  for (int i = 0; i < 40; ++i)
    items.push_back({"s" + std::to_string(i) + ".yaml", "s" + std::to_string(i) + ".yaml", 1});
  for (const int n : {2, 4, 8}) {
    for (const auto& shard : shard_partition(items, n)) {
      // The load margin allows 15 % over the mean, no more.
      EXPECT_LE(static_cast<double>(shard.size()), 40.0 / n * (1 + kShardLoadMargin));
      EXPECT_FALSE(shard.empty());
    }
  }
}

TEST(ShardPartition, AddingAFileMovesFewOthers) {
  for (const int n : {2, 3, 4, 6, 8}) {
    std::size_t worst = 0;
    for (std::uint32_t seed = 1; seed <= 20; ++seed) {
      auto items = synthetic(80, seed);
      const auto before = assignment(items, n);
      items.push_back({"logi/new-scenario.yaml", "scenarios/logi/new-scenario.yaml", 6.5});
      const auto after = assignment(items, n);
      std::size_t moved = 0;
      for (const auto& [path, shard] : before)
        moved += after.at(path) != shard ? 1 : 0;
      worst = std::max(worst, moved);
    }
    std::cout << n << " shards: adding a file moved at most " << worst << " of 80 others\n";
    // Reassigning from scratch (a hash modulo N) would move about
    // 80 (1 - 1/N) of them: 40 to 70.
    EXPECT_LE(worst, 10U) << n << " shards";
  }
}

// The scenarios hil ships, weighed as hil run weighs them.
std::vector<ShardItem> library() {
  std::vector<ShardItem> items;
  const fs::path root = fs::path(HIL_SOURCE_DIR) / "scenarios";
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".yaml") continue;
    std::ifstream in(entry.path());
    bool car = false;
    bool steps = false;
    for (std::string line; std::getline(in, line);) {
      car = car || line.rfind("car:", 0) == 0;
      steps = steps || line.rfind("steps:", 0) == 0;
    }
    if (!car || !steps) continue;
    double weight_s = kShardNominalWeightS;
    try {
      weight_s =
          std::chrono::duration<double>(expected_duration(load_scenario(entry.path().string())))
              .count();
    } catch (const std::exception&) {
    }
    const std::string path = entry.path().string();
    items.push_back({shard_key(path, {root.string()}), path, weight_s});
  }
  return items;
}

TEST(ShardPartition, TheLibraryIsBalanced) {
  const auto items = library();
  ASSERT_GE(items.size(), 50U);
  double heaviest = 0;
  for (const auto& i : items)
    heaviest = std::max(heaviest, i.weight_s);
  for (int n = 2; n <= 8; ++n) {
    const double mean = mean_of(items, n);
    const double worst = max_load(items, n);
    std::cout << n << " shards: mean " << mean << " s, the longest shard " << worst << " s\n";
    // No shard passes the mean by more than the margin, unless a single
    // file is longer than that.
    EXPECT_LE(worst, std::max(mean * (1 + kShardLoadMargin), heaviest) + 1e-9) << n << " shards";
  }
}

}  // namespace
}  // namespace hil::harness
