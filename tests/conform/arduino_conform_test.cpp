// The Arduino probe against hil's mock in each profile, in virtual time:
// the README's board and the real sketch differ in the payload of a
// request without an argument, in their replies' texts, in how V reads a
// number, and in what the sketch's parser drops silently
// (docs/protocols/arduino.md, "Profiles").
#include <gtest/gtest.h>

#include "tests/conform/conform_support.hpp"

namespace hil::conform {
namespace {

using mocks::CarKind;
using test::differing;

TEST(ArduinoConform, EachProfileMatchesItself) {
  for (const char* profile : {"firmware", "readme"}) {
    EXPECT_EQ(differing(CarKind::arduino, profile, profile), std::set<std::string>{}) << profile;
  }
}

TEST(ArduinoConform, TheProbeIsDeterministicInVirtualTime) {
  const auto probe = make_probe(CarKind::arduino, "firmware");
  EXPECT_EQ(probe_mock(probe, "readme", 3), probe_mock(probe, "readme", 3));
}

// The same set both ways. Ten exchanges match: the connects, the refusals
// both boards word alike (V out of range, an unknown command, a wrong
// checksum, a bad SEQ, two fields) and the silently dropped oversized frame.
const std::set<std::string> kReadmeVersusFirmware = {
    // A request without an argument: the README's board refuses the one-space
    // payload, the sketch the empty one; where both accept it, the answers
    // differ (PONG, CMDS:..., STATUS:V=..., B:<cm>, I:AL=..., STOPPED on the
    // sketch; OK, the command list, IDLE PWM=..., the bare number, L=.. R=..
    // on the README's board).
    "ping-space",
    "ping-empty",
    "help-space",
    "help-empty",
    "status-space",
    "status-empty",
    "b-space",
    "b-empty",
    "i-space",
    "i-empty",
    "s-space",
    "s-empty",
    // V answers OK on the sketch and echoes the value on the README's board.
    "v-160",
    "v-0",
    "v-255",
    "v-100",
    // The sketch reads V with atol, so "abc" is 0 and accepted.
    "v-abc",
    // M and R answer ACCEPTED on the sketch, OK on the README's board; S,
    // STATUS and the requests in the probed form as above.
    "m-20-status",
    "s-after-m",
    "status-after-s",
    "m-minus-10",
    "status-after-rev",
    "r-15",
    "m-0",
    "s-final",
    "lowercase-checksum",
    "after-oversized",
    "garbage-between",
    "two-in-one-write",
    "split-in-bytes",
    "status-after-reconnect",
    "stop",
    // The sketch matches commands in any case; the README's board does not.
    "lowercase-command",
    // The sketch ignores a fourth field.
    "fourth-field",
    // The sketch drops a frame whose checksum field is not two characters,
    // and one under 7 bytes, without a word; the README's board says BAD_FMT.
    "one-char-checksum",
    "short-frame",
};

TEST(ArduinoConform, ReadmeAgainstFirmwareDiffersWhereTheBoardsDo) {
  EXPECT_EQ(differing(CarKind::arduino, "readme", "firmware"), kReadmeVersusFirmware);
  EXPECT_EQ(differing(CarKind::arduino, "firmware", "readme"), kReadmeVersusFirmware);
}

TEST(ArduinoConform, AllProfilesRanksTheProbedOneFirst) {
  for (const char* profile : {"firmware", "readme"}) {
    const auto probe = make_probe(CarKind::arduino, profile);
    const auto result = check(probe_mock(probe, profile));
    EXPECT_EQ(result.ranking().front(), profile);
    EXPECT_TRUE(result.of(profile).all_match());
  }
}

}  // namespace
}  // namespace hil::conform
