#pragma once
// The bench the WR8 firmware tests share: a GUI connected to the car on
// mem:// that decodes every packet with the virtual time it arrived, the
// answers to requests in order, and DATA values and settings as the default
// profile presents them.

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "mocks/wr8.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/wr8/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks::test {

namespace wr8 = protocol::wr8;

/// One packet the client received, and when.
struct Packet {
  link::Time at{};
  wr8::Message message;
};

/// A WR8 car on mem:// and a GUI connected to it (at 1 ms) that decodes
/// everything the car sends, with the virtual time it arrived.
class Wr8Gui {
 public:
  explicit Wr8Gui(Wr8Config config = {}, ServerOptions options = {})
      : config_(config),
        car_(
            sim::wr8_vehicle(),
            [config](sim::World& w, sim::Vehicle& v) {
              return std::make_unique<Wr8Firmware>(w, v, config);
            },
            std::move(options)),
        decoder_(vehicle_side(config)) {
    client_ = car_.connect();
  }

  static wr8::DecoderOptions vehicle_side(const Wr8Config& config) {
    wr8::DecoderOptions options;
    options.profile = config.profile;
    options.sender = wr8::Sender::vehicle;
    return options;
  }

  /// Writes a packet now; what the car answers at once is collected.
  void send(const wr8::Message& m) { send_bytes(wr8::encode(m, config_.profile)); }
  /// Sends what encode() would refuse (wrong parameter counts).
  void send_unchecked(const wr8::Message& m) {
    send_bytes(wr8::encode_unchecked(m, config_.profile));
  }
  void send_bytes(const protocol::Bytes& bytes) {
    client_->write(protocol::ByteView(bytes));
    run_until(car_.now());
  }
  void task(std::uint8_t coi, wr8::TaskCode code, std::vector<wr8::Word> params = {}) {
    send(wr8::Task{coi, code, std::move(params)});
  }
  void drive(std::uint8_t coi, std::int32_t cm) {
    task(coi, wr8::TaskCode::drive, {wr8::Word::from_i32(cm)});
  }
  void turn(std::uint8_t coi, std::int32_t deg) {
    task(coi, wr8::TaskCode::turn, {wr8::Word::from_i32(deg)});
  }
  void settings(std::uint8_t coi, std::vector<wr8::Setting> entries) {
    send(wr8::Settings{coi, std::move(entries)});
  }
  void authenticate() {
    send(wr8::Auth{config_.profile.auth_text});
    ASSERT_FALSE(log_.empty());
    ASSERT_TRUE(std::holds_alternative<wr8::AuthReply>(log_.back().message));
  }

  /// Authenticates and forgets the bytes received so far, for a test that
  /// reads the raw bytes (client(), take_hex()).
  void authenticate_raw() {
    authenticate();
    client().take();
  }
  /// The bytes received since the last look, in hex.
  std::string take_hex() { return protocol::to_hex(client().take()); }

  /// Authenticates, runs to `t` and forgets what arrived so far.
  void settle(link::Time t) {
    authenticate();
    run_until(t);
    take();
  }

  /// Runs every event up to `t`, recording each packet at its exact time.
  void run_until(link::Time t) {
    car_.run_until_each(t, [this] { collect(); });
  }
  void run_for(link::Duration d) { run_until(car_.now() + d); }

  /// Packets received so far (and forgets them).
  std::vector<Packet> take() { return std::exchange(log_, {}); }

  link::Time now() const { return car_.now(); }
  VirtualCar<Wr8Firmware>& car() { return car_; }
  Wr8Firmware& fw() { return car_.firmware(); }
  const Wr8State& state() { return car_.firmware().state(); }
  sim::Vehicle& vehicle() { return car_.vehicle(); }
  sim::AckermannChassis& chassis() { return *car_.vehicle().ackermann(); }
  ClientEnd& client() { return *client_; }
  const Wr8Config& config() const { return config_; }

 private:
  void collect() {
    const protocol::Bytes bytes = client_->take();
    decode_frames<wr8::Message>(
        decoder_, bytes, "the car sent bytes a GUI cannot decode: ", [this](const auto& frame) {
          log_.push_back(Packet{car_.now(), frame.message});
        });
  }

  Wr8Config config_;
  VirtualCar<Wr8Firmware> car_;
  std::shared_ptr<ClientEnd> client_;
  wr8::Decoder decoder_;
  std::vector<Packet> log_;
};

template <class T>
std::vector<std::pair<link::Time, T>> select(const std::vector<Packet>& packets) {
  std::vector<std::pair<link::Time, T>> out;
  for (const Packet& p : packets) {
    if (const auto* m = std::get_if<T>(&p.message)) out.emplace_back(p.at, *m);
  }
  return out;
}

/// The answers to requests, in order, as (time ms, COI, code).
struct Answer {
  std::int64_t at_ms;
  std::uint8_t coi;
  wr8::ResponseCode code;
  friend bool operator==(const Answer&, const Answer&) = default;
};

inline std::ostream& operator<<(std::ostream& os, const Answer& a) {
  return os << "{" << a.at_ms << " ms, coi " << int{a.coi} << ", " << wr8::to_string(a.code) << "}";
}

inline std::vector<Answer> answers(const std::vector<Packet>& packets) {
  std::vector<Answer> out;
  for (const auto& [t, r] : select<wr8::Response>(packets))
    out.push_back(Answer{ms_of(t), r.coi, r.code});
  return out;
}

constexpr auto kError = wr8::ResponseCode::error;
constexpr auto kStarted = wr8::ResponseCode::started;
constexpr auto kCompleted = wr8::ResponseCode::completed;

/// A DATA value in the default profile's presentation.
inline double value(const wr8::Data& data, std::uint8_t code) {
  for (const auto& v : data.values) {
    if (v.code != code) continue;
    switch (code) {
      case wr8::data_code::odometry:
        return v.value.as_i32();
      case wr8::data_code::speed:
      case wr8::data_code::wheel_angle:
        return static_cast<double>(v.value.as_f32());
      default:
        return v.value.bits;
    }
  }
  ADD_FAILURE() << "DATA without parameter " << int{code};
  return 0;
}

inline wr8::Setting setting(wr8::SettingCode code, float v) {
  return {code, wr8::Word::from_f32(v)};
}
inline wr8::Setting servo_zero(std::int32_t deg) {
  return {wr8::SettingCode::servo_zero, wr8::Word::from_i32(deg)};
}

}  // namespace hil::mocks::test
