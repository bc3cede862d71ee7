#include <gtest/gtest.h>

#include <vector>

#include "link/executor.hpp"

namespace hil::link {
namespace {

TEST(VirtualExecutor, RunsTasksInTimeOrderThenSchedulingOrder) {
  VirtualExecutor ex;
  std::vector<int> order;
  ex.call_at(milliseconds(20), [&] { order.push_back(3); });
  ex.call_at(milliseconds(10), [&] { order.push_back(1); });
  ex.call_at(milliseconds(10), [&] { order.push_back(2); });
  EXPECT_EQ(ex.run_until_idle(), 3u);
  EXPECT_EQ(order, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(ex.now(), milliseconds(20));
}

TEST(VirtualExecutor, ClockJumpsExactlyToEachTask) {
  VirtualExecutor ex;
  std::vector<Time> seen;
  ex.call_after(milliseconds(800), [&] {
    seen.push_back(ex.now());
    ex.call_after(milliseconds(1000), [&] { seen.push_back(ex.now()); });
  });
  ex.run_until_idle();
  EXPECT_EQ(seen, (std::vector<Time>{milliseconds(800), milliseconds(1800)}));
}

TEST(VirtualExecutor, RunUntilStopsAtTheGivenTime) {
  VirtualExecutor ex;
  int ran = 0;
  ex.call_at(milliseconds(5), [&] { ++ran; });
  ex.call_at(milliseconds(15), [&] { ++ran; });
  EXPECT_EQ(ex.run_until(milliseconds(10)), 1u);
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(ex.now(), milliseconds(10));
  EXPECT_EQ(ex.next_due(), milliseconds(15));
  ex.run_for(milliseconds(5));
  EXPECT_EQ(ran, 2);
}

TEST(VirtualExecutor, CancelledTaskNeverRuns) {
  VirtualExecutor ex;
  bool ran = false;
  const auto id = ex.call_after(milliseconds(1), [&] { ran = true; });
  EXPECT_TRUE(ex.cancel(id));
  EXPECT_FALSE(ex.cancel(id));
  ex.run_until_idle();
  EXPECT_FALSE(ran);
}

TEST(VirtualExecutor, TaskInThePastRunsNowNotBackwards) {
  VirtualExecutor ex;
  ex.run_until(seconds(1));
  Time at{-1};
  ex.call_at(milliseconds(10), [&] { at = ex.now(); });
  ex.run_until_idle();
  EXPECT_EQ(at, seconds(1));
}

TEST(VirtualExecutor, PostRunsAfterTheCurrentTask) {
  VirtualExecutor ex;
  std::vector<int> order;
  ex.post([&] {
    ex.post([&] { order.push_back(2); });
    order.push_back(1);
  });
  ex.run_until_idle();
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
  EXPECT_EQ(ex.now(), Time{0});
}

TEST(VirtualExecutor, IdleGuardStopsARunawayTask) {
  VirtualExecutor ex;
  std::function<void()> again = [&] { ex.post(again); };
  ex.post(again);
  EXPECT_EQ(ex.run_until_idle(1000), 1000u);
  EXPECT_EQ(ex.pending(), 1u);
}

}  // namespace
}  // namespace hil::link
