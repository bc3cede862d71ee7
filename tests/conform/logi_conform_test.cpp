// The LOGI probe against hil's mock in each profile, in virtual time: the
// mock in one profile plays the car, and a check against the other lists
// exactly the cuts of the stream on which the guide's stream rule and the
// STM32's hand-over parser disagree (docs/protocols/logi.md, "Where the
// two differ"), and nothing else.
#include <gtest/gtest.h>

#include "tests/conform/conform_support.hpp"

namespace hil::conform {
namespace {

using mocks::CarKind;
using test::differing;

TEST(LogiConform, EachProfileMatchesItself) {
  for (const char* profile : {"guide", "firmware"}) {
    EXPECT_EQ(differing(CarKind::logi, profile, profile), std::set<std::string>{}) << profile;
  }
}

TEST(LogiConform, TheProbeIsDeterministicInVirtualTime) {
  const auto probe = make_probe(CarKind::logi, "guide");
  EXPECT_EQ(probe_mock(probe, "guide", 7), probe_mock(probe, "guide", 7));
}

// The same set both ways: each names a row of the table of differences.
const std::set<std::string> kGuideVersusFirmware = {
    "garbage-before",    // bytes before LOGI: are part of the hand-over, so its sum is wrong
    "crlf-after",        // the hand-over's last byte is LF, not '#'
    "two-in-one-write",  // one hand-over, one checksum field after the last ':'
    "split-in-two",      // 9 bytes, then a hand-over without the header
    "split-in-bytes",    // every hand-over is one byte
    "hash-inside",       // the firmware takes the whole write, the stream cuts at the first '#'
};

TEST(LogiConform, GuideAgainstFirmwareDiffersWhereTheParsersDo) {
  EXPECT_EQ(differing(CarKind::logi, "guide", "firmware"), kGuideVersusFirmware);
  EXPECT_EQ(differing(CarKind::logi, "firmware", "guide"), kGuideVersusFirmware);
}

TEST(LogiConform, AllProfilesRanksTheProbedOneFirst) {
  for (const char* profile : {"guide", "firmware"}) {
    const auto probe = make_probe(CarKind::logi, profile);
    const auto result = check(probe_mock(probe, profile));
    EXPECT_EQ(result.ranking().front(), profile);
    EXPECT_TRUE(result.of(profile).all_match());
    for (const auto& comparison : result.by_profile) {
      for (const auto& row : comparison.exchanges) {
        if (row.matches()) continue;
        // Every difference is explained by the profile the car plays.
        EXPECT_EQ(row.explained_by, std::vector<std::string>{profile}) << row.name;
      }
    }
  }
}

}  // namespace
}  // namespace hil::conform
