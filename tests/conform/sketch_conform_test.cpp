// hil's own Arduino sketch on the emulated ATmega328P, probed in virtual
// time and checked against the behavioural mock's profiles: the two
// implementations of the real sketch's protocol, compared exchange by
// exchange as a real board's capture would be.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "conform/check.hpp"
#include "conform/probe.hpp"

namespace hil::conform {
namespace {

Capture probe_sketch() {
  mocks::CarOptions options;
  options.kind = mocks::CarKind::arduino;
  mocks::AvrConfig avr;
  avr.elf = HIL_TEST_SKETCH_ELF;
  options.configs.avr = avr;
  const auto probe = make_probe(mocks::CarKind::arduino, "firmware");
  return probe_in_virtual_time(probe, std::move(options), "sketch:hil_arduino");
}

TEST(SketchConform, TheSketchOnTheEmulatedBoardPlaysTheFirmwareProfile) {
  const Capture capture = probe_sketch();
  const CheckResult result = check(capture);
  ASSERT_FALSE(result.ranking().empty());
  EXPECT_EQ(result.ranking().front(), "firmware");
  const Comparison& firmware = result.of("firmware");
  std::set<std::string> differing;
  for (const auto& e : firmware.exchanges)
    if (!e.matches()) differing.insert(e.name);
  // All 46 exchanges of arduino-probe/1, bytes, silences and latencies
  // (within the check's 50 ms / 50 %) alike.
  EXPECT_EQ(firmware.exchanges.size(), 46U);
  EXPECT_EQ(differing, (std::set<std::string>{}));
  // And the other profile is told apart, as for a real board.
  EXPECT_LT(result.of("readme").matches(), firmware.matches());
}

TEST(SketchConform, TheProbeOfTheEmulatedBoardIsDeterministic) {
  EXPECT_EQ(probe_sketch(), probe_sketch());
}

}  // namespace
}  // namespace hil::conform
