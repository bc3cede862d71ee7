#include <gtest/gtest.h>

#include <memory>
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

TEST(VirtualExecutor, TimerIdsAreNeverZeroAndACancelledIdStaysDeadWhenItsSlotIsReused) {
  VirtualExecutor ex;
  int ran = 0;
  const auto first = ex.call_after(milliseconds(5), [&] { ran += 1; });
  EXPECT_NE(first, 0u);
  EXPECT_TRUE(ex.cancel(first));
  // The next task reuses the cancelled task's place; the old id must not reach it.
  const auto second = ex.call_after(milliseconds(5), [&] { ran += 10; });
  EXPECT_NE(second, 0u);
  EXPECT_NE(second, first);
  EXPECT_FALSE(ex.cancel(first));
  EXPECT_EQ(ex.pending(), 1u);
  ex.run_until_idle();
  EXPECT_EQ(ran, 10);
  EXPECT_FALSE(ex.cancel(second));  // it has run
  EXPECT_EQ(ex.pending(), 0u);
}

TEST(VirtualExecutor, CancellingReleasesTheTaskAtOnce) {
  VirtualExecutor ex;
  auto held = std::make_shared<int>(7);
  const std::weak_ptr<int> watch = held;
  const auto id = ex.call_after(seconds(30), [held = std::move(held)] { (void)held; });
  EXPECT_FALSE(watch.expired());
  EXPECT_TRUE(ex.cancel(id));
  EXPECT_TRUE(watch.expired());
}

TEST(VirtualExecutor, ManyCancelledTimeoutsNeitherRunNorDisturbTheOrder) {
  // A client re-arming a far timeout on every frame: thousands of cancelled
  // entries between live ones, which must still run in time order, each once.
  VirtualExecutor ex;
  std::vector<int> order;
  Executor::TimerId timeout = 0;
  for (int i = 0; i < 5000; ++i) {
    if (timeout != 0) {
      EXPECT_TRUE(ex.cancel(timeout));
    }
    timeout = ex.call_after(seconds(30) + milliseconds(i), [&] { order.push_back(-1); });
    if (i % 1000 == 0) ex.call_at(milliseconds(5000 - i), [&order, i] { order.push_back(i); });
  }
  EXPECT_EQ(ex.pending(), 6u);
  EXPECT_EQ(ex.next_due(), milliseconds(1000));
  EXPECT_EQ(ex.run_until_idle(), 6u);
  EXPECT_EQ(order, (std::vector<int>{4000, 3000, 2000, 1000, 0, -1}));
  EXPECT_EQ(ex.now(), seconds(30) + milliseconds(4999));
}

TEST(VirtualExecutor, ATaskMayCancelAnotherDueAtTheSameTime) {
  VirtualExecutor ex;
  std::vector<int> order;
  Executor::TimerId second = 0;
  ex.call_at(milliseconds(10), [&] {
    order.push_back(1);
    EXPECT_TRUE(ex.cancel(second));
    ex.post([&] { order.push_back(3); });
  });
  second = ex.call_at(milliseconds(10), [&] { order.push_back(2); });
  ex.run_until_idle();
  EXPECT_EQ(order, (std::vector<int>{1, 3}));
}

}  // namespace
}  // namespace hil::link
