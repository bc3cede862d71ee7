// libFuzzer target for the LOGI mock firmware: arbitrary client bytes, cut
// into writes at fuzzer-chosen points and times, under the invariants in
// firmware_fuzz_support.hpp (every answer a valid LOGI frame, counters that
// add up, the car inside the arena, no wakeup loop).

#include "mocks/logi.hpp"
#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"
#include "tests/fuzz/firmware_fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil;
  sim::World world(sim::WorldDef{});
  sim::Vehicle& vehicle = world.add_vehicle(sim::logi_car());
  mocks::LogiFirmware firmware(world, vehicle);
  fuzz::drive_firmware<protocol::logi::Message>(firmware, [] { return protocol::logi::Decoder(); },
                                                {}, {data, size});
  return 0;
}
