// The car judged at the end of a run, in virtual time: 1 s after the run
// stopped the client the car must be at rest (or, with `at_end: moving`,
// still moving), and hil's reference clients stop the car when they are
// stopped, as an operator quitting does.

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "harness/client_under_test.hpp"
#include "harness/runner.hpp"
#include "tests/harness/runner_test_support.hpp"

namespace hil::harness {
namespace {

using namespace test;

/// A client that walks away: the car's reference client in every way but
/// its stop, which abandons its actions and leaves the car as it is.
class WalksAway final : public ForwardingClient {
 public:
  using ForwardingClient::ForwardingClient;
  void stop() override { inner().cancel(); }
};

RunOptions walking_away() {
  RunOptions options;
  options.reference_client = [](const ClientSetup& setup) -> std::unique_ptr<ScenarioClient> {
    return std::make_unique<WalksAway>(
        make_reference_client(setup.scenario.car, setup.context, setup.car, setup.timeline));
  };
  return options;
}

/// LOGI in MAN with FWD held when the steps end.
Scenario driving_at_the_end(mocks::CarKind car = mocks::CarKind::logi) {
  Scenario s;
  s.name = "driving-at-the-end";
  s.car = car;
  s.seed = 3;
  s.steps = {action("connect"), action("speed 50"), action("mode MAN"), action("press FWD"),
             wait(seconds(1))};
  return s;
}

const ExpectationOutcome& end_verdict(const ScenarioOutcome& o) {
  return o.expectations.back();
}

TEST(EndOfRun, AClientThatLeavesTheCarMovingFailsTheRunAndTheMessageSaysWhy) {
  const auto o = run_scenario(driving_at_the_end(), walking_away());
  ASSERT_TRUE(o.error.empty()) << o.error;
  EXPECT_FALSE(o.passed());
  const auto& end = end_verdict(o);
  EXPECT_FALSE(end.passed);
  EXPECT_EQ(end.label, "the car at rest 1.0 s after the run stopped the client");
  EXPECT_EQ(
      end.message.rfind("the car was still moving 1.0 s after the run stopped the client (0.", 0),
      0u)
      << end.message;
  EXPECT_NE(end.message.find(" m/s, its motors driven): the reference client stops the car when "
                             "the run ends, as an operator quitting does; a scenario that ends "
                             "moving on purpose says `at_end: moving`"),
            std::string::npos)
      << end.message;
  EXPECT_EQ(o.first_failure().rfind("at the end: the car was still moving", 0), 0u)
      << o.first_failure();
  // Judged 1 s of sim time after the stop, which came after the 500 ms settle.
  EXPECT_EQ(o.session_end, *end.window_from);
  EXPECT_EQ(*end.window_to, o.session_end + seconds(1));
  EXPECT_EQ(o.run_time, *end.window_to);
  EXPECT_TRUE(in_session(o, SimKind::at_rest).size() == 1u) << "at rest only at the start";
}

TEST(EndOfRun, TheSameRunPassesWhenTheScenarioSaysItEndsMoving) {
  Scenario s = driving_at_the_end();
  s.at_end = AtEnd::moving;
  const auto o = run_scenario(s, walking_away());
  EXPECT_TRUE(o.passed()) << o.first_failure();
  EXPECT_EQ(end_verdict(o).label, "the car still moving 1.0 s after the run stopped the client");
  EXPECT_NE(end_verdict(o).message.find("as `at_end: moving` asks"), std::string::npos);
}

TEST(EndOfRun, AtEndAnyIsNotJudged) {
  Scenario s = driving_at_the_end();
  s.at_end = AtEnd::any;
  const auto o = run_scenario(s, walking_away());
  EXPECT_TRUE(o.passed()) << o.first_failure();
  EXPECT_TRUE(o.expectations.empty());
}

TEST(EndOfRun, TheLogiReferenceClientStopsTheCarBeforeItHangsUp) {
  const auto o = run_scenario(driving_at_the_end());
  EXPECT_TRUE(o.passed()) << o.first_failure();
  EXPECT_EQ(end_verdict(o).message, "the car was at rest 1.0 s after the run stopped the client");
  // The emergency stop goes out when the run stops the client, after the
  // session: MV:STOP reaches the car, then the hang-up, and the car stops.
  std::vector<Record> stops;
  for (const auto& r : of(o, WireKind::frame))
    if (r.data["dir"] == "to_car" && r.data["stage"] == "delivered" && r.data["frame"] == "MV:STOP")
      stops.push_back(r);
  ASSERT_EQ(stops.size(), 1u);
  EXPECT_GE(stops[0].at, o.session_end);
  const auto rest = of(o, SimKind::at_rest);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_GT(rest[1].at, stops[0].at);
}

TEST(EndOfRun, AScenarioThatWantsTheCarMovingFailsWhenItStopped) {
  Scenario s = driving_at_the_end();
  s.at_end = AtEnd::moving;
  const auto o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  EXPECT_EQ(end_verdict(o).message,
            "expected the car still moving 1.0 s after the run stopped the client (`at_end: "
            "moving`), but it was at rest");
}

TEST(EndOfRun, ACarThatNeverMovedPassesForEveryCar) {
  for (const auto car :
       {mocks::CarKind::logi, mocks::CarKind::wr8, mocks::CarKind::arduino, mocks::CarKind::leka}) {
    Scenario s;
    s.name = "idle";
    s.car = car;
    s.seed = 1;
    s.steps = {wait(milliseconds(200))};
    const auto o = run_scenario(s);
    SCOPED_TRACE(std::string(mocks::to_string(car)));
    EXPECT_TRUE(o.passed()) << o.first_failure();
    ASSERT_EQ(o.expectations.size(), 1u);
    EXPECT_TRUE(end_verdict(o).passed);
  }
}

TEST(EndOfRun, TheLekaReferenceClientStopsARobotItLeftDriving) {
  Scenario s;
  s.name = "leka-driving";
  s.car = mocks::CarKind::leka;
  s.seed = 1;
  s.steps = {action("motor all forward 200"), wait(seconds(1))};
  const auto stopping = run_scenario(s);
  EXPECT_TRUE(stopping.passed()) << stopping.first_failure();
  const auto left = run_scenario(s, walking_away());
  EXPECT_FALSE(left.passed());
  EXPECT_EQ(end_verdict(left).message.rfind("the car was still moving 1.0 s after", 0), 0u)
      << end_verdict(left).message;
}

}  // namespace
}  // namespace hil::harness
