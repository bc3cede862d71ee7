// Leka decoder throughput: a master's command stream, from one-command
// frames (info, stops, motor updates) to full 20-LED belt frames.

#include "bench/bench_support.hpp"
#include "protocol/leka/codec.hpp"

void hil_register_leka_benchmarks() {
  namespace leka = hil::protocol::leka;
  hil::bench::register_decoder<leka::Decoder, leka::Message>("leka", [](std::size_t i) {
    const auto v = static_cast<std::uint8_t>(i);
    leka::CommandGroup g;
    switch (i % 5) {
      case 0:
        g.commands = {leka::MotorDuo{0, v, 1, static_cast<std::uint8_t>(255 - v)}};
        break;
      case 1:
        g.commands = {leka::EarAll{leka::Rgb{v, 0, 255}}, leka::MotorAll{1, 200}};
        break;
      case 2:
        g.commands = {leka::Info{}};
        break;
      case 3:
        for (std::uint8_t led = 0; led < 20; ++led) {
          g.commands.push_back(
              leka::BeltSingle{led, leka::Rgb{v, led, static_cast<std::uint8_t>(led * 12)}});
        }
        break;
      default:
        g.commands = {leka::BeltRange{2, 9, leka::Rgb{0, v, 0}}, leka::Motivator{0x53},
                      leka::StopMotor{}};
        break;
    }
    return leka::encode(g);
  });
}
