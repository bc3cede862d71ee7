// libFuzzer target for the Arduino mock firmware (profile readme): arbitrary client bytes,
// cut into writes at fuzzer-chosen points and times, under the invariants in
// firmware_fuzz_support.hpp (every answer a valid Arduino frame, counters
// that add up, the robot inside the arena, no wakeup loop).

#include "mocks/arduino.hpp"
#include "protocol/arduino/codec.hpp"
#include "sim/presets.hpp"
#include "tests/fuzz/firmware_fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil;
  sim::World world(sim::WorldDef{});
  sim::Vehicle& vehicle = world.add_vehicle(sim::arduino_robot());
  // The README's board: every answer of it decodes. The real sketch
  // (the default profile) echoes whatever two bytes stand where a SEQ
  // belongs (`^zz|NACK|BAD_CS*..$`), which the strict decoder refuses.
  mocks::ArduinoConfig config;
  config.dialect = protocol::arduino::Dialect::readme;
  mocks::ArduinoFirmware firmware(world, vehicle, config);
  fuzz::drive_firmware<protocol::arduino::Message>(
      firmware, [] { return protocol::arduino::Decoder(); }, {}, {data, size});
  return 0;
}
