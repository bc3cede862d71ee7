// The WR8 probe of each profile against hil's mock of each profile, in
// virtual time. A profile's probe against its own mock answers as the
// profile's documents say and matches itself run after run; against
// another profile's mock it differs exactly where a documented fact says
// the two profiles differ.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "conform/check.hpp"
#include "conform/compare.hpp"
#include "conform/probe.hpp"

namespace hil::conform {
namespace {

using std::chrono::milliseconds;

const std::vector<std::string> kProfiles = {"document", "svgui-2019", "svgui-head"};

Probe wr8_probe(const std::string& profile) {
  return make_probe(mocks::CarKind::wr8, profile);
}

// ---------------------------------------------------------------- A == B

/// What the mock of the probe's own profile answers: the start of each
/// frame as the report shows it ("kind hex"), and the closes.
struct Answered {
  std::vector<std::string> frames;
  std::size_t closes = 0;
};

const std::string kSet = "SET 61 04 ";        // the 97-byte SET, length byte 0x61
const std::string kMap = "MAP 77 07 0A 08 ";  // the warehouse: 10 x 8 cells

const std::map<std::string, std::map<std::string, Answered>> kAnswers = {
    {"document",
     {
         {"connect", {}},
         {"task-before-auth", {}},
         {"auth-bad", {{}, 1}},
         {"reconnect-after-refusal", {}},
         {"auth", {{"AUTH_REPLY 02 08 01 02"}}},
         {"auth-again", {{"AUTH_REPLY 02 08 01 02"}}},
         {"empty", {}},
         {"check", {{"RESPONSE 05 02 02"}}},
         {"check-coi-0", {{"RESPONSE 05 00 02"}}},
         {"check-coi-255", {{"RESPONSE 05 FF 02"}}},
         {"get-settings",
          {{"SETTINGS 04 03 14 00 00 00 C0 3F 01 00 00 80 3E 02 CD CC 4C 3D 03 5A 00 00 00",
            "RESPONSE 05 03 02"}}},
         {"settings", {{"RESPONSE 05 04 02"}}},
         {"settings-no-entries", {{"RESPONSE 05 05 02"}}},
         {"settings-min", {{"RESPONSE 05 06 02"}}},
         {"settings-max", {{"RESPONSE 05 08 02"}}},
         {"settings-p-over", {{"RESPONSE 05 09 00"}}},
         {"settings-i-negative", {{"RESPONSE 05 0A 00"}}},
         {"settings-servo-over", {{"RESPONSE 05 0B 00"}}},
         {"settings-servo-under", {{"RESPONSE 05 0C 00"}}},
         {"settings-restore", {{"RESPONSE 05 0D 02"}}},
         {"drive", {{"RESPONSE 05 14 01", "RESPONSE 05 14 02"}}},
         {"drive-min", {{"RESPONSE 05 15 01", "RESPONSE 05 15 02"}}},
         {"drive-zero", {{"RESPONSE 05 16 00"}}},
         {"drive-over-max", {{"RESPONSE 05 17 00"}}},
         {"turn", {{"RESPONSE 05 18 01", "RESPONSE 05 18 02"}}},
         {"turn-min", {{"RESPONSE 05 19 01", "RESPONSE 05 19 02"}}},
         {"turn-max", {{"RESPONSE 05 1A 01", "RESPONSE 05 1A 02"}}},
         {"turn-over", {{"RESPONSE 05 1B 00"}}},
         {"turn-under", {{"RESPONSE 05 1C 00"}}},
         {"motion-busy", {{"RESPONSE 05 1D 01", "RESPONSE 05 1E 00", "RESPONSE 05 1D 02"}}},
         {"blink", {{"RESPONSE 05 1F 01", "RESPONSE 05 20 00", "RESPONSE 05 1F 02"}}},
         {"task-bad-size", {{"RESPONSE 05 28 00"}}},
         {"task-missing-parameter", {{"RESPONSE 05 29 00"}}},
         {"task-unknown-code", {{"RESPONSE 05 2A 00"}}},
         {"settings-bad-size", {{"RESPONSE 05 2B 00"}}},
         {"settings-unknown-type", {{"RESPONSE 05 2C 00"}}},
         {"unknown-packet-code", {}},
         {"vehicle-packet", {}},
         {"oversized", {{"RESPONSE 05 2E 00"}}},
         {"garbage-between-frames", {{"RESPONSE 05 2F 02", "RESPONSE 05 30 02"}}},
         {"split-bytes", {{"RESPONSE 05 31 02"}}},
         {"two-frames-one-write", {{"RESPONSE 05 32 02", "RESPONSE 05 33 02"}}},
         {"reconnect", {}},
         {"task-after-reconnect", {}},
         {"auth-after-reconnect", {{"AUTH_REPLY 02 08 01 02"}}},
         {"stop", {{"RESPONSE 05 3D 01", "RESPONSE 05 3D 02"}}},
     }},
    {"svgui-2019",
     {
         {"connect", {}},
         {"task-before-auth", {{"ANSWER 03 05 01 02"}}},
         {"auth-head-form", {}},
         {"auth-bad", {}},
         {"auth", {{"AUTH_REPLY 04 02 01 02 03"}}},
         {"auth-again", {{"AUTH_REPLY 04 02 01 02 03"}}},
         {"wheels", {{"ANSWER 03 05 02 02"}}},
         {"wheels-int-max", {{"ANSWER 03 05 03 02"}}},
         {"wheels-int-min", {{"ANSWER 03 05 04 02"}}},
         {"task-coi-0", {{"ANSWER 03 05 00 02"}}},
         {"task-coi-255", {{"ANSWER 03 05 FF 02"}}},
         {"forward", {{"ANSWER 03 05 05 02"}}},
         {"forward-back", {{"ANSWER 03 05 06 02"}}},
         {"forward-zero", {{"ANSWER 03 05 07 02"}}},
         {"busy", {{"ANSWER 03 05 08 02"}}},  // COI 9 dropped while 8 runs
         {"signals", {{"ANSWER 03 05 0A 02"}}},
         {"settings", {}},
         {"task-after-settings", {{"ANSWER 03 05 0B 02"}}},
         {"task-type-4", {}},
         {"task-unknown-type", {}},
         {"task-missing-parameter", {}},
         {"task-short", {}},
         {"unknown-packet-code", {}},
         {"length-zero", {}},
         {"oversized", {{"ANSWER 03 05 16 02"}}},
         {"garbage-between-frames", {{"ANSWER 03 05 17 02"}}},  // one packet: 24 never read
         {"split-bytes", {}},
         {"two-frames-one-write", {{"ANSWER 03 05 1A 02"}}},  // one packet: 27 never read
         {"reconnect", {}},
         {"task-after-reconnect", {{"ANSWER 03 05 1E 02"}}},
         {"stop", {{"ANSWER 03 05 1F 02"}}},
     }},
    {"svgui-head",
     {
         {"connect", {}},
         {"set-request-before-auth", {{kSet}}},
         {"auth-v2019-form", {{"AUTH_REPLY 04 02 01 02 03", kMap}}},
         {"auth-bad", {}},
         {"auth", {{"AUTH_REPLY 04 02 01 02 03", kMap}}},
         {"set-request", {{kSet + "3F F0 00 00 00 00 00 00"}}},  // steering p 1.0
         {"set", {{kSet + "40 04 00 00 00 00 00 00"}}},          // steering p 2.5
         {"set-extremes", {{kSet + "3F F0 00 00 00 00 00 00"}}},
         {"set-nan", {{kSet + "3F F0 00 00 00 00 00 00"}}},
         {"set-defaults", {}},
         {"control", {}},
         {"control-x-max", {}},
         {"control-x-min", {}},
         {"control-y-max", {}},
         {"control-x-over", {}},
         {"control-nan", {}},
         {"task-v2019", {}},
         {"unknown-packet-code", {}},
         {"control-short", {}},
         {"length-zero", {}},
         {"split-bytes", {}},
         {"two-frames-one-write", {{kSet}}},  // one packet per arrival
         {"reconnect", {}},
         {"garbage-between-frames", {{kSet}}},
         {"reconnect-2", {}},
         {"oversized", {}},
         {"reconnect-3", {}},
         {"set-request-after-reconnect", {{kSet}}},
         {"stop", {}},
     }},
};

TEST(Wr8Conform, EachProbeAgainstItsOwnProfileAnswersAsDocumented) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const Capture capture = probe_mock(probe, profile);
    const Comparison self = compare(capture, capture, probe, profile);
    const auto& expected = kAnswers.at(profile);
    ASSERT_EQ(self.exchanges.size(), probe.exchanges.size());
    for (const auto& row : self.exchanges) {
      if (row.kind == ExchangeKind::telemetry) continue;
      const auto it = expected.find(row.name);
      ASSERT_NE(it, expected.end()) << "no expectation for " << row.name;
      EXPECT_EQ(row.mock.closes, it->second.closes) << row.name;
      ASSERT_EQ(row.mock.frames.size(), it->second.frames.size())
          << row.name << ": " << row.mock.summary();
      for (std::size_t i = 0; i < row.mock.frames.size(); ++i)
        EXPECT_TRUE(row.mock.frames[i].starts_with(it->second.frames[i]))
            << row.name << " frame " << i + 1 << ": " << row.mock.frames[i];
    }
  }
}

TEST(Wr8Conform, HeadSetWithANanChangesNothing) {
  const Probe probe = wr8_probe("svgui-head");
  const Capture capture = probe_mock(probe, "svgui-head");
  const Comparison self = compare(capture, capture, probe, "svgui-head");
  std::map<std::string, std::vector<std::string>> frames;
  for (const auto& row : self.exchanges)
    frames[row.name] = row.mock.frames;
  ASSERT_EQ(frames["set-extremes"].size(), 1U);
  // The integral limits came back as the largest and lowest doubles.
  EXPECT_NE(frames["set-extremes"][0].find("7F EF FF FF FF FF FF FF"), std::string::npos);
  EXPECT_NE(frames["set-extremes"][0].find("FF EF FF FF FF FF FF FF"), std::string::npos);
  EXPECT_EQ(frames["set-nan"], frames["set-extremes"]);
  EXPECT_EQ(frames["set-request"], frames["set-request-after-reconnect"]);
}

TEST(Wr8Conform, TelemetryPeriodsAreEachProfiles) {
  const std::map<std::string, std::map<std::string, Duration>> periods = {
      {"document", {{"DATA", milliseconds(100)}}},
      {"svgui-2019", {{"DATA", milliseconds(100)}}},
      {"svgui-head", {{"HIGH_FREQ_DATA", milliseconds(50)}, {"LOW_FREQ_DATA", milliseconds(1000)}}},
  };
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const Capture capture = probe_mock(probe, profile);
    const Comparison self = compare(capture, capture, probe, profile);
    for (const auto& row : self.exchanges) {
      if (row.kind != ExchangeKind::telemetry) continue;
      std::map<std::string, Duration> seen;
      for (const auto& [kind, period] : row.mock.periods) {
        ASSERT_TRUE(period.has_value()) << kind;
        seen[kind] = *period;
      }
      EXPECT_EQ(seen, periods.at(profile));
      EXPECT_GE(row.mock.frames.size(), 10U);
    }
  }
}

TEST(Wr8Conform, WorldDependentAnswersAreComparedByShape) {
  // The document vehicle's AUTH-REPLY carries its state of the moment;
  // head's login answer carries the MAP of the arena.
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const Capture capture = probe_mock(probe, profile);
    const Comparison self = compare(capture, capture, probe, profile);
    for (std::size_t i = 0; i < self.exchanges.size(); ++i) {
      const auto& row = self.exchanges[i];
      bool world = false;
      for (const auto& f : row.mock.frames) {
        world =
            world || f.starts_with("MAP") || (profile == "document" && f.starts_with("AUTH_REPLY"));
      }
      if (row.kind != ExchangeKind::telemetry)
        EXPECT_EQ(probe.exchanges[i].physical, world) << row.name;
    }
  }
}

TEST(Wr8Conform, EachProfileMatchesItselfAndRunsDeterministically) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const Capture first = probe_mock(probe, profile);
    const Capture second = probe_mock(probe, profile);
    EXPECT_EQ(first, second);
    const Comparison comparison = compare(first, second, probe, profile);
    EXPECT_TRUE(comparison.all_match());
    for (const auto& row : comparison.exchanges) {
      for (const auto& d : row.differences)
        ADD_FAILURE() << row.name << ": " << d;
    }
    EXPECT_EQ(first.exchanges.size(), probe.exchanges.size());
  }
}

// ---------------------------------------------------------------- A != B

// The documented facts that make two profiles answer a probe differently
// (docs/protocols/wr8.md, "Every difference, by profile" and "The real
// programs' length byte"; docs/mocks/wr8.md).

/// The real programs put a length byte before every packet and send their
/// DATA to every connection from the moment it opens (protocols/wr8.md:
/// framing, DATA; mocks/wr8.md: the real vehicle programs). Read with the
/// document's framing, which has no delimiter, any byte 0..6 starts a
/// packet (protocols/wr8.md: Resynchronisation), so those bytes are
/// phantom packets in every exchange.
constexpr std::string_view kPhantomsFromSvguiData =
    "svgui DATA from the connection's start, read without its length byte";
/// The document vehicle serves nothing before a login with its own string
/// and drops the session with the connection; the real programs keep no
/// login state (protocols/wr8.md: login state; mocks/wr8.md: Logging in).
constexpr std::string_view kDocumentNeedsItsLogin =
    "the document vehicle answers nothing before its own login";
/// An svgui AUTH is no document login: its length byte is no packet code
/// (garbage), and `01 konnichiwa` is an AUTH with the wrong string, which
/// the document vehicle answers with silence and a close 1 s later
/// (protocols/wr8.md: a wrong login; mocks/wr8.md: Logging in).
constexpr std::string_view kSvguiAuthRefused =
    "the svgui AUTH is a wrong login to the document vehicle: silence, then a close after 1 s";
/// The document vehicle streams DATA only after a login; the real
/// programs stream theirs to whoever is connected (protocols/wr8.md: DATA;
/// mocks/wr8.md: DATA and the real vehicle programs).
constexpr std::string_view kDataOnlyAfterLogin =
    "svgui DATA flows to any connection, document DATA only after a login";
/// head's HIGH-FREQ (code 9, every 50 ms) and LOW-FREQ (code 8) DATA are
/// no packets of v2019 (protocols/wr8.md: packet codes); they reach every
/// exchange as unreadable frames.
constexpr std::string_view kHeadDataUnknownToV2019 =
    "head's DATA codes 8 and 9 are no v2019 packets, every 50 ms";
/// v2019's DATA is code 6, which in head is SET-REQUEST: each DATA
/// (42 bytes, every 100 ms) reads as a malformed SET-REQUEST in every
/// exchange (protocols/wr8.md: packet codes, DATA).
constexpr std::string_view kV2019DataIsHeadSetRequest =
    "v2019 DATA (code 6) is a malformed head SET-REQUEST, every 100 ms";
/// The phantom packets of v2019's DATA come in one long phantom SETTINGS
/// (its size byte declares 249 block bytes, about six DATA packets: one
/// phantom per 600 ms), so every other 300 ms window holds none. In this
/// window the document vehicle is silent too (a code-7 packet is no
/// packet), so the two match.
constexpr std::string_view kPhantomGap = "a window between two phantom packets";

struct Explained {
  std::string_view exchange;
  std::string_view fact;
};

struct Pair {
  std::string probe;
  std::string mock;
  /// Every exchange differs, for `all_fact`, except `matching`.
  std::string_view all_fact;
  std::vector<Explained> matching;
  /// Otherwise: exactly these differ.
  std::vector<Explained> differing;
};

const std::vector<Pair> kPairs = {
    {"document", "svgui-2019", kPhantomsFromSvguiData, {{"unknown-packet-code", kPhantomGap}}, {}},
    {"document", "svgui-head", kPhantomsFromSvguiData, {}, {}},
    {"svgui-2019",
     "document",
     {},
     {},
     {
         {"task-before-auth", kDocumentNeedsItsLogin},
         {"auth", kSvguiAuthRefused},
         {"auth-again", kSvguiAuthRefused},  // the close of the first refusal comes here
         // From here to the reconnect the document vehicle has closed.
         {"wheels", kSvguiAuthRefused},
         {"wheels-int-max", kSvguiAuthRefused},
         {"wheels-int-min", kSvguiAuthRefused},
         {"task-coi-0", kSvguiAuthRefused},
         {"task-coi-255", kSvguiAuthRefused},
         {"forward", kSvguiAuthRefused},
         {"forward-back", kSvguiAuthRefused},
         {"forward-zero", kSvguiAuthRefused},
         {"busy", kSvguiAuthRefused},
         {"signals", kSvguiAuthRefused},
         {"task-after-settings", kSvguiAuthRefused},
         {"oversized", kSvguiAuthRefused},
         {"garbage-between-frames", kSvguiAuthRefused},
         {"two-frames-one-write", kSvguiAuthRefused},
         {"telemetry", kDataOnlyAfterLogin},
         {"task-after-reconnect", kDocumentNeedsItsLogin},
         {"stop", kDocumentNeedsItsLogin},
     }},
    {"svgui-2019", "svgui-head", kHeadDataUnknownToV2019, {}, {}},
    {"svgui-head",
     "document",
     {},
     {},
     {
         {"set-request-before-auth", kDocumentNeedsItsLogin},
         {"auth-v2019-form", kSvguiAuthRefused},
         {"auth", kSvguiAuthRefused},
         {"set-request", kSvguiAuthRefused},  // and the close of the first refusal
         {"set", kSvguiAuthRefused},
         {"set-extremes", kSvguiAuthRefused},
         {"set-nan", kSvguiAuthRefused},
         {"telemetry", kDataOnlyAfterLogin},
         {"two-frames-one-write", kSvguiAuthRefused},
         // After each reconnect the document session starts without a login.
         {"garbage-between-frames", kDocumentNeedsItsLogin},
         {"set-request-after-reconnect", kDocumentNeedsItsLogin},
     }},
    {"svgui-head", "svgui-2019", kV2019DataIsHeadSetRequest, {}, {}},
};

TEST(Wr8Conform, ProfilesDifferExactlyWhereTheirDocumentsSay) {
  ASSERT_EQ(kPairs.size(), kProfiles.size() * (kProfiles.size() - 1));
  for (const auto& pair : kPairs) {
    SCOPED_TRACE(pair.probe + " probe against the " + pair.mock + " mock");
    const Probe probe = wr8_probe(pair.probe);
    const Comparison comparison =
        compare(probe_mock(probe, pair.probe), probe_mock(probe, pair.mock), probe, pair.mock);
    std::set<std::string> expected;
    std::map<std::string, std::string_view> why;
    if (!pair.all_fact.empty()) {
      for (const auto& e : probe.exchanges) {
        expected.insert(e.name);
        why[e.name] = pair.all_fact;
      }
      for (const auto& m : pair.matching)
        expected.erase(std::string(m.exchange));
    } else {
      for (const auto& d : pair.differing) {
        expected.insert(std::string(d.exchange));
        why[std::string(d.exchange)] = d.fact;
      }
    }
    std::set<std::string> differing;
    for (const auto& row : comparison.exchanges) {
      if (!row.matches()) differing.insert(row.name);
      if (row.matches() && expected.contains(row.name)) {
        ADD_FAILURE() << row.name << " matches, but should differ: " << why[row.name];
      }
      if (!row.matches() && !expected.contains(row.name)) {
        ADD_FAILURE() << row.name
                      << " differs, and no documented fact says why: " << row.differences.front();
      }
    }
    EXPECT_EQ(differing, expected);
  }
}

}  // namespace
}  // namespace hil::conform
