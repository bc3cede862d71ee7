// libFuzzer target for the WR8 vehicle as the real smart_vehicle_gui
// programs play it (mocks/wr8_svgui.hpp): arbitrary GUI bytes, cut into
// writes at fuzzer-chosen points and times, under the invariants in
// firmware_fuzz_support.hpp (every packet the vehicle sends decodes by its
// length byte, counters that add up, the car inside the arena, no wakeup
// loop). The first input byte picks the version and whether the real GUI's
// AUTH comes first.

#include "mocks/wr8_svgui.hpp"
#include "protocol/wr8/svgui.hpp"
#include "sim/presets.hpp"
#include "tests/fuzz/firmware_fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil;
  namespace svgui = protocol::wr8::svgui;
  if (size == 0) return 0;
  const std::uint8_t flags = data[0];
  mocks::SvguiConfig config;
  config.version = (flags & 2) != 0 ? svgui::Version::head : svgui::Version::v2019;
  sim::World world(sim::WorldDef{});
  sim::Vehicle& vehicle = world.add_vehicle(sim::wr8_vehicle());
  mocks::SvguiFirmware firmware(world, vehicle, config);
  protocol::Bytes auth;
  if ((flags & 1) != 0) {
    protocol::Bytes text{'k', 'o', 'n', 'n', 'i', 'c', 'h', 'i', 'w', 'a'};
    if (*config.version == svgui::Version::head) text.push_back(0);
    auth = svgui::encode_prefixed(svgui::Auth{text}, *config.version);
  }
  const auto make_decoder = [&] { return svgui::Decoder(*config.version); };
  fuzz::drive_firmware<svgui::Message>(firmware, make_decoder, auth, {data + 1, size - 1});
  return 0;
}
