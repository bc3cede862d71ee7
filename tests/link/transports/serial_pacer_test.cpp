// Serial pacing in virtual time, with exact expectations.
#include <gtest/gtest.h>

#include <vector>

#include "link/serial_pacer.hpp"

namespace hil::link {
namespace {

using std::chrono::nanoseconds;

struct Arrival {
  Time at;
  std::size_t bytes;
};

/// The bytes 0, 1, 2, ... (mod 256), `n` of them.
Bytes counting(std::size_t n) {
  Bytes b(n);
  for (std::size_t i = 0; i < n; ++i)
    b[i] = static_cast<std::uint8_t>(i);
  return b;
}

struct Paced {
  explicit Paced(unsigned baud, Duration min_tick = milliseconds(1))
      : pacer(
            ex, baud,
            [this](ByteView b) {
              arrivals.push_back({ex.now(), b.size()});
              data.insert(data.end(), b.begin(), b.end());
            },
            min_tick) {}

  Time last_arrival() const { return arrivals.empty() ? Time{-1} : arrivals.back().at; }

  /// Writes `first` bytes at time 0 and `second` bytes at `then`, and runs
  /// until the line is idle.
  void push_twice(std::size_t first, Time then, std::size_t second) {
    pacer.push(counting(first));
    ex.run_until(then);
    pacer.push(counting(second));
    ex.run_until_idle();
  }

  VirtualExecutor ex;
  std::vector<Arrival> arrivals;
  Bytes data;
  SerialPacer pacer;
};

TEST(SerialPacer, ByteTimeIsTenBitsAtTheBaud) {
  EXPECT_EQ(SerialPacer::byte_time(9600), nanoseconds(1'041'666));
  EXPECT_EQ(SerialPacer::byte_time(115200), nanoseconds(86'805));
}

TEST(SerialPacer, NinetySixBytesAt9600TakeOneHundredMilliseconds) {
  Paced p(9600);
  p.pacer.push(counting(96));
  p.ex.run_until_idle();
  ASSERT_EQ(p.arrivals.size(), 96u);  // 1.04 ms apart: one byte per release
  EXPECT_EQ(p.arrivals.front().at, nanoseconds(1'041'667));
  EXPECT_EQ(p.arrivals[47].at, milliseconds(50));
  EXPECT_EQ(p.last_arrival(), milliseconds(100));
  EXPECT_EQ(p.data, counting(96));
}

TEST(SerialPacer, NoByteArrivesBeforeItsLastBitIsSent) {
  Paced p(9600);
  p.pacer.push(counting(20));
  p.ex.run_until_idle();
  std::size_t total = 0;
  for (const auto& a : p.arrivals) {
    total += a.bytes;
    EXPECT_GE(a.at.count() * 9600, static_cast<long long>(total) * 10'000'000'000LL);
  }
}

TEST(SerialPacer, WritesDuringABurstQueueBehindIt) {
  Paced p(9600);
  p.push_twice(10, milliseconds(5), 10);
  // 20 bytes back to back: 20 * 10 / 9600 s = 20.8333.. ms, rounded up.
  EXPECT_EQ(p.last_arrival(), nanoseconds(20'833'334));
  EXPECT_EQ(p.data.size(), 20u);
}

TEST(SerialPacer, AnIdleLineStartsANewBurstWhenBytesArrive) {
  Paced p(9600);
  p.push_twice(1, milliseconds(10), 1);
  ASSERT_EQ(p.arrivals.size(), 2u);
  EXPECT_EQ(p.arrivals[1].at, milliseconds(10) + nanoseconds(1'041'667));
}

TEST(SerialPacer, HighRatesReleaseChunksAtMostOncePerTick) {
  Paced p(115200, milliseconds(1));
  p.pacer.push(counting(1000));
  p.ex.run_until_idle();
  EXPECT_EQ(p.data, counting(1000));
  const Time ideal_end = nanoseconds(86'805'556);  // 1000 * 10 / 115200 s, rounded up
  EXPECT_GE(p.last_arrival(), ideal_end);
  EXPECT_LE(p.last_arrival(), ideal_end + milliseconds(1));
  EXPECT_LE(p.arrivals.size(), 88u);
  for (std::size_t i = 1; i < p.arrivals.size(); ++i) {
    EXPECT_GE(p.arrivals[i].at - p.arrivals[i - 1].at, milliseconds(1));
  }
}

TEST(SerialPacer, TheFirstByteOfTheFirstBurstIsNotHeldForATick) {
  // At 115200 baud a byte is 86.8 us: the first one is due long before the
  // 1 ms tick, and nothing was released before it to space it from.
  Paced p(115200, milliseconds(1));
  p.pacer.push(counting(3));
  p.ex.run_until_idle();
  ASSERT_EQ(p.arrivals.size(), 2u);
  EXPECT_EQ(p.arrivals[0].at, nanoseconds(86'806));
  EXPECT_EQ(p.arrivals[0].bytes, 1u);
  EXPECT_EQ(p.arrivals[1].at, nanoseconds(86'806) + milliseconds(1));
  EXPECT_EQ(p.arrivals[1].bytes, 2u);
}

TEST(SerialPacer, LongStreamsKeepExactTiming) {
  Paced p(9600);
  p.pacer.push(counting(30'000));
  p.ex.run_until_idle();
  EXPECT_EQ(p.data.size(), 30'000u);
  EXPECT_EQ(p.last_arrival(), milliseconds(31'250));
}

TEST(SerialPacer, ClearDropsWhatWasNotReleased) {
  Paced p(9600);
  p.pacer.push(counting(10));
  p.ex.run_until(milliseconds(3));
  EXPECT_EQ(p.data.size(), 2u);
  EXPECT_EQ(p.pacer.queued(), 8u);
  p.pacer.clear();
  p.ex.run_until_idle();
  EXPECT_EQ(p.data.size(), 2u);
  EXPECT_EQ(p.pacer.queued(), 0u);
}

TEST(SerialPacer, WhenDrainedRunsAfterTheLastByte) {
  Paced p(9600);
  Time drained{-1};
  p.pacer.push(counting(5));
  p.pacer.when_drained([&] { drained = p.ex.now(); });
  p.ex.run_until_idle();
  EXPECT_EQ(drained, p.last_arrival());
  bool at_once = false;
  p.pacer.when_drained([&] { at_once = true; });
  EXPECT_TRUE(at_once);
}

TEST(SerialPacer, ZeroBaudPassesBytesStraightThrough) {
  Paced p(0);
  p.pacer.push(counting(3));
  EXPECT_EQ(p.data.size(), 3u);
  EXPECT_EQ(p.ex.pending(), 0u);
}

}  // namespace
}  // namespace hil::link
