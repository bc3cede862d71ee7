// The playback on `hil run --report-dir` pages in a real browser: headless
// Chromium opens a recorded run from disk (as from a CI artifact), shows
// the pose recorded at the time the address asks for, draws the car there,
// and plays the run forward. Skipped where Chromium or chromedriver is
// missing.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/view/browser_support.hpp"

namespace hil::view::test {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The recorded run the page plays back (its embedded JSON).
json playback_data(const std::string& page) {
  const std::string open = "<script id=\"pb-data\" type=\"application/json\">";
  const auto from = page.find(open);
  if (from == std::string::npos) return nullptr;
  const auto to = page.find("</script>", from);
  return json::parse(page.substr(from + open.size(), to - from - open.size()), nullptr, false);
}

class TempDir {
 public:
  TempDir() {
    char path[] = "/tmp/hil-playback-XXXXXX";
    if (::mkdtemp(path) != nullptr) path_ = path;
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

TEST(ReportPlaybackBrowser, ShowsTheRecordedPoseAtTheChosenTimeAndPlaysOn) {
  if (const auto missing = browser_missing(); !missing.empty()) GTEST_SKIP() << missing;
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  const auto report = dir.path() / "report";
  const auto run = hil::test::run_hil(
      "run scenarios/examples/logi-auto-station-2.yaml --seed 5 "
      "--report-dir '" +
      report.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path page = report / "logi-auto-station-2" / "index.html";
  const json data = playback_data(read(page));
  ASSERT_TRUE(data.is_object()) << "no playback data in " << page;
  const json& samples = data["cars"][0]["samples"];
  ASSERT_GT(samples.size(), 100U);

  // A recorded moment half-way through the drive to station 2.
  const json& mid = samples[samples.size() / 2];
  const double t_ms = mid[0].get<double>();
  char hash[64];
  std::snprintf(hash, sizeof hash, "#t=%.3f", t_ms / 1000);

  Browser browser;
  ASSERT_TRUE(browser.ready()) << browser.log();
  browser.open("file://" + page.string() + hash);
  const auto shown = [&] {
    return browser.run(
        "const e = document.getElementById('pb-pose'); return e ? Object.assign({}, e.dataset) : "
        "null;");
  };
  json pose = shown();
  EXPECT_NEAR(number(pose, "tMs"), t_ms, 0.5) << pose;
  EXPECT_NEAR(number(pose, "x"), mid[1].get<double>(), 1e-3) << pose << " vs " << mid;
  EXPECT_NEAR(number(pose, "y"), mid[2].get<double>(), 1e-3) << pose << " vs " << mid;
  EXPECT_NEAR(number(pose, "heading"), mid[3].get<double>(), 0.05) << pose << " vs " << mid;

  // The car is drawn there: the canvas is the car's blue under the pose.
  const json pixel = browser.run(
      "const c = document.getElementById('pb-canvas').getContext('2d');"
      "const d = document.getElementById('pb-pose').dataset;"
      "const p = c.getImageData(Math.round(hilPx(+d.x)), Math.round(hilPy(+d.y)), 1, 1).data;"
      "return [p[0], p[1], p[2]];");
  ASSERT_TRUE(pixel.is_array() && pixel.size() == 3) << pixel;
  EXPECT_LT(pixel[0].get<int>(), 80) << pixel;
  EXPECT_GT(pixel[2].get<int>(), 150) << pixel;

  // Play at 16x: the time moves on and the pose follows the recording.
  browser.run(
      "document.getElementById('pb-speed').value = '16';"
      "document.getElementById('pb-play').click(); return null;");
  ASSERT_TRUE(wait_until([&] { return number(shown(), "tMs") > t_ms + 2000; })) << shown();
  browser.run("document.getElementById('pb-play').click(); return null;");
  pose = shown();
  EXPECT_GT(std::hypot(number(pose, "x") - mid[1].get<double>(),
                       number(pose, "y") - mid[2].get<double>()),
            0.05)
      << "the car did not move on from " << mid << ": " << pose;

  // The slider takes the page back to the start pose.
  browser.run(
      "const s = document.getElementById('pb-slider'); s.value = 0;"
      "s.dispatchEvent(new Event('input')); return null;");
  pose = shown();
  EXPECT_NEAR(number(pose, "x"), samples[0][1].get<double>(), 1e-3) << pose;
  EXPECT_NEAR(number(pose, "y"), samples[0][2].get<double>(), 1e-3) << pose;

  browser.open("file://" + page.string() + "#t=8");
  browser.save_screenshot(PLAYBACK_SCREENSHOT_PATH);
}

}  // namespace
}  // namespace hil::view::test
