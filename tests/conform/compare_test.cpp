// compare() on captures made by hand: what matches, what differs, and the
// words of each difference, with exact times (virtual time needs no slack).
#include "conform/compare.hpp"

#include <gtest/gtest.h>

#include "protocol/common/bytes.hpp"
#include "protocol/logi/codec.hpp"

namespace hil::conform {
namespace {

using protocol::to_bytes;
using std::chrono::milliseconds;

// A LOGI probe of three exchanges: connect, telemetry, and one command.
Probe probe() {
  Probe p;
  p.car = mocks::CarKind::logi;
  p.profile = "guide";
  p.version = "logi-probe/test";
  p.telemetry_kinds = {"STAT"};
  p.exchanges = {{"connect", "open", ExchangeKind::connect, {}, false, milliseconds(100)},
                 {"telemetry", "listen", ExchangeKind::telemetry, {}, false, milliseconds(2000)},
                 {"sp", "SP:020", ExchangeKind::command, {}, false, milliseconds(300)}};
  return p;
}

std::string stat_frame(int distance_cm) {
  std::string body =
      "STAT:SP:050,STA:000,RUN:0,MODE:MAN,MAN:STOP,DIS:" + std::to_string(distance_cm) +
      ",TRK:0000,DEV:0,OBS:0,RPM:0:0:0:0";
  return protocol::logi::frame_text(body);
}

// The capture of a car that sends STAT every `period` and answers SP after
// `latency` with `answer` (nothing when empty).
Capture capture(milliseconds period, milliseconds latency, const std::string& answer,
                int distance_cm = 120, bool closes = false) {
  CaptureRecorder r({"logi-probe/test", "logi", "guide", "test", 0});
  r.begin_exchange(milliseconds(0), "connect", ExchangeKind::connect, "open");
  r.opened(milliseconds(0), "probe", "car");
  r.begin_exchange(milliseconds(100), "telemetry", ExchangeKind::telemetry, "listen");
  for (auto t = milliseconds(100) + period; t < milliseconds(2100); t += period)
    r.received(t, to_bytes(stat_frame(distance_cm)));
  r.begin_exchange(milliseconds(2100), "sp", ExchangeKind::command, "SP:020");
  r.sent(milliseconds(2100), to_bytes("LOGI:SP:020:D4#"));
  if (!answer.empty()) r.received(milliseconds(2100) + latency, to_bytes(answer));
  if (closes)
    r.closed(milliseconds(2300),
             {link::LinkClose::By::car, link::CloseMode::graceful, "car closed"});
  r.end_exchange(milliseconds(2400));
  return r.take();
}

const std::string kFbSp = "LOGI:FB:SP:1:35#";

TEST(Compare, EqualCapturesMatchEveryExchange) {
  const auto c = capture(milliseconds(500), milliseconds(10), kFbSp);
  const auto result = compare(c, c, probe(), "guide");
  EXPECT_EQ(result.matches(), 3u);
  EXPECT_TRUE(result.all_match());
  EXPECT_EQ(result.exchanges[2].car.summary(), kFbSp);
  EXPECT_EQ(result.exchanges[2].car.latency, milliseconds(10));
}

TEST(Compare, ADifferentAnswerIsShownFrameByFrame) {
  const auto result =
      compare(capture(milliseconds(500), milliseconds(10), kFbSp),
              capture(milliseconds(500), milliseconds(10), "LOGI:FB:SP:0:34#"), probe(), "guide");
  EXPECT_EQ(result.matches(), 2u);
  EXPECT_EQ(result.exchanges[2].differences,
            std::vector<std::string>{
                "frame 1: the car sent LOGI:FB:SP:1:35#, the mock LOGI:FB:SP:0:34#"});
}

TEST(Compare, SilenceIsComparedToo) {
  const auto result =
      compare(capture(milliseconds(500), milliseconds(10), ""),
              capture(milliseconds(500), milliseconds(10), kFbSp), probe(), "guide");
  EXPECT_EQ(result.exchanges[2].car.summary(), "(silent)");
  EXPECT_EQ(result.exchanges[2].differences,
            (std::vector<std::string>{"the car answered nothing, the mock 1 frame",
                                      "only the mock sent LOGI:FB:SP:1:35#"}));
}

TEST(Compare, LatencyWithinTheLargerToleranceMatches) {
  const auto car = capture(milliseconds(500), milliseconds(10), kFbSp);
  // 50 ms is the absolute tolerance: 60 ms is within it, 61 ms is not.
  EXPECT_TRUE(
      compare(car, capture(milliseconds(500), milliseconds(60), kFbSp), probe(), "g").all_match());
  const auto late = compare(car, capture(milliseconds(500), milliseconds(61), kFbSp), probe(), "g");
  EXPECT_EQ(late.exchanges[2].differences,
            std::vector<std::string>{"answered after 10.0 ms by the car, 61.0 ms by the mock "
                                     "(allowed: 50.0 ms apart)"});
  // Relative to a slow car: half of 200 ms.
  const auto slow = capture(milliseconds(500), milliseconds(200), kFbSp);
  EXPECT_TRUE(compare(slow, capture(milliseconds(500), milliseconds(300), kFbSp), probe(), "g")
                  .all_match());
  EXPECT_FALSE(compare(slow, capture(milliseconds(500), milliseconds(301), kFbSp), probe(), "g")
                   .all_match());
}

TEST(Compare, TelemetryIsComparedByPeriodAndShape) {
  const auto car = capture(milliseconds(500), milliseconds(10), kFbSp, 120);
  // Another distance is the same shape; 590 ms is within 20 % of 500 ms.
  EXPECT_TRUE(compare(car, capture(milliseconds(590), milliseconds(10), kFbSp, 37), probe(), "g")
                  .all_match());
  const auto slow = compare(car, capture(milliseconds(650), milliseconds(10), kFbSp), probe(), "g");
  EXPECT_EQ(slow.exchanges[1].differences,
            std::vector<std::string>{"STAT every 500.0 ms from the car, every 650.0 ms from the "
                                     "mock (allowed: 100.0 ms apart)"});
}

TEST(Compare, TelemetryOfAnotherShapeDiffers) {
  auto other = capture(milliseconds(500), milliseconds(10), kFbSp);
  for (auto& e : other.exchanges[1].events)
    e.bytes = to_bytes(protocol::logi::frame_text("STAT:SP:050,STA:000,RUN:0,MODE:MAN"));
  const auto result =
      compare(capture(milliseconds(500), milliseconds(10), kFbSp), other, probe(), "guide");
  ASSERT_EQ(result.exchanges[1].differences.size(), 1u);
  EXPECT_EQ(result.exchanges[1].differences[0].substr(0, 24), "STAT: the car sent LOGI:");
}

TEST(Compare, TelemetryDoesNotCountAsAnAnswerElsewhere) {
  auto car = capture(milliseconds(500), milliseconds(10), kFbSp);
  // A STAT arriving during the command's window is left out of its answer.
  car.exchanges[2].events.insert(
      car.exchanges[2].events.begin() + 1,
      {CaptureEvent::Kind::received, milliseconds(2105), to_bytes(stat_frame(99))});
  const auto result =
      compare(car, capture(milliseconds(500), milliseconds(10), kFbSp), probe(), "guide");
  EXPECT_TRUE(result.exchanges[2].matches());
  EXPECT_EQ(result.exchanges[2].car.latency, milliseconds(10));
}

TEST(Compare, ACloseByTheCarIsADifference) {
  const auto result = compare(capture(milliseconds(500), milliseconds(10), kFbSp, 120, true),
                              capture(milliseconds(500), milliseconds(10), kFbSp), probe(), "g");
  EXPECT_EQ(result.exchanges[2].car.summary(), kFbSp + "  (closed)");
  EXPECT_EQ(
      result.exchanges[2].differences,
      std::vector<std::string>{"the car closed the connection, the mock kept the connection open"});
}

TEST(Compare, AnExchangeMissingFromACaptureDiffers) {
  auto cut = capture(milliseconds(500), milliseconds(10), kFbSp);
  cut.exchanges.pop_back();
  const auto result =
      compare(cut, capture(milliseconds(500), milliseconds(10), kFbSp), probe(), "guide");
  EXPECT_EQ(result.matches(), 2u);
  EXPECT_EQ(result.exchanges[2].differences,
            std::vector<std::string>{"not in the car's capture (the probe stopped before it)"});
}

TEST(Compare, PhysicalAnswersAreComparedByShape) {
  auto p = probe();
  p.exchanges[2].physical = true;
  // The digits differ and so does the checksum; the shape is the same.
  const auto a = capture(milliseconds(500), milliseconds(10), kFbSp);
  const auto b = capture(milliseconds(500), milliseconds(10), "LOGI:FB:SP:0:34#");
  EXPECT_TRUE(compare(a, b, p, "guide").exchanges[2].matches());
  EXPECT_FALSE(compare(a, b, probe(), "guide").exchanges[2].matches());
}

}  // namespace
}  // namespace hil::conform
