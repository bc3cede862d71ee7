// libFuzzer target for the WR8 mock firmware: arbitrary GUI bytes, cut into
// writes at fuzzer-chosen points and times, under the invariants in
// firmware_fuzz_support.hpp (every packet the vehicle sends decodes as a
// vehicle packet, counters that add up, the car inside the arena, no wakeup
// loop). The first input byte picks the byte order and whether a valid AUTH
// comes first, so the authenticated state (tasks, settings, DATA) is
// explored as well as the door.

#include "mocks/wr8.hpp"
#include "protocol/wr8/codec.hpp"
#include "sim/presets.hpp"
#include "tests/fuzz/firmware_fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil;
  namespace wr8 = protocol::wr8;
  if (size == 0) return 0;
  const std::uint8_t flags = data[0];
  mocks::Wr8Config config;
  config.profile.byte_order = (flags & 2) != 0 ? wr8::ByteOrder::big : wr8::ByteOrder::little;
  sim::World world(sim::WorldDef{});
  sim::Vehicle& vehicle = world.add_vehicle(sim::wr8_vehicle());
  mocks::Wr8Firmware firmware(world, vehicle, config);
  protocol::Bytes auth;
  if ((flags & 1) != 0) auth = wr8::encode(wr8::Auth{config.profile.auth_text}, config.profile);
  const auto make_decoder = [&] {
    wr8::DecoderOptions options;
    options.profile = config.profile;
    options.sender = wr8::Sender::vehicle;
    return wr8::Decoder(options);
  };
  fuzz::drive_firmware<wr8::Message>(firmware, make_decoder, auth, {data + 1, size - 1});
  return 0;
}
