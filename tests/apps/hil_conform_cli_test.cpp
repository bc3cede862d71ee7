// hil conform as a client team runs it: a probe of a car (here hil mock
// logi in its firmware profile, over real TCP), the checks of the capture,
// the files they write, Ctrl-C during a probe, and every refusal.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "link/capture/probe_capture.hpp"
#include "tests/apps/hil_cli_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1))
    ++n;
  return n;
}

TEST(HilConform, RefusesWhatItCannotUse) {
  ScratchDir dir("hil-conform-cli");
  const auto out = (dir.path() / "c.ndjson").string();
  const auto plain_file = (dir.path() / "not-a-tty").string();
  std::ofstream(plain_file) << "x";
  for (const auto& run : {
           says("conform probe tank --target tcp://127.0.0.1:9 -o " + out, 2,
                {"unknown car 'tank' (expected logi, wr8, arduino or leka)"}),
           says("conform probe logi --target tcp://192.0.2.1:8080 -o " + out, 2,
                {"tcp host 192.0.2.1 is not this machine", "add --yes"}),
           says("conform probe arduino --target pty://" + plain_file + " -o " + out, 2,
                {plain_file + " is not a pseudo-terminal", "add --yes"}),
           says("conform probe logi --target tcp://127.0.0.1 -o " + out, 2, {"hil conform probe"}),
           says("conform probe arduino --profile sketch --target tcp://127.0.0.1:9 -o " + out, 2,
                {"arduino has no profile 'sketch'"}),
           says("conform check " + out + ".missing", 2, {"hil conform check: ", ".missing"}),
           says("conform check scenarios/captures/logi-session.txt", 2, {"logi-session.txt:1:"}),
           says("conform check x --profile guide --all-profiles", 2, {"excludes"}),
       }) {
    expect_run(run);
  }
}

TEST(HilConform, NamesAStaleProbeVersion) {
  ScratchDir dir("hil-conform-cli");
  const auto path = dir.path() / "old.ndjson";
  std::ofstream(path)
      << R"({"link":"probe","event":"probe","t_ms":0,"wall_us":1,"probe":"logi-probe/0",)"
      << R"("car":"logi","profile":"guide","target":"tcp://10.0.0.2:8080"})"
      << "\n";
  expect_run(says("conform check " + path.string(), 2,
                  {"made by probe logi-probe/0", "probe the car again"}));
}

TEST(HilConform, ProbesACarAndChecksTheCapture) {
  ScratchDir dir("hil-conform-cli");
  HilProcess mock({"mock", "logi", "--port", "0", "--profile", "firmware"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  const auto capture = (dir.path() / "car.ndjson").string();
  const auto probe = run_hil("conform probe logi --target tcp://127.0.0.1:" + std::to_string(port) +
                             " -q -o " + capture);
  EXPECT_EQ(mock.interrupt(), 0);
  ASSERT_EQ(probe.exit_code, 0) << probe.output;
  EXPECT_THAT(probe.output, ::testing::HasSubstr("probe: 54 exchanges recorded in " + capture));

  // Probed in the default profile (guide), the car is compared with it:
  // the six cuts of the stream the firmware reads otherwise differ.
  const auto guide = run_hil("conform check " + capture);
  EXPECT_EQ(guide.exit_code, 1) << guide.output;
  EXPECT_THAT(guide.output, ::testing::HasSubstr("conform: 48 of 54 exchanges match (logi, "
                                                 "profile guide)"));
  EXPECT_EQ(count(guide.output, "-> answered as the car did by profile firmware"), 6u)
      << guide.output;

  const auto junit = (dir.path() / "conform.xml").string();
  const auto html = (dir.path() / "conform.html").string();
  const auto best =
      run_hil("conform check " + capture + " --all-profiles --junit " + junit + " --html " + html);
  EXPECT_EQ(best.exit_code, 0) << best.output;
  EXPECT_THAT(best.output, ::testing::HasSubstr("profiles by matches:\n  firmware        54 of "
                                                "54\n  guide           48 of 54\n"));
  EXPECT_THAT(best.output,
              ::testing::HasSubstr("conform: 54 of 54 exchanges match (logi, profile firmware)"));
  const auto xml = read_file(junit);
  EXPECT_EQ(count(xml, "<testcase "), 54u);
  EXPECT_THAT(xml, ::testing::HasSubstr("failures=\"0\""));
  EXPECT_THAT(read_file(html), ::testing::HasSubstr("conform: 54 of 54 exchanges match"));

  const auto failing = run_hil("conform check " + capture + " --profile guide --junit " + junit);
  EXPECT_EQ(failing.exit_code, 1);
  EXPECT_THAT(read_file(junit), ::testing::HasSubstr("failures=\"6\""));
}

TEST(HilConform, CtrlCSendsTheClosingStopAndKeepsTheCapture) {
  ScratchDir dir("hil-conform-cli");
  HilProcess mock({"mock", "logi", "--port", "0"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  const auto capture = dir.path() / "cut.ndjson";
  HilProcess probe({"conform", "probe", "logi", "--target",
                    "tcp://127.0.0.1:" + std::to_string(port), "-o", capture.string()});
  ASSERT_TRUE(probe.wait_for_line("exchange 4/54 sp-000", 20s)) << probe.output();
  const auto status = probe.interrupt(20s);
  EXPECT_EQ(status, 1) << probe.output();
  EXPECT_THAT(probe.output(), ::testing::HasSubstr("interrupted: the probe sent its closing stop"));
  EXPECT_EQ(mock.interrupt(), 0);
  const auto read = link::read_capture(capture);
  ASSERT_GE(read.exchanges.size(), 5u);
  EXPECT_LT(read.exchanges.size(), 54u);
  EXPECT_EQ(read.exchanges.back().name, "stop");
  const auto& sent = read.exchanges.back().events;
  ASSERT_FALSE(sent.empty());
  EXPECT_EQ(std::string(sent[0].bytes.begin(), sent[0].bytes.end()), "LOGI:MV:STOP:88#");
}

}  // namespace
}  // namespace hil::test
