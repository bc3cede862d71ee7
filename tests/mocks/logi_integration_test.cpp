// The LOGI mock car behind a MockServer on real TCP (tcp://127.0.0.1:0)
// under the real-time driver: a client that frames commands and reads the
// car's stream with the codec's decoder drives the source's manual driving
// flow and its auto transport flow to both stations.

#include <gtest/gtest.h>

#include <asio/io_context.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mocks/logi.hpp"
#include "protocol/logi/codec.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/mock_test_support.hpp"
#include "tests/mocks/real_time_car.hpp"

namespace hil::mocks {
namespace {

namespace logi = protocol::logi;
using std::chrono::seconds;

/// The car on a real TCP port and one upper-computer client connected to it.
class TcpCar {
 public:
  TcpCar() {
    EXPECT_TRUE(test::connect_and_wait(car_, pipe_,
                                       {[this](protocol::ByteView b) { decoder_.feed(b, items_); },
                                        [this](std::error_code) { closed_ = true; }}));
  }
  ~TcpCar() {
    if (pipe_) pipe_->close();
    car_.server.close();
  }

  bool connected() const { return pipe_ != nullptr && !closed_; }

  void send_raw(const std::string& bytes) { pipe_->write(protocol::to_bytes(bytes)); }
  void send(std::string_view payload) { send_raw(logi::frame_text(payload)); }

  /// Sends a command and waits (10 s at most) for its feedback; returns the
  /// feedback's payload text, or "timeout".
  std::string command(std::string_view payload) {
    send(payload);
    std::optional<logi::Feedback> answer;
    const bool got = link::test::run_until(car_.io, [&] {
      collect();
      if (!feedback_.empty()) {
        answer = feedback_.front();
        feedback_.erase(feedback_.begin());
      }
      return answer.has_value();
    });
    return got ? logi::payload_of(*answer) : "timeout";
  }

  /// Waits (at most `limit`) for a STAT that satisfies `match`; returns it.
  std::optional<logi::Status> wait_status(const std::function<bool(const logi::Status&)>& match,
                                          std::chrono::milliseconds limit) {
    std::optional<logi::Status> found;
    link::test::run_until(
        car_.io,
        [&] {
          collect();
          for (auto it = status_.begin(); it != status_.end(); ++it) {
            if (match(*it)) {
              found = *it;
              status_.erase(status_.begin(), it + 1);  // later frames stay for the next wait
              return true;
            }
          }
          status_.clear();
          return false;
        },
        limit);
    return found;
  }

  std::size_t status_seen() const { return status_count_; }
  std::uint64_t decode_errors() const { return decode_errors_; }
  LogiFirmware& firmware() { return car_.firmware; }
  sim::Vehicle& vehicle() { return car_.vehicle; }
  asio::io_context& io() { return car_.io; }

 private:
  void collect() {
    for (auto& item : items_) {
      if (auto* f = std::get_if<protocol::Frame<logi::Message>>(&item)) {
        if (auto* fb = std::get_if<logi::Feedback>(&f->message)) feedback_.push_back(*fb);
        if (auto* st = std::get_if<logi::Status>(&f->message)) {
          status_.push_back(*st);
          ++status_count_;
        }
      } else {
        ++decode_errors_;
      }
    }
    items_.clear();
  }

  test::RealTimeCar<LogiFirmware> car_{sim::logi_car(),
                                       test::listening_on("tcp://127.0.0.1:0", "logi")};
  link::BytePipePtr pipe_;
  bool closed_ = false;
  logi::Decoder decoder_;
  std::vector<logi::Item> items_;
  std::vector<logi::Feedback> feedback_;
  std::vector<logi::Status> status_;
  std::size_t status_count_ = 0;
  std::uint64_t decode_errors_ = 0;
};

TEST(LogiOverTcp, ManualDrivingFlow) {
  TcpCar car;
  ASSERT_TRUE(car.connected());
  // Source section 7.1: speed, manual mode, press a direction, release it.
  EXPECT_EQ(car.command("SP:080"), "FB:SP:1");
  EXPECT_EQ(car.command("MD:MAN"), "FB:MD:1");
  const sim::Pose start = car.vehicle().pose();
  EXPECT_EQ(car.command("MV:FWD"), "FB:MV:1");
  const auto driving = car.wait_status(
      [](const logi::Status& s) {
        return s.mode == logi::Mode::manual && s.manual == logi::Direction::fwd && s.rpm[0] > 0 &&
               s.rpm[1] > 0 && s.rpm[2] > 0 && s.rpm[3] > 0;
      },
      std::chrono::seconds(10));
  ASSERT_TRUE(driving.has_value());
  EXPECT_EQ(driving->speed_percent, 80);
  EXPECT_TRUE(
      link::test::run_until(car.io(), [&] { return car.vehicle().pose().x_m > start.x_m + 0.1; }));
  EXPECT_EQ(car.command("MV:STOP"), "FB:MV:1");
  const auto stopped = car.wait_status(
      [](const logi::Status& s) {
        return s.manual == logi::Direction::stop && s.rpm == std::array<int, 4>{0, 0, 0, 0};
      },
      std::chrono::seconds(10));
  ASSERT_TRUE(stopped.has_value());
  const double stopped_x = car.vehicle().pose().x_m;
  EXPECT_GT(stopped_x, start.x_m + 0.1);
  EXPECT_NEAR(car.vehicle().pose().y_m, start.y_m, 0.01);  // straight ahead only

  // A strafe the same way, then stop again.
  EXPECT_EQ(car.command("MV:LEFT"), "FB:MV:1");
  EXPECT_TRUE(
      link::test::run_until(car.io(), [&] { return car.vehicle().pose().y_m > start.y_m + 0.1; }));
  EXPECT_EQ(car.command("MV:STOP"), "FB:MV:1");

  // A corrupted frame is dropped and the session goes on.
  car.send_raw("LOGI:SP:030:D6#");
  EXPECT_EQ(car.command("SP:030"), "FB:SP:1");
  EXPECT_TRUE(car.connected());
  EXPECT_EQ(car.firmware().stats().bad_frames, 1u);
  EXPECT_EQ(car.decode_errors(), 0u);
}

TEST(LogiOverTcp, AutoTransportFlowToBothStations) {
  TcpCar car;
  ASSERT_TRUE(car.connected());
  // Source section 7.2: speed, auto mode, station, run, watch RUN until arrival.
  EXPECT_EQ(car.command("SP:100"), "FB:SP:1");
  EXPECT_EQ(car.command("MD:AUTO"), "FB:MD:1");
  EXPECT_EQ(car.command("MV:FWD"), "FB:MV:0");  // no manual moves in AUTO
  EXPECT_EQ(car.command("GS:001"), "FB:GS:1");
  EXPECT_EQ(car.command("ST:RUN"), "FB:ST:1");
  const auto running = car.wait_status(
      [](const logi::Status& s) { return s.running && s.station == 1; }, std::chrono::seconds(10));
  ASSERT_TRUE(running.has_value());
  EXPECT_EQ(running->mode, logi::Mode::automatic);
  const auto at_001 =
      car.wait_status([](const logi::Status& s) { return !s.running; }, std::chrono::seconds(60));
  ASSERT_TRUE(at_001.has_value());
  EXPECT_EQ(at_001->station, 1);
  EXPECT_EQ(car.firmware().state().last_run_end, LogiRunEnd::arrived);
  EXPECT_NEAR(car.vehicle().pose().x_m, 2.0, 0.15);
  EXPECT_NEAR(car.vehicle().pose().y_m, 0.6, 0.05);

  // The next run needs GS again.
  EXPECT_EQ(car.command("ST:RUN"), "FB:ST:0");
  EXPECT_EQ(car.command("GS:002"), "FB:GS:1");
  EXPECT_EQ(car.command("ST:RUN"), "FB:ST:1");
  const auto to_002 = car.wait_status(
      [](const logi::Status& s) { return s.running && s.station == 2; }, std::chrono::seconds(10));
  ASSERT_TRUE(to_002.has_value());
  const auto at_002 =
      car.wait_status([](const logi::Status& s) { return !s.running; }, std::chrono::seconds(60));
  ASSERT_TRUE(at_002.has_value());
  EXPECT_EQ(at_002->station, 2);
  EXPECT_EQ(car.firmware().state().last_run_end, LogiRunEnd::arrived);
  EXPECT_EQ(car.firmware().state().arrivals, 2u);
  EXPECT_NEAR(car.vehicle().pose().x_m, 2.0, 0.15);
  EXPECT_NEAR(car.vehicle().pose().y_m, 2.4, 0.05);
  EXPECT_EQ(car.command("ST:STOP"), "FB:ST:1");
  EXPECT_GE(car.status_seen(), 4u);
  EXPECT_EQ(car.decode_errors(), 0u);
}

}  // namespace
}  // namespace hil::mocks
