// The live view in a real browser: headless Chromium, steered through
// chromedriver's WebDriver API, loads the page from `hil mock logi --view`,
// follows a car logi-client drives, switches a fault on through the panel,
// and saves a screenshot. Skipped where Chromium or chromedriver is missing.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/view/browser_support.hpp"

namespace hil::view::test {
namespace {

TEST(LiveViewBrowser, PageFollowsTheCarAndItsPanelSwitchesAFaultOn) {
  if (const auto missing = browser_missing(); !missing.empty()) GTEST_SKIP() << missing;
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  Browser browser;
  ASSERT_TRUE(browser.ready()) << browser.log();
  browser.open(mock.url());
  ASSERT_TRUE(wait_until([&] { return number(browser.drawn(), "updates") > 2; }))
      << browser.drawn();
  const json start = mock.state()["pose"];
  json drawn = browser.drawn();
  EXPECT_NEAR(number(drawn, "x"), start["x"].get<double>(), 0.01) << drawn;
  EXPECT_NEAR(number(drawn, "y"), start["y"].get<double>(), 0.01) << drawn;

  // Drive: the drawn pose leaves the start and settles where the car stopped.
  const std::string out = mock.drive(
      {"connect", "speed 60", "mode MAN", "press FWD", "wait 1500ms", "release", "wait 300ms"});
  EXPECT_NE(out.find("ok   press FWD"), std::string::npos) << out;
  const json stopped = mock.state()["pose"];
  ASSERT_GT(distance_between(stopped, start), 0.2);
  EXPECT_TRUE(wait_until([&] {
    drawn = browser.drawn();
    return std::hypot(number(drawn, "x") - stopped["x"].get<double>(),
                      number(drawn, "y") - stopped["y"].get<double>()) < 0.01;
  })) << drawn
      << " vs " << stopped;

  // The panel: pick a preset (wrong checksum on every 5th car frame), apply.
  browser.click("#preset option[value=corrupt]");
  browser.click("#apply-faults");
  EXPECT_TRUE(wait_until([&] { return number(browser.drawn(), "faultRules") == 1; }))
      << browser.drawn();
  const std::string faulty = mock.drive({"connect", "wait 3s"});
  EXPECT_NE(faulty.find("bad_checksum"), std::string::npos) << faulty;
  EXPECT_TRUE(wait_until([&] { return number(browser.drawn(), "faultsInjected") > 0; }))
      << browser.drawn();
  EXPECT_EQ(browser.run("return document.getElementById('message').textContent;"), "faults: done");

  browser.save_screenshot(VIEW_SCREENSHOT_PATH);
}

}  // namespace
}  // namespace hil::view::test
