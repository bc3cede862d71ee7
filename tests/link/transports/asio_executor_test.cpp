#include "link/asio_executor.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace {

TEST(AsioExecutor, TasksRunByDueTimeAndEqualTimesInSchedulingOrder) {
  asio::io_context io;
  AsioExecutor ex(io);
  std::string order;
  const Time t0 = ex.now();
  ex.call_at(t0 + milliseconds(40), [&] { order += 'A'; });
  for (char c : std::string("BCDEFG"))
    ex.call_at(t0 + milliseconds(20), [&order, c] { order += c; });
  ex.post([&] { order += 'p'; });
  ASSERT_TRUE(test::run_until(io, [&] { return order.size() == 8; }));
  EXPECT_EQ(order, "pBCDEFGA");
}

TEST(AsioExecutor, TaskRunsNoEarlierThanItsTime) {
  asio::io_context io;
  AsioExecutor ex(io);
  Time ran_at{-1};
  const Time due = ex.now() + milliseconds(30);
  ex.call_at(due, [&] { ran_at = ex.now(); });
  ASSERT_TRUE(test::run_until(io, [&] { return ran_at >= Time{0}; }));
  EXPECT_GE(ran_at, due);
  // Generous: a loaded machine may be late, never early.
  EXPECT_LT(ran_at - due, milliseconds(500));
}

TEST(AsioExecutor, CancelledTaskNeverRunsAndCancelReportsWhetherPending) {
  asio::io_context io;
  AsioExecutor ex(io);
  std::string order;
  const auto a = ex.call_after(milliseconds(10), [&] { order += 'a'; });
  const auto b = ex.call_after(milliseconds(10), [&] { order += 'b'; });
  ex.call_after(milliseconds(20), [&] { order += 'c'; });
  EXPECT_TRUE(ex.cancel(b));
  EXPECT_FALSE(ex.cancel(b));
  ASSERT_TRUE(test::run_until(io, [&] { return order.size() == 2; }));
  test::run_for(io, milliseconds(20));
  EXPECT_EQ(order, "ac");
  EXPECT_FALSE(ex.cancel(a));  // already ran
  EXPECT_EQ(ex.pending(), 0u);
}

TEST(AsioExecutor, TasksScheduledInThePastRunAfterThoseAlreadyDue) {
  asio::io_context io;
  AsioExecutor ex(io);
  std::string order;
  ex.post([&] { order += '1'; });
  ex.call_at(Time{0}, [&] { order += '2'; });  // long past: means "now"
  ASSERT_TRUE(test::run_until(io, [&] { return order.size() == 2; }));
  EXPECT_EQ(order, "12");
}

TEST(AsioExecutor, TasksMaySchedulePostAndCancelFromInsideTasks) {
  asio::io_context io;
  AsioExecutor ex(io);
  std::vector<int> seen;
  Executor::TimerId later = 0;
  ex.post([&] {
    seen.push_back(1);
    later = ex.call_after(milliseconds(5), [&] { seen.push_back(99); });
    ex.post([&] {
      seen.push_back(2);
      ex.cancel(later);
      ex.call_after(milliseconds(10), [&] { seen.push_back(3); });
    });
  });
  ASSERT_TRUE(test::run_until(io, [&] { return seen.size() == 3; }));
  test::run_for(io, milliseconds(20));
  EXPECT_EQ(seen, (std::vector<int>{1, 2, 3}));
}

TEST(AsioExecutor, IoContextRunReturnsOnceNothingIsPending) {
  asio::io_context io;
  AsioExecutor ex(io);
  const auto id = ex.call_after(std::chrono::seconds(30), [] {});
  ex.cancel(id);
  const auto start = std::chrono::steady_clock::now();
  io.run_for(std::chrono::seconds(5));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST(AsioExecutor, DestroyingTheExecutorDropsPendingTasks) {
  asio::io_context io;
  bool ran = false;
  {
    AsioExecutor ex(io);
    ex.post([&] { ran = true; });
  }
  io.run_for(milliseconds(50));
  EXPECT_FALSE(ran);
}

}  // namespace
}  // namespace hil::link
