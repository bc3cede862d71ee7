// LOGI decoder throughput: a stream of STAT telemetry and commands.

#include "bench/bench_support.hpp"
#include "protocol/logi/codec.hpp"

void hil_register_logi_benchmarks() {
  namespace logi = hil::protocol::logi;
  hil::bench::register_decoder<logi::Decoder, logi::Message>("logi", [](std::size_t i) {
    if (i % 4 != 0) return logi::encode(logi::Move{logi::kAllDirections[i % 11]});
    logi::Status s;
    s.speed_percent = static_cast<int>(i % 101);
    s.station = 2;
    s.running = true;
    s.distance_cm = static_cast<int>(i % 400);
    s.track_mask = static_cast<std::uint8_t>(i % 16);
    s.deviation = static_cast<int>(i % 7) - 3;
    s.rpm = {120, 121, -119, static_cast<int>(i % 200)};
    return logi::encode(s);
  });
}
