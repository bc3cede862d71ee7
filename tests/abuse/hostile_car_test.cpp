// The reference clients' cores under a hostile car: random bytes, garbage
// between valid frames, overlong frames, a frame that never ends, and
// answers that fail their checksum. The client keeps working, reports the
// errors, and never takes a damaged answer as a confirmation, so it never
// moves the car because of one.

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "client/arduino/core.hpp"
#include "client/leka/core.hpp"
#include "client/logi/core.hpp"
#include "client/wr8/core.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/logi/codec.hpp"

namespace hil::test {
namespace {

using link::milliseconds;
using link::seconds;
using link::Time;

protocol::ByteView view(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

std::string random_text(std::mt19937_64& rng, std::size_t n) {
  std::string out(n, '\0');
  for (auto& c : out)
    c = static_cast<char>(rng() & 0xFF);
  return out;
}

/// The hostile streams every client gets: {name, bytes}.
std::vector<std::pair<std::string, std::string>> hostile_streams(std::uint64_t seed,
                                                                 const std::string& start,
                                                                 const std::string& valid) {
  std::mt19937_64 rng(seed);
  std::string garbage_between;
  for (int i = 0; i < 200; ++i)
    garbage_between += random_text(rng, 1 + rng() % 40) + valid;
  return {{"random bytes", random_text(rng, 4 << 20)},
          {"garbage between valid frames", garbage_between},
          {"an overlong frame", start + std::string(4096, 'A') + valid},
          {"a frame that never ends", start + std::string(4 << 20, 'A')}};
}

/// Hands `bytes` to `car`'s client core 4 KiB at a time, taking what each
/// piece made it do.
template <class Car>
void feed(Car& car, const std::string& bytes) {
  for (std::size_t at = 0; at < bytes.size(); at += 4096) {
    car.core.on_bytes(car.now, view(bytes.substr(at, 4096)));
    car.collect();
  }
}

// ---------------------------------------------------------------- LOGI

namespace logi = client::logi;

std::string logi_fb(const std::string& sent, bool good) {
  // "LOGI:SP:050:D7#" -> payload "FB:SP:1" with a right or wrong checksum.
  const std::string cmd = sent.substr(5, 2);
  std::string frame = protocol::logi::frame_text("FB:" + cmd + ":1");
  if (!good) frame[frame.size() - 2] = frame[frame.size() - 2] == '0' ? '1' : '0';
  return frame;
}

struct LogiCar {
  logi::LogiClientCore core;
  Time now{0};
  std::vector<std::string> sent;
  int parse_errors = 0;
  int accepted = 0;

  void collect() {
    for (auto& a : core.take_actions())
      if (auto* s = std::get_if<logi::SendBytes>(&a)) sent.push_back(s->text);
    for (auto& e : core.take_events()) {
      if (std::holds_alternative<logi::ParseErrorEvent>(e)) ++parse_errors;
      if (auto* c = std::get_if<logi::CommandEvent>(&e);
          c != nullptr && c->state == logi::CommandState::accepted)
        ++accepted;
    }
  }
  /// Connects and takes what connecting did.
  void open_link() {
    core.connect(now);
    core.on_connected(now);
    collect();
  }
  void run_for(link::Duration d) {
    const Time end = now + d;
    while (now < end) {
      now += milliseconds(10);
      if (auto w = core.next_wakeup(); w && *w <= now) core.on_timer(now);
      collect();
    }
  }
  bool sent_movement() const {
    for (const auto& s : sent)
      if (s.rfind("LOGI:MV:", 0) == 0 && s.rfind("LOGI:MV:STOP", 0) != 0) return true;
    return false;
  }
};

TEST(HostileCar, LogiClientNeverTakesADamagedFeedbackAsConfirmation) {
  LogiCar car;
  car.open_link();
  ASSERT_TRUE(car.core.submit(car.now, protocol::logi::SetMode{protocol::logi::Mode::manual}));
  ASSERT_TRUE(car.core.submit(car.now, protocol::logi::SetSpeed{50}));
  // Forward, queued behind MD and SP: it goes out only once they are
  // settled, so a damaged FB taken as "accepted" would send it early.
  ASSERT_TRUE(car.core.press(car.now, protocol::logi::Direction::fwd));
  car.collect();
  // Every command is answered FB:x:1, but with a wrong checksum.
  int damaged = 0;
  std::size_t first_move = 0;
  for (int step = 0; step < 1000 && first_move == 0; ++step) {
    const std::size_t before = car.sent.size();
    car.run_for(milliseconds(10));
    for (std::size_t i = before; i < car.sent.size(); ++i) {
      if (car.sent[i].rfind("LOGI:MV:FWD", 0) == 0) {
        first_move = i;
        break;
      }
      car.core.on_bytes(car.now, view(logi_fb(car.sent[i], false)));
      ++damaged;
    }
    car.collect();
  }
  EXPECT_EQ(car.accepted, 0) << "a damaged FB counted as accepted";
  EXPECT_EQ(car.parse_errors, damaged) << "each damaged FB is reported once";
  // MD and SP were each sent three times (two retries): the damaged FBs
  // settled nothing, and forward waited for the retries to run out.
  int md = 0;
  int sp = 0;
  for (std::size_t i = 0; i < first_move; ++i) {
    md += car.sent[i].rfind("LOGI:MD:", 0) == 0 ? 1 : 0;
    sp += car.sent[i].rfind("LOGI:SP:", 0) == 0 ? 1 : 0;
  }
  EXPECT_EQ(md, 3) << damaged;
  EXPECT_EQ(sp, 3) << damaged;

  // Answered correctly, the same commands are accepted at once.
  LogiCar good;
  good.core.connect(good.now);
  good.core.on_connected(good.now);
  ASSERT_TRUE(good.core.submit(good.now, protocol::logi::SetSpeed{50}));
  good.collect();
  ASSERT_FALSE(good.sent.empty());
  good.core.on_bytes(good.now, view(logi_fb(good.sent.back(), true)));
  good.collect();
  EXPECT_EQ(good.accepted, 1);
  EXPECT_EQ(good.parse_errors, 0);
}

TEST(HostileCar, LogiClientSurvivesHostileStreamsAndReportsThem) {
  const std::uint64_t seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  const std::string stat = protocol::logi::encode_text(protocol::logi::Status{});
  for (const auto& [name, bytes] : hostile_streams(seed, "LOGI:", stat)) {
    SCOPED_TRACE(name);
    LogiCar car;
    car.open_link();
    feed(car, bytes);
    EXPECT_GT(car.parse_errors, 0);
    EXPECT_FALSE(car.sent_movement());
    // Still reading: a STAT after the stream is taken.
    car.core.on_bytes(car.now, view(std::string("#") + stat));
    car.collect();
    EXPECT_TRUE(car.core.last_status().has_value());
  }
}

// ---------------------------------------------------------------- Arduino

namespace ard = client::arduino;

struct ArduinoCar {
  ard::ArduinoClientCore core;
  Time now{0};
  std::vector<std::string> sent;
  std::vector<ard::Result> done;
  int invalid_frames = 0;

  void collect() {
    for (auto& a : core.take_actions())
      if (auto* s = std::get_if<ard::SendFrame>(&a))
        sent.emplace_back(s->bytes.begin(), s->bytes.end());
    for (auto& e : core.take_events()) {
      if (auto* d = std::get_if<ard::RequestDone>(&e)) done.push_back(d->result);
      if (auto* f = std::get_if<ard::FrameReceived>(&e); f != nullptr && !f->valid)
        ++invalid_frames;
    }
  }
  /// Opens the port and takes what opening did.
  void open_link() {
    core.open(now);
    core.on_connected(now);
    collect();
  }
  void step(link::Duration d) {
    now += d;
    if (auto w = core.next_wakeup(); w && *w <= now) core.on_timer(now);
    collect();
  }
};

/// The ACK the robot gives to a sent frame, with a right or wrong checksum.
std::string arduino_ack(const std::string& sent, bool good) {
  const auto seq = static_cast<std::uint8_t>(std::stoi(sent.substr(1, 2), nullptr, 16));
  std::string frame = protocol::arduino::frame_text({seq, "ACK", ""});
  if (!good) frame[frame.size() - 2] = frame[frame.size() - 2] == '0' ? '1' : '0';
  return frame;
}

TEST(HostileCar, ArduinoClientNeverMovesOnADamagedAck) {
  ArduinoCar car;
  car.open_link();
  car.core.set_v(car.now, 160);
  car.core.move_cm(car.now, 50);
  car.collect();
  int damaged = 0;
  // Every frame is ACKed with a wrong checksum until the speed request ends.
  for (int i = 0; i < 2000 && car.done.empty(); ++i) {
    const std::size_t before = car.sent.size();
    car.step(milliseconds(10));
    for (std::size_t k = before; k < car.sent.size(); ++k) {
      car.core.on_bytes(car.now, view(arduino_ack(car.sent[k], false)));
      ++damaged;
    }
    car.collect();
    for (const auto& s : car.sent)
      ASSERT_EQ(s.find("|M|"), std::string::npos) << "moved while V was unconfirmed: " << s;
  }
  ASSERT_FALSE(car.done.empty());
  EXPECT_NE(car.done.front().code, ard::ResultCode::ok) << "a damaged ACK confirmed V";
  EXPECT_GT(damaged, 0);
  EXPECT_GE(car.core.parse_errors() + static_cast<std::uint64_t>(car.invalid_frames), 1u);
}

TEST(HostileCar, ArduinoClientSurvivesHostileStreams) {
  const std::uint64_t seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  for (const auto& [name, bytes] :
       hostile_streams(seed, "^", protocol::arduino::frame_text({7, "ACK", ""}))) {
    SCOPED_TRACE(name);
    ArduinoCar car;
    car.open_link();
    feed(car, bytes);
    EXPECT_GT(car.core.parse_errors() + car.core.stale_frames(), 0u);
    for (const auto& s : car.sent)
      EXPECT_EQ(s.find("|M|"), std::string::npos);
    // Still answering: a PING gets its ACK.
    car.core.ping(car.now);
    car.collect();
    ASSERT_FALSE(car.sent.empty());
    car.core.on_bytes(car.now, view("$" + arduino_ack(car.sent.back(), true)));
    car.collect();
    ASSERT_FALSE(car.done.empty());
    EXPECT_EQ(car.done.back().code, ard::ResultCode::ok);
  }
}

// ---------------------------------------------------------------- WR8, Leka

TEST(HostileCar, Wr8AndLekaClientsSurviveHostileStreams) {
  const std::uint64_t seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  for (const auto& [name, bytes] : hostile_streams(seed, "\x02", "\x02\x01")) {
    SCOPED_TRACE(name);
    client::wr8::Wr8ClientCore wr8;
    wr8.connect(Time{0});
    wr8.on_connected(Time{0});
    client::leka::LekaClientCore leka;
    leka.on_connected(Time{0});
    int wr8_errors = 0;
    for (std::size_t at = 0; at < bytes.size(); at += 4096) {
      wr8.on_bytes(Time{0}, view(bytes.substr(at, 4096)));
      leka.on_bytes(Time{0}, view(bytes.substr(at, 4096)));
      for (const auto& e : wr8.take_events())
        if (std::holds_alternative<client::wr8::ParseErrorEvent>(e)) ++wr8_errors;
      leka.take_events();
    }
    wr8.on_timer(seconds(1));
    leka.on_timer(seconds(1));
    EXPECT_GT(wr8_errors, 0) << "the WR8 client reports what it cannot decode";
  }
}

}  // namespace
}  // namespace hil::test
