// WR8 decoder throughput: what a GUI receives from a vehicle, mostly DATA
// telemetry with all four parameters, some RESPONSE and a SETTINGS reply.

#include "bench/bench_support.hpp"
#include "protocol/wr8/codec.hpp"

void hil_register_wr8_benchmarks() {
  namespace wr8 = hil::protocol::wr8;
  hil::bench::register_decoder<wr8::Decoder, wr8::Message>("wr8", [](std::size_t i) {
    const auto coi = static_cast<std::uint8_t>(i);
    if (i % 10 == 3) return wr8::encode(wr8::Response{coi, wr8::ResponseCode::completed});
    if (i % 50 == 7) {
      return wr8::encode(wr8::Settings{coi,
                                       {{wr8::SettingCode::p, wr8::Word::from_f32(1.5f)},
                                        {wr8::SettingCode::i, wr8::Word::from_f32(0.25f)},
                                        {wr8::SettingCode::d, wr8::Word::from_f32(0.05f)},
                                        {wr8::SettingCode::servo_zero, wr8::Word::from_i32(90)}}});
    }
    wr8::Data d;
    d.state = wr8::State::run;
    d.timestamp_ms = static_cast<std::uint32_t>(i * 50);  // 20 Hz telemetry
    d.values = {
        {wr8::data_code::odometry, wr8::Word::from_i32(static_cast<std::int32_t>(i % 5000))},
        {wr8::data_code::speed, wr8::Word::from_f32(static_cast<float>(i % 20) / 10.0f)},
        {wr8::data_code::wheel_angle, wr8::Word::from_f32(static_cast<float>(i % 61) - 30.0f)},
        {wr8::data_code::battery, wr8::Word{static_cast<std::uint32_t>(100 - i % 100)}}};
    return wr8::encode(d);
  });
}
