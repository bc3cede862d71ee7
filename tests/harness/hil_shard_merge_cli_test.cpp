// hil run --shard K/N and hil report merge as a sharded CI gate runs them:
// the shards together run every scenario once, and the merge joins their
// JUnit files and report folders, failing on a failed run, a scenario no
// shard ran and a scenario two shards ran. The scenarios are in
// tests/harness/data/shard/ (short, virtual time).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <pugixml.hpp>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/harness/scratch_dir.hpp"
#include "tests/support/text.hpp"

namespace hil::test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kData = "tests/harness/data/shard";
constexpr int kShards = 3;

// The files `hil run ARGS --list` lists (the first word of each line that
// names a scenario file).
std::vector<std::string> listed(const std::string& args) {
  const auto r = run_hil("run " + args + " --list");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> files;
  for (const auto& line : lines_of(r.output))
    if (line.rfind(kData, 0) == 0) files.push_back(line.substr(0, line.find(' ')));
  return files;
}

// The file attribute of each <testcase>, counted.
std::map<std::string, int> junit_files(const fs::path& path) {
  pugi::xml_document doc;
  EXPECT_TRUE(doc.load_file(path.c_str())) << path;
  std::map<std::string, int> out;
  for (const auto& tc : doc.child("testsuite").children("testcase"))
    ++out[tc.attribute("file").as_string()];
  return out;
}

std::string read(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// The three shards run once for every test: DIR/K.xml and DIR/report-K.
class ShardedGate : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir("hil-shard");
    for (int k = 1; k <= kShards; ++k) {
      const auto r = run_hil("run " + kData + " --shard " + std::to_string(k) + "/3 --junit " +
                             out(std::to_string(k) + ".xml") + " --report-dir " +
                             out("report-" + std::to_string(k)));
      outputs_[k] = r.output;
      exits_[k] = r.exit_code;
    }
  }
  static void TearDownTestSuite() {
    delete scratch_;
    scratch_ = nullptr;
  }
  static std::string out(const std::string& name) { return (scratch_->path() / name).string(); }
  static std::string shard_xmls() { return out("1.xml") + " " + out("2.xml") + " " + out("3.xml"); }

  static inline ScratchDir* scratch_ = nullptr;
  static inline std::map<int, std::string> outputs_;
  static inline std::map<int, int> exits_;
};

TEST(HilShardCli, ABadShardIsAUsageErrorNamingTheOption) {
  for (const char* bad : {"0/3", "4/3", "3", "a/b", "1/0"}) {
    SCOPED_TRACE(bad);
    const auto r = run_hil("run " + kData + " --shard " + bad);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr("--shard"));
    EXPECT_THAT(r.output, HasSubstr(std::string("'") + bad + "'"));
    EXPECT_THAT(r.output, Not(HasSubstr("passed")));
  }
}

TEST(HilShardCli, TheShardsListEveryScenarioOnce) {
  const auto all = listed(kData);
  ASSERT_EQ(all.size(), 7U);
  for (const int n : {1, 2, 3, 5, 9}) {
    std::multiset<std::string> seen;
    for (int k = 1; k <= n; ++k)
      for (const auto& f :
           listed(kData + " --shard " + std::to_string(k) + "/" + std::to_string(n)))
        seen.insert(f);
    EXPECT_EQ(seen, std::multiset<std::string>(all.begin(), all.end())) << n << " shards";
  }
}

TEST(HilShardCli, TheShardsDoNotDependOnHowTheFolderIsWritten) {
  for (int k = 1; k <= kShards; ++k) {
    const std::string shard = " --shard " + std::to_string(k) + "/3";
    std::vector<std::string> plain;
    for (const auto& f : listed(kData + shard))
      plain.push_back(fs::path(f).filename().string());
    const auto r = run_hil("run ./" + kData + "/ --list" + shard);
    for (const auto& name : plain)
      EXPECT_THAT(r.output, HasSubstr(name));
    // The absolute path of the same folder (another checkout's place).
    const auto a =
        run_hil("run " + (fs::path(HIL_SOURCE_DIR) / kData).string() + " --list" + shard);
    for (const auto& name : plain)
      EXPECT_THAT(a.output, HasSubstr(name));
    EXPECT_EQ(lines_of(a.output).size(), lines_of(r.output).size());
  }
}

TEST(HilShardCli, RepeatRepeatsWithinTheShard) {
  const auto files = listed(kData + " --shard 2/3");
  ASSERT_FALSE(files.empty());
  const auto r = run_hil("run " + kData + " --shard 2/3 --repeat 2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr(std::to_string(files.size()) + " passed, 0 failed"));
  for (const auto& file : files) {
    const std::string name = "shard-" + fs::path(file).stem().string();
    EXPECT_THAT(r.output, HasSubstr(name + " #1"));
    EXPECT_THAT(r.output, HasSubstr(name + " #2"));
  }
  for (const auto& other : listed(kData + " --shard 1/3"))
    EXPECT_THAT(r.output, Not(HasSubstr("shard-" + fs::path(other).stem().string() + " ")));
}

TEST(HilShardCli, AnEmptyShardRunsNothingAndPasses) {
  const std::string one = kData + "/logi/stop-quick.yaml";
  int ran = 0;
  for (int k = 1; k <= kShards; ++k) {
    const auto r = run_hil("run " + one + " --shard " + std::to_string(k) + "/3");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    if (r.output.find("shard-stop-quick") != std::string::npos) {
      ++ran;
    } else {
      EXPECT_THAT(r.output, HasSubstr("has no scenarios"));
    }
  }
  EXPECT_EQ(ran, 1);
}

TEST_F(ShardedGate, EachShardPasses) {
  for (int k = 1; k <= kShards; ++k)
    EXPECT_EQ(exits_[k], 0) << outputs_[k];
}

TEST_F(ShardedGate, MergedReportFoldersHoldEveryScenarioOnce) {
  const auto r = run_hil("report merge --expect " + kData + " --junit " + out("merged.xml") +
                         " --report-dir " + out("merged") + " " + out("report-1") + " " +
                         out("report-2") + " " + out("report-3"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("7 runs from 3 inputs, 7 scenarios expected"));
  EXPECT_THAT(r.output, HasSubstr("7 passed, 0 failed"));
  const auto files = junit_files(out("merged.xml"));
  ASSERT_EQ(files.size(), 7U);
  for (const auto& [file, count] : files) {
    EXPECT_EQ(count, 1) << file;
    EXPECT_EQ(file.rfind(kData, 0), 0U) << file;
  }
  // One index linking every run, whose folders were copied.
  const std::string index = read(out("merged/index.html"));
  EXPECT_THAT(index, HasSubstr("7 passed, 0 failed"));
  for (const char* name :
       {"shard-forward-short", "shard-forward-long", "shard-forward-mid", "shard-stop-quick",
        "shard-speed-low", "shard-speed-high", "shard-pause"}) {
    EXPECT_THAT(index, HasSubstr(std::string("href=\"") + name + "/index.html\""));
    EXPECT_TRUE(fs::exists(out(std::string("merged/") + name + "/timeline.ndjson"))) << name;
  }
  EXPECT_TRUE(fs::exists(out("merged/results.json")));
}

TEST_F(ShardedGate, MergedJUnitFilesHoldEveryScenarioOnce) {
  const auto r = run_hil("report merge --expect " + kData + " --junit " + out("from-xml.xml") +
                         " " + shard_xmls());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const auto files = junit_files(out("from-xml.xml"));
  EXPECT_EQ(files.size(), 7U);
  for (const auto& [file, count] : files)
    EXPECT_EQ(count, 1) << file;
}

TEST_F(ShardedGate, AFailedShardFailsTheMerge) {
  const auto fail = run_hil("run tests/harness/data/run/fail.yaml --junit " + out("fail.xml"));
  ASSERT_EQ(fail.exit_code, 1) << fail.output;
  const auto r = run_hil("report merge --junit " + out("with-fail.xml") + " " + shard_xmls() + " " +
                         out("fail.xml"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("failed: run-fail (tests/harness/data/run/fail.yaml) in " +
                                  out("fail.xml")));
  EXPECT_THAT(r.output, HasSubstr("7 passed, 1 failed"));
  EXPECT_EQ(junit_files(out("with-fail.xml")).size(), 8U);
}

TEST_F(ShardedGate, AMissingShardNamesEveryScenarioItRan) {
  const auto third = listed(kData + " --shard 3/3");
  ASSERT_FALSE(third.empty());
  const auto r = run_hil("report merge --expect " + kData + " --junit " + out("missing.xml") + " " +
                         out("1.xml") + " " + out("2.xml"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  for (const auto& file : third)
    EXPECT_THAT(r.output, HasSubstr("missing: " + file + " is in no input")) << r.output;
  EXPECT_THAT(r.output, HasSubstr(std::to_string(third.size()) + " missing"));
}

TEST_F(ShardedGate, AShardGivenTwiceNamesTheDoubledScenarios) {
  fs::copy_file(out("2.xml"), out("2-again.xml"), fs::copy_options::overwrite_existing);
  const auto second = listed(kData + " --shard 2/3");
  ASSERT_FALSE(second.empty());
  const auto r = run_hil("report merge --expect " + kData + " --junit " + out("doubled.xml") + " " +
                         shard_xmls() + " " + out("2-again.xml"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  for (const auto& file : second) {
    EXPECT_THAT(r.output, HasSubstr("(" + file + ") ran in 2 inputs: " + out("2.xml") + ", " +
                                    out("2-again.xml")));
  }
}

TEST_F(ShardedGate, AnUnreadableInputIsAUsageErrorNamingIt) {
  std::ofstream(out("garbage.xml")) << "this is not XML <";
  fs::create_directories(out("not-a-report"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {out("no-such.xml"), out("no-such.xml") + ": no such file or folder"},
      {out("not-a-report"), out("not-a-report") + ": a folder without results.json"},
      {out("garbage.xml"), out("garbage.xml") + ": not"},
  };
  for (const auto& [input, message] : cases) {
    const auto r =
        run_hil("report merge --junit " + out("x.xml") + " " + out("1.xml") + " " + input);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(message));
  }
  expect_run(says("report merge " + out("1.xml"), 2, {"--junit"}));
}

}  // namespace
}  // namespace hil::test
