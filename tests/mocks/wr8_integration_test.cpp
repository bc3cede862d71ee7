// The WR8 mock firmware behind a MockServer on real TCP (127.0.0.1, a free
// port) under the real-time driver: a GUI authenticates, drives 100 cm and
// watches DATA; a wrong string gets the connection closed. Waits are bounded
// and generous; nothing asserts how fast the machine is.

#include <gtest/gtest.h>

#include <asio/io_context.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <system_error>
#include <vector>

#include "link/endpoint.hpp"
#include "mocks/wr8.hpp"
#include "protocol/wr8/codec.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/mock_test_support.hpp"
#include "tests/mocks/real_time_car.hpp"

namespace hil::mocks {
namespace {

namespace wr8 = protocol::wr8;
using std::chrono::seconds;

/// A WR8 car listening on tcp://127.0.0.1:0 and a GUI connected to it over
/// a real socket, decoding what the car sends.
class TcpCar {
 public:
  explicit TcpCar(Wr8Config config = {})
      : config_(config),
        car_(sim::wr8_vehicle(), test::listening_on("tcp://127.0.0.1:0", "wr8"), config) {
    EXPECT_TRUE(test::connect_and_wait(car_, pipe_,
                                       {[this](protocol::ByteView b) { on_data(b); },
                                        [this](std::error_code why) { closed_ = why; }},
                                       [this](std::error_code ec) { closed_ = ec; }))
        << "could not connect to " << car_.server.address();
  }

  ~TcpCar() {
    if (pipe_) pipe_->close();
    car_.server.close();
    link::test::run_for(car_.io, std::chrono::milliseconds(20));
  }

  void send(const wr8::Message& m) {
    if (pipe_) pipe_->write(wr8::encode(m, config_.profile));
  }

  bool wait_for(const std::function<bool()>& done, std::chrono::milliseconds limit = seconds(10)) {
    return link::test::run_until(car_.io, done, limit);
  }
  void run_for(std::chrono::milliseconds d) { link::test::run_for(car_.io, d); }

  /// The first response with this COI and code, if it has come.
  std::optional<std::size_t> response_index(std::uint8_t coi, wr8::ResponseCode code) const {
    for (std::size_t n = 0; n < received_.size(); ++n) {
      const auto* r = std::get_if<wr8::Response>(&received_[n]);
      if (r != nullptr && r->coi == coi && r->code == code) return n;
    }
    return std::nullopt;
  }
  template <class T>
  std::vector<T> all() const {
    std::vector<T> out;
    for (const auto& m : received_) {
      if (const auto* t = std::get_if<T>(&m)) out.push_back(*t);
    }
    return out;
  }

  const std::vector<wr8::Message>& received() const { return received_; }
  std::size_t decode_errors() const { return decode_errors_; }
  const std::optional<std::error_code>& closed() const { return closed_; }
  Wr8Firmware& firmware() { return car_.firmware; }
  sim::Vehicle& vehicle() { return car_.vehicle; }
  const Wr8Config& config() const { return config_; }

 private:
  void on_data(protocol::ByteView bytes) {
    std::vector<wr8::Item> items;
    decoder_.feed(bytes, items);
    for (auto& item : items) {
      if (auto* f = std::get_if<protocol::Frame<wr8::Message>>(&item)) {
        received_.push_back(std::move(f->message));
      } else {
        ++decode_errors_;
      }
    }
  }

  Wr8Config config_;
  test::RealTimeCar<Wr8Firmware> car_;
  link::BytePipePtr pipe_;
  std::optional<std::error_code> closed_;
  wr8::Decoder decoder_{wr8::DecoderOptions{config_.profile, wr8::Sender::vehicle, 0}};
  std::vector<wr8::Message> received_;
  std::size_t decode_errors_ = 0;
};

double odometry_cm(const wr8::Data& d) {
  for (const auto& v : d.values) {
    if (v.code == wr8::data_code::odometry) return v.value.as_i32();
  }
  return -1;
}

TEST(Wr8OverTcp, AuthenticatesAndDrives100Cm) {
  TcpCar car;
  car.send(wr8::Auth{car.config().profile.auth_text});
  ASSERT_TRUE(car.wait_for([&] { return !car.all<wr8::AuthReply>().empty(); }));
  EXPECT_EQ(car.all<wr8::AuthReply>().front(), (wr8::AuthReply{8, 1, wr8::State::stop}));

  car.send(wr8::Task{1, wr8::TaskCode::drive, {wr8::Word::from_i32(100)}});
  ASSERT_TRUE(
      car.wait_for([&] { return car.response_index(1, wr8::ResponseCode::started).has_value(); }));
  // About 3.3 s of driving; the limit leaves room for a slow machine.
  ASSERT_TRUE(
      car.wait_for([&] { return car.response_index(1, wr8::ResponseCode::completed).has_value(); },
                   seconds(30)));
  EXPECT_LT(*car.response_index(1, wr8::ResponseCode::started),
            *car.response_index(1, wr8::ResponseCode::completed));
  EXPECT_FALSE(car.response_index(1, wr8::ResponseCode::error).has_value());
  EXPECT_GE(car.vehicle().odometry().distance_m, 1.0);

  // The DATA after the answer reports the distance (and STOP).
  const std::size_t done_at = *car.response_index(1, wr8::ResponseCode::completed);
  std::optional<wr8::Data> after;
  ASSERT_TRUE(car.wait_for([&] {
    for (std::size_t n = done_at + 1; n < car.received().size(); ++n) {
      if (const auto* d = std::get_if<wr8::Data>(&car.received()[n])) {
        after = *d;
        return true;
      }
    }
    return false;
  }));
  EXPECT_GE(odometry_cm(*after), 100);
  EXPECT_EQ(after->state, wr8::State::stop);
  EXPECT_EQ(car.decode_errors(), 0u);
}

TEST(Wr8OverTcp, DataArrivesAtAboutTenHertz) {
  TcpCar car;
  car.send(wr8::Auth{car.config().profile.auth_text});
  ASSERT_TRUE(car.wait_for([&] { return !car.all<wr8::AuthReply>().empty(); }));
  car.run_for(std::chrono::milliseconds(2000));
  const auto data = car.all<wr8::Data>();
  EXPECT_GE(data.size(), 5u);
  // Timestamps (when each DATA went out) go forward.
  for (std::size_t n = 0; n < data.size(); ++n) {
    if (n > 0) {
      EXPECT_GT(data[n].timestamp_ms, data[n - 1].timestamp_ms);
    }
    EXPECT_EQ(data[n].state, wr8::State::stop);
  }
  EXPECT_EQ(car.decode_errors(), 0u);
}

TEST(Wr8OverTcp, AWrongStringClosesTheConnection) {
  TcpCar car;
  car.send(wr8::Auth{});  // ten zero bytes
  ASSERT_TRUE(car.wait_for([&] { return car.closed().has_value(); }));
  EXPECT_EQ(*car.closed(), link::end_of_stream());
  EXPECT_TRUE(car.received().empty());
  EXPECT_EQ(car.firmware().state().auth_failures, 1u);
  EXPECT_TRUE(car.wait_for([&] { return !car.firmware().connected(); }));
}

}  // namespace
}  // namespace hil::mocks
