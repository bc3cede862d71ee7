// Arduino decoder throughput: a request/response conversation as it crosses
// the serial link, each request followed by its ACK or NACK.

#include "bench/bench_support.hpp"
#include "protocol/arduino/codec.hpp"

void hil_register_arduino_benchmarks() {
  namespace ard = hil::protocol::arduino;
  hil::bench::register_decoder<ard::Decoder, ard::Message>("arduino", [](std::size_t i) {
    const auto seq = static_cast<std::uint8_t>(i / 2);
    if (i % 2 == 1) {
      // Every answer but one in sixteen is an ACK with a short info text.
      if (i % 32 == 31) return ard::encode({seq, ard::Nack{ard::NackCode::bad_cs}});
      return ard::encode({seq, ard::Ack{i % 6 == 1 ? "OK" : "dist=" + std::to_string(i % 400)}});
    }
    switch ((i / 2) % 6) {
      case 0:
        return ard::encode({seq, ard::SetSpeed{static_cast<int>(i % 256)}});
      case 1:
        return ard::encode({seq, ard::Move{static_cast<int>(i % 200) - 100}});
      case 2:
        return ard::encode({seq, ard::Rotate{static_cast<int>(i % 360) - 180}});
      case 3:
        return ard::encode({seq, ard::SonarRead{}});
      case 4:
        return ard::encode({seq, ard::StatusRequest{}});
      default:
        return ard::encode({seq, ard::Ping{}});
    }
  });
}
