// The WR8 probe of each profile, read back with that profile's own
// framing: every exchange sends the frames it says it sends.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "conform/probe.hpp"
#include "link/protocol_adapter.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::conform {
namespace {

namespace wr8 = protocol::wr8;
namespace svgui = protocol::wr8::svgui;
using std::chrono::milliseconds;

const std::vector<std::string> kProfiles = {"document", "svgui-2019", "svgui-head"};

Probe wr8_probe(const std::string& profile) {
  return make_probe(mocks::CarKind::wr8, profile);
}

const Exchange& exchange(const Probe& probe, std::string_view name) {
  for (const auto& e : probe.exchanges) {
    if (e.name == name) return e;
  }
  throw std::out_of_range("no exchange " + std::string(name));
}

Bytes all_bytes(const Exchange& e) {
  Bytes out;
  for (const auto& w : e.writes)
    out.insert(out.end(), w.bytes.begin(), w.bytes.end());
  return out;
}

/// The exchange's bytes cut by the profile's adapter, the way a wire log
/// of the probe shows them.
std::vector<link::WireFrame> frames(const Probe& probe, const Exchange& e) {
  auto splitter = link::protocol_adapter("wr8", probe.profile)->splitter();
  std::vector<link::WireFrame> out;
  for (const auto& w : e.writes)
    splitter->feed(w.bytes, out);
  splitter->finish(out);
  return out;
}

/// Each frame as its kind, "!" in front of an invalid one.
std::vector<std::string> kinds(const Probe& probe, const Exchange& e) {
  std::vector<std::string> out;
  for (const auto& f : frames(probe, e))
    out.push_back((f.valid ? "" : "!") + f.kind);
  return out;
}

TEST(Wr8Probe, EveryProfileHasItsOwnProbeOfTheSameVersion) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    EXPECT_EQ(probe.car, mocks::CarKind::wr8);
    EXPECT_EQ(probe.profile, profile);
    EXPECT_EQ(probe.version, "wr8-probe/1");
  }
  EXPECT_EQ(probe_version(mocks::CarKind::wr8), "wr8-probe/1");
  EXPECT_EQ(wr8_probe("document").exchanges.size(),
            make_probe(mocks::CarKind::wr8, "").exchanges.size());
}

TEST(Wr8Probe, StartsWithConnectEndsWithStopNamesUniqueUnder40Seconds) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    ASSERT_GE(probe.exchanges.size(), 2U);
    EXPECT_EQ(probe.exchanges.front().name, "connect");
    EXPECT_EQ(probe.exchanges.front().kind, ExchangeKind::connect);
    EXPECT_TRUE(probe.exchanges.front().writes.empty());
    EXPECT_EQ(probe.exchanges.back().kind, ExchangeKind::stop);
    EXPECT_EQ(probe.exchanges.back().name, "stop");
    std::set<std::string> names;
    for (const auto& e : probe.exchanges) {
      EXPECT_TRUE(names.insert(e.name).second) << "twice: " << e.name;
      EXPECT_FALSE(e.what.empty()) << e.name;
      EXPECT_GT(e.listen, Duration::zero()) << e.name;
      if (e.kind == ExchangeKind::connect || e.kind == ExchangeKind::telemetry) {
        EXPECT_TRUE(e.writes.empty()) << e.name;
      } else {
        EXPECT_FALSE(e.writes.empty()) << e.name;
      }
    }
    EXPECT_LT(probe.duration(), std::chrono::seconds(40));
    EXPECT_GT(probe.duration(), std::chrono::seconds(10));
  }
}

TEST(Wr8Probe, ReconnectsMidProbeAndGoesOnAfterIt) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    std::size_t reconnects = 0;
    for (std::size_t i = 1; i + 1 < probe.exchanges.size(); ++i) {
      if (probe.exchanges[i].kind != ExchangeKind::connect) continue;
      ++reconnects;
      EXPECT_FALSE(probe.exchanges[i + 1].writes.empty())
          << "nothing sent after " << probe.exchanges[i].name;
    }
    EXPECT_GE(reconnects, 1U);
  }
}

TEST(Wr8Probe, TelemetryListensForTenPeriodsOfEveryKind) {
  const std::map<std::string, std::vector<std::pair<std::string, Duration>>> periods = {
      {"document", {{"DATA", milliseconds(100)}}},
      {"svgui-2019", {{"DATA", milliseconds(100)}}},
      // LOW-FREQ comes once a second: two of its periods are enough for a median.
      {"svgui-head", {{"HIGH_FREQ_DATA", milliseconds(50)}, {"LOW_FREQ_DATA", milliseconds(1000)}}},
  };
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const auto& telemetry = exchange(probe, "telemetry");
    EXPECT_EQ(telemetry.kind, ExchangeKind::telemetry);
    std::vector<std::string> expected_kinds;
    for (const auto& [kind, period] : periods.at(profile)) {
      expected_kinds.push_back(kind);
      EXPECT_GE(telemetry.listen, std::min<Duration>(period * 10, period * 2 + milliseconds(100)))
          << kind;
    }
    EXPECT_EQ(probe.telemetry_kinds, expected_kinds);
    EXPECT_GE(telemetry.listen, milliseconds(1000));
  }
}

// Every exchange's frames as the profile's adapter cuts them. A valid
// command decodes as a valid frame of its packet; each error exchange
// holds the broken frame it names.
const std::map<std::string, std::map<std::string, std::vector<std::string>>> kFrames = {
    {"document",
     {
         {"connect", {}},
         {"task-before-auth", {"TASK"}},
         {"auth-bad", {"AUTH"}},
         {"reconnect-after-refusal", {}},
         {"auth", {"AUTH"}},
         {"auth-again", {"AUTH"}},
         {"empty", {"EMPTY"}},
         {"check", {"TASK"}},
         {"check-coi-0", {"TASK"}},
         {"check-coi-255", {"TASK"}},
         {"get-settings", {"TASK"}},
         {"settings", {"SETTINGS"}},
         {"settings-no-entries", {"SETTINGS"}},
         {"settings-min", {"SETTINGS"}},
         {"settings-max", {"SETTINGS"}},
         {"settings-p-over", {"SETTINGS"}},
         {"settings-i-negative", {"SETTINGS"}},
         {"settings-servo-over", {"SETTINGS"}},
         {"settings-servo-under", {"SETTINGS"}},
         {"settings-restore", {"SETTINGS"}},
         {"drive", {"TASK"}},
         {"drive-min", {"TASK"}},
         {"drive-zero", {"TASK"}},
         {"drive-over-max", {"TASK"}},
         {"turn", {"TASK"}},
         {"turn-min", {"TASK"}},
         {"turn-max", {"TASK"}},
         {"turn-over", {"TASK"}},
         {"turn-under", {"TASK"}},
         {"motion-busy", {"TASK", "TASK"}},
         {"blink", {"TASK", "TASK"}},
         {"task-bad-size", {"!TASK"}},
         {"task-missing-parameter", {"!TASK"}},
         {"task-unknown-code", {"!TASK"}},
         {"settings-bad-size", {"!SETTINGS"}},
         {"settings-unknown-type", {"!SETTINGS"}},
         {"unknown-packet-code", {"!"}},
         {"vehicle-packet", {"RESPONSE"}},
         {"oversized", {"!TASK"}},
         {"garbage-between-frames", {"!", "TASK", "!", "TASK"}},
         {"split-bytes", {"SETTINGS"}},
         {"two-frames-one-write", {"TASK", "TASK"}},
         {"telemetry", {}},
         {"reconnect", {}},
         {"task-after-reconnect", {"TASK"}},
         {"auth-after-reconnect", {"AUTH"}},
         {"stop", {"TASK"}},
     }},
    {"svgui-2019",
     {
         {"connect", {}},
         {"task-before-auth", {"TASK"}},
         {"auth-head-form", {"AUTH"}},
         {"auth-bad", {"AUTH"}},
         {"auth", {"AUTH"}},
         {"auth-again", {"AUTH"}},
         {"wheels", {"TASK"}},
         {"wheels-int-max", {"TASK"}},
         {"wheels-int-min", {"TASK"}},
         {"task-coi-0", {"TASK"}},
         {"task-coi-255", {"TASK"}},
         {"forward", {"TASK"}},
         {"forward-back", {"TASK"}},
         {"forward-zero", {"TASK"}},
         {"busy", {"TASK", "TASK"}},
         {"signals", {"TASK"}},
         {"settings", {"SETTINGS"}},
         {"task-after-settings", {"TASK"}},
         // The codec reads any type and count; the vehicle has no action
         // for these, or no parameter to take.
         {"task-type-4", {"TASK"}},
         {"task-unknown-type", {"TASK"}},
         {"task-missing-parameter", {"TASK"}},
         {"task-short", {"!TASK"}},
         {"unknown-packet-code", {"!"}},
         {"length-zero", {"!length"}},
         {"oversized", {}},  // checked on its own below
         {"garbage-between-frames", {"TASK", "!length", "!length", "TASK"}},
         {"split-bytes", {"TASK"}},
         {"two-frames-one-write", {"TASK", "TASK"}},
         {"telemetry", {}},
         {"reconnect", {}},
         {"task-after-reconnect", {"TASK"}},
         {"stop", {"TASK"}},
     }},
    {"svgui-head",
     {
         {"connect", {}},
         {"set-request-before-auth", {"SET_REQUEST"}},
         {"auth-v2019-form", {"AUTH"}},
         {"auth-bad", {"AUTH"}},
         {"auth", {"AUTH"}},
         {"set-request", {"SET_REQUEST"}},
         {"set", {"SET", "SET_REQUEST"}},
         {"set-extremes", {"SET", "SET_REQUEST"}},
         {"set-nan", {"SET", "SET_REQUEST"}},
         {"set-defaults", {"SET"}},
         {"control", {"CONTROL", "CONTROL"}},
         {"control-x-max", {"CONTROL"}},
         {"control-x-min", {"CONTROL"}},
         {"control-y-max", {"CONTROL", "CONTROL"}},
         {"control-x-over", {"CONTROL"}},
         {"control-nan", {"CONTROL"}},
         {"telemetry", {}},
         {"task-v2019", {"!"}},
         {"unknown-packet-code", {"!"}},
         {"control-short", {"!CONTROL"}},
         {"length-zero", {"!length"}},
         {"split-bytes", {"SET_REQUEST"}},
         {"two-frames-one-write", {"SET_REQUEST", "SET_REQUEST"}},
         {"reconnect", {}},
         {"garbage-between-frames", {"SET_REQUEST", "!length", "!length", "SET_REQUEST"}},
         {"reconnect-2", {}},
         {"oversized", {"!length", "!"}},
         {"reconnect-3", {}},
         {"set-request-after-reconnect", {"SET_REQUEST"}},
         {"stop", {"CONTROL"}},
     }},
};

TEST(Wr8Probe, EveryExchangeSendsTheFramesItNames) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const auto& expected = kFrames.at(profile);
    EXPECT_EQ(probe.exchanges.size(), expected.size());
    for (const auto& e : probe.exchanges) {
      const auto it = expected.find(e.name);
      ASSERT_NE(it, expected.end()) << "no expectation for " << e.name;
      if (profile == "svgui-2019" && e.name == "oversized") continue;
      EXPECT_EQ(kinds(probe, e), it->second) << e.name;
    }
  }
}

TEST(Wr8Probe, ValidCommandsDecodeAsValidFrames) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    for (const auto& e : probe.exchanges) {
      if (e.kind != ExchangeKind::command && e.kind != ExchangeKind::boundary &&
          e.kind != ExchangeKind::stop)
        continue;
      const auto cut = frames(probe, e);
      EXPECT_FALSE(cut.empty()) << e.name;
      for (const auto& f : cut)
        EXPECT_TRUE(f.valid) << e.name << ": " << f.text;
    }
  }
}

TEST(Wr8Probe, FramingExchangesCutAndJoinWholeFrames) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const auto& split = exchange(probe, "split-bytes");
    EXPECT_EQ(split.kind, ExchangeKind::framing);
    ASSERT_GT(split.writes.size(), 1U);
    for (std::size_t i = 0; i < split.writes.size(); ++i) {
      EXPECT_EQ(split.writes[i].bytes.size(), 1U);
      EXPECT_EQ(split.writes[i].after, i == 0 ? Duration{0} : milliseconds(5));
    }
    const auto split_frames = frames(probe, split);
    ASSERT_EQ(split_frames.size(), 1U);
    EXPECT_TRUE(split_frames[0].valid);

    const auto& two = exchange(probe, "two-frames-one-write");
    ASSERT_EQ(two.writes.size(), 1U);
    const auto two_frames = frames(probe, two);
    ASSERT_EQ(two_frames.size(), 2U);
    EXPECT_TRUE(two_frames[0].valid && two_frames[1].valid);

    const auto& garbage = exchange(probe, "garbage-between-frames");
    ASSERT_EQ(garbage.writes.size(), 1U);
    const auto garbage_frames = frames(probe, garbage);
    const auto valid = std::count_if(garbage_frames.begin(), garbage_frames.end(),
                                     [](const link::WireFrame& f) { return f.valid; });
    EXPECT_EQ(valid, 2);
    EXPECT_GT(garbage_frames.size(), 2U);
  }
}

TEST(Wr8Probe, Wr8HasNoChecksumSoNoBadChecksumExchange) {
  for (const auto& profile : kProfiles) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const auto adapter = link::protocol_adapter("wr8", profile);
    for (const auto& f : frames(probe, probe.exchanges.back()))
      EXPECT_FALSE(adapter->checksum_field(f.raw).has_value());
    for (const auto& e : probe.exchanges)
      EXPECT_EQ(e.name.find("checksum"), std::string::npos) << e.name;
  }
}

// ---- document: the values at the edges

wr8::Task document_task(const Exchange& e) {
  const auto item = wr8::decode_packet(all_bytes(e));
  const auto* frame = std::get_if<protocol::Frame<wr8::Message>>(&item);
  if (frame == nullptr) throw std::runtime_error(e.name + " is no valid packet");
  return std::get<wr8::Task>(frame->message);
}

wr8::Settings document_settings(const Exchange& e) {
  const auto item = wr8::decode_packet(all_bytes(e));
  const auto* frame = std::get_if<protocol::Frame<wr8::Message>>(&item);
  if (frame == nullptr) throw std::runtime_error(e.name + " is no valid packet");
  return std::get<wr8::Settings>(frame->message);
}

TEST(Wr8ProbeDocument, EveryTaskAndSettingIsSent) {
  const Probe probe = wr8_probe("document");
  std::set<wr8::TaskCode> tasks;
  std::set<wr8::SettingCode> settings;
  for (const auto& e : probe.exchanges) {
    if (e.kind != ExchangeKind::command && e.kind != ExchangeKind::boundary) continue;
    wr8::Decoder decoder;
    std::vector<wr8::Item> items;
    decoder.feed(all_bytes(e), items);
    for (const auto& item : items) {
      const auto* frame = std::get_if<protocol::Frame<wr8::Message>>(&item);
      ASSERT_NE(frame, nullptr) << e.name;
      if (const auto* t = std::get_if<wr8::Task>(&frame->message)) tasks.insert(t->task);
      if (const auto* s = std::get_if<wr8::Settings>(&frame->message)) {
        for (const auto& p : s->params)
          settings.insert(p.code);
      }
    }
  }
  EXPECT_EQ(tasks.size(), wr8::kAllTaskCodes.size());
  EXPECT_EQ(settings.size(), wr8::kAllSettingCodes.size());
}

TEST(Wr8ProbeDocument, EdgesAndOnePastThem) {
  const Probe probe = wr8_probe("document");
  const auto param = [&](std::string_view name) {
    const auto task = document_task(exchange(probe, name));
    EXPECT_EQ(task.params.size(), 1U) << name;
    return task.params.empty() ? 0 : task.params[0].as_i32();
  };
  EXPECT_EQ(param("drive-min"), 1);
  EXPECT_EQ(param("drive-zero"), 0);
  EXPECT_EQ(param("drive-over-max"), 1001);
  EXPECT_EQ(param("turn-min"), -30);
  EXPECT_EQ(param("turn-max"), 30);
  EXPECT_EQ(param("turn-over"), 31);
  EXPECT_EQ(param("turn-under"), -31);
  EXPECT_EQ(document_task(exchange(probe, "check-coi-0")).coi, 0);
  EXPECT_EQ(document_task(exchange(probe, "check-coi-255")).coi, 255);

  // The stalled drive at the longest distance runs with every gain at 0.
  const auto min = document_settings(exchange(probe, "settings-min"));
  ASSERT_EQ(min.params.size(), 4U);
  for (const auto& s : min.params)
    EXPECT_EQ(s.value.bits, 0U);
  const auto max = document_settings(exchange(probe, "settings-max"));
  ASSERT_EQ(max.params.size(), 4U);
  EXPECT_EQ(max.params[0].value.as_f32(), 100.0F);
  EXPECT_EQ(max.params[3].value.as_i32(), 180);
  const auto over = document_settings(exchange(probe, "settings-p-over"));
  ASSERT_EQ(over.params.size(), 1U);
  EXPECT_GT(over.params[0].value.as_f32(), 100.0F);
  EXPECT_LT(over.params[0].value.as_f32(), 100.001F);
  EXPECT_TRUE(document_settings(exchange(probe, "settings-no-entries")).params.empty());
  // The longest TASK a size byte counting bytes can declare.
  EXPECT_EQ(all_bytes(exchange(probe, "oversized")).size(), 4U + 252U);
}

TEST(Wr8ProbeDocument, LoginRulesComeFirst) {
  const Probe probe = wr8_probe("document");
  ASSERT_GE(probe.exchanges.size(), 5U);
  EXPECT_EQ(probe.exchanges[1].name, "task-before-auth");
  EXPECT_EQ(probe.exchanges[2].name, "auth-bad");
  // The vehicle closes 1 s after a wrong login: the window sees the close.
  EXPECT_GE(probe.exchanges[2].listen, milliseconds(1200));
  EXPECT_EQ(probe.exchanges[3].kind, ExchangeKind::connect);
  EXPECT_EQ(probe.exchanges[4].name, "auth");
  const Bytes good = all_bytes(probe.exchanges[4]);
  const Bytes bad = all_bytes(probe.exchanges[2]);
  ASSERT_EQ(good.size(), 11U);
  ASSERT_EQ(bad.size(), 11U);
  EXPECT_TRUE(std::equal(good.begin() + 1, good.end(), wr8::default_profile().auth_text.begin()));
  EXPECT_NE(good, bad);
}

// ---- the real programs

TEST(Wr8ProbeSvgui, EveryPacketOfTheVersionIsSent) {
  const std::map<std::string, std::set<std::string>> packets = {
      {"svgui-2019", {"AUTH", "TASK", "SETTINGS"}},
      {"svgui-head", {"AUTH", "SET", "SET_REQUEST", "CONTROL"}},
  };
  for (const auto& [profile, wanted] : packets) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    std::set<std::string> sent;
    for (const auto& e : probe.exchanges) {
      for (const auto& f : frames(probe, e)) {
        if (f.valid) sent.insert(f.kind);
      }
    }
    EXPECT_EQ(sent, wanted);
  }
  // v2019's three task types with an action.
  const Probe v2019 = wr8_probe("svgui-2019");
  std::set<std::uint8_t> types;
  for (const auto& e : v2019.exchanges) {
    svgui::Decoder decoder(svgui::Version::v2019);
    std::vector<svgui::Item> items;
    decoder.feed(all_bytes(e), items);
    for (const auto& item : items) {
      const auto* frame = std::get_if<protocol::Frame<svgui::Message>>(&item);
      if (frame == nullptr) continue;
      if (const auto* t = std::get_if<svgui::Task>(&frame->message)) types.insert(t->type);
    }
  }
  for (const int type : {1, 2, 3})
    EXPECT_TRUE(types.contains(static_cast<std::uint8_t>(type))) << type;
}

TEST(Wr8ProbeSvgui, EachVersionLogsInWithItsOwnGuisBytesAndTriesTheOther) {
  const Bytes v2019_auth = {0x0B, 0x01, 'k', 'o', 'n', 'n', 'i', 'c', 'h', 'i', 'w', 'a'};
  Bytes head_auth = {0x0C, 0x01, 'k', 'o', 'n', 'n', 'i', 'c', 'h', 'i', 'w', 'a', 0x00};
  const Probe v2019 = wr8_probe("svgui-2019");
  EXPECT_EQ(all_bytes(exchange(v2019, "auth")), v2019_auth);
  EXPECT_EQ(all_bytes(exchange(v2019, "auth-head-form")), head_auth);
  const Probe head = wr8_probe("svgui-head");
  EXPECT_EQ(all_bytes(exchange(head, "auth")), head_auth);
  EXPECT_EQ(all_bytes(exchange(head, "auth-v2019-form")), v2019_auth);
}

TEST(Wr8ProbeSvgui, V2019TasksThatWouldLeaveTheVehicleBusyGoWithCoi0) {
  // A type without an action (and a SETTINGS) keeps a v2019 vehicle busy
  // with its COI for good; with COI 0 it stays idle.
  const Probe probe = wr8_probe("svgui-2019");
  for (const auto* name : {"task-type-4", "task-unknown-type", "settings"}) {
    const Bytes bytes = all_bytes(exchange(probe, name));
    ASSERT_GE(bytes.size(), 3U) << name;
    EXPECT_EQ(bytes[2], 0) << name;
  }
  // Its SETTINGS values, read at the vehicle's offsets 2, 7, 12 and 17
  // (bytes past the packet as 0), are the defaults p 1, i 0, d 0, servo 90.
  const Bytes settings = all_bytes(exchange(probe, "settings"));
  ASSERT_EQ(settings.size(), 19U);  // the length byte and 18
  const auto le32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const std::size_t i = 1 + at + k;  // after the length byte
      v |= static_cast<std::uint32_t>(i < settings.size() ? settings[i] : 0) << (8 * k);
    }
    return static_cast<std::int32_t>(v);
  };
  EXPECT_EQ(le32(2), 1);
  EXPECT_EQ(le32(7), 0);
  EXPECT_EQ(le32(12), 0);
  EXPECT_EQ(le32(17), 90);
}

TEST(Wr8ProbeSvgui, OversizedIsALengthByteNoReceiverCanFrame) {
  for (const auto* profile : {"svgui-2019", "svgui-head"}) {
    SCOPED_TRACE(profile);
    const Probe probe = wr8_probe(profile);
    const auto& e = exchange(probe, "oversized");
    const Bytes bytes = all_bytes(e);
    ASSERT_EQ(bytes.size(), 129U);
    EXPECT_EQ(bytes[0], 0x80);
    const auto cut = frames(probe, e);
    ASSERT_FALSE(cut.empty());
    EXPECT_FALSE(cut[0].valid);
    EXPECT_EQ(cut[0].raw, Bytes{0x80});
    EXPECT_NE(cut[0].text.find("oversized"), std::string::npos) << cut[0].text;
  }
  // The v2019 one holds a whole 128-byte TASK: the program reads it anyway.
  const Bytes v2019 = all_bytes(exchange(wr8_probe("svgui-2019"), "oversized"));
  const auto item =
      svgui::decode_packet(protocol::ByteView(v2019).subspan(1), svgui::Version::v2019);
  const auto* frame = std::get_if<protocol::Frame<svgui::Message>>(&item);
  ASSERT_NE(frame, nullptr);
  EXPECT_EQ(std::get<svgui::Task>(frame->message).params.size(), 31U);
}

TEST(Wr8ProbeSvgui, HeadReconnectsAfterEveryExchangeThatLeavesBytesUnread) {
  // The head program reads one packet per arrival: bytes left behind
  // would shift every later answer by one packet.
  const Probe probe = wr8_probe("svgui-head");
  for (const auto* name : {"two-frames-one-write", "garbage-between-frames", "oversized"}) {
    const auto at = std::find_if(probe.exchanges.begin(), probe.exchanges.end(),
                                 [&](const Exchange& e) { return e.name == name; });
    ASSERT_NE(at, probe.exchanges.end()) << name;
    ASSERT_NE(at + 1, probe.exchanges.end()) << name;
    EXPECT_EQ((at + 1)->kind, ExchangeKind::connect) << name;
  }
}

}  // namespace
}  // namespace hil::conform
