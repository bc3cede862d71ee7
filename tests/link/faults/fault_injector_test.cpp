#include "link/faults/fault_injector.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>

#include "protocol/logi/codec.hpp"
#include "protocol/wr8/svgui.hpp"
#include "tests/link/faults/fault_test_support.hpp"

namespace hil::link {
namespace {

using namespace test;
using protocol::to_bytes;
namespace logi = protocol::logi;

Bytes sp(int percent) {
  return logi::encode(logi::SetSpeed{percent});
}
Bytes fb_st() {
  return logi::encode(logi::Feedback{logi::Command::st, true});
}
Bytes fb_sp() {
  return logi::encode(logi::Feedback{logi::Command::sp, true});
}
Bytes stat() {
  return logi::encode(logi::Status{});
}

/// `count` SP frames, one every `spacing` from `start`.
std::vector<Write> sp_writes(int count, Duration spacing, Time start = Time{0}) {
  std::vector<Write> w;
  for (int i = 0; i < count; ++i)
    w.push_back(Write{start + spacing * i, sp(i % 101)});
  return w;
}

std::vector<Bytes> valid_frames(const Bytes& stream) {
  std::vector<Bytes> out;
  for (const auto& f : decode("logi", stream)) {
    if (f.valid) out.push_back(f.raw);
  }
  return out;
}

TEST(FaultInjector, NoRulesDeliversEveryWriteAtOnce) {
  const auto writes = sp_writes(3, 10ms);
  const auto run = run_injector("logi", {}, writes);
  ASSERT_EQ(run.deliveries().size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(run.deliveries()[i].at, writes[i].at);
    EXPECT_EQ(std::get<Delivery>(run.deliveries()[i].what).bytes, writes[i].bytes);
  }
  EXPECT_TRUE(run.events.empty());
}

TEST(FaultInjector, DelayWithoutJitterDeliversExactlyThatLater) {
  const auto run = run_injector("logi", profile_of({rule(Delay{100ms, 0ms})}), {{1s, sp(50)}});
  ASSERT_EQ(run.deliveries().size(), 1U);
  EXPECT_EQ(run.deliveries()[0].at, Time{1100ms});
  EXPECT_EQ(run.delivered(), sp(50));
  ASSERT_EQ(run.events.size(), 1U);
  EXPECT_EQ(run.events[0].kind, FaultKind::delay);
  EXPECT_EQ(run.events[0].at, Time{1s});
  EXPECT_EQ(run.events[0].frame, 1U);
}

TEST(FaultInjector, DelayWithJitterNeverReordersTheStream) {
  const auto writes = sp_writes(60, 1ms);
  const auto run = run_injector("logi", profile_of({rule(Delay{10ms, 40ms})}), writes, 7);
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), writes.size());
  EXPECT_EQ(run.delivered(), concat([&] {
              std::vector<Bytes> all;
              for (const auto& w : writes)
                all.push_back(w.bytes);
              return all;
            }()));
  Time latest_allowed{0};
  bool held_back = false;
  for (std::size_t i = 0; i < d.size(); ++i) {
    latest_allowed = std::max(latest_allowed, writes[i].at + 50ms);
    EXPECT_GE(d[i].at, writes[i].at + 10ms);
    EXPECT_LE(d[i].at, latest_allowed);
    if (i > 0) {
      EXPECT_GE(d[i].at, d[i - 1].at);
    }
    // Delays are drawn to the nanosecond, so two frames leave at the same
    // instant only when the later one waited for the earlier.
    held_back = held_back || (i > 0 && d[i].at == d[i - 1].at);
  }
  EXPECT_TRUE(held_back) << "with 40 ms jitter and 1 ms spacing some frame waits for a slower one";
}

TEST(FaultInjector, FragmentPiecesStayInTheirSizeRangeAndGap) {
  const Bytes frame = stat();
  ASSERT_GT(frame.size(), 40U);
  Fragment f;
  f.piece_bytes = {3, 5};
  f.gap = {2ms, 2ms};
  const auto run = run_injector("logi", profile_of({rule(f)}), {{0ms, frame}});
  const auto d = run.deliveries();
  ASSERT_GE(d.size(), frame.size() / 5);
  for (std::size_t i = 0; i < d.size(); ++i) {
    const auto size = std::get<Delivery>(d[i].what).bytes.size();
    EXPECT_LE(size, 5U);
    if (i + 1 < d.size()) {
      EXPECT_GE(size, 3U);
    }
    EXPECT_EQ(d[i].at, Time{2ms} * static_cast<int>(i));
  }
  EXPECT_EQ(run.delivered(), frame);
  ASSERT_EQ(run.events_of(FaultKind::fragment).size(), 1U);
}

TEST(FaultInjector, CoalesceByCountDeliversThreeFramesInOneWrite) {
  Coalesce c;
  c.count = 3;
  const auto writes = sp_writes(3, 10ms);
  const auto run = run_injector("logi", profile_of({rule(c)}), writes);
  ASSERT_EQ(run.deliveries().size(), 1U);
  EXPECT_EQ(run.deliveries()[0].at, Time{20ms});
  EXPECT_EQ(run.delivered(), concat({writes[0].bytes, writes[1].bytes, writes[2].bytes}));
  EXPECT_EQ(valid_frames(run.delivered()).size(), 3U);
}

TEST(FaultInjector, CoalesceByWindowReleasesWhenTheWindowEnds) {
  Coalesce c;
  c.window = 50ms;
  const std::vector<Write> writes = {{0ms, sp(1)}, {10ms, sp(2)}, {70ms, sp(3)}};
  const auto run = run_injector("logi", profile_of({rule(c)}), writes, 1, false);
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 2U);
  EXPECT_EQ(d[0].at, Time{50ms});
  EXPECT_EQ(std::get<Delivery>(d[0].what).bytes, concat({sp(1), sp(2)}));
  EXPECT_EQ(d[1].at, Time{120ms});
  EXPECT_EQ(std::get<Delivery>(d[1].what).bytes, sp(3));
}

TEST(FaultInjector, CorruptChecksumMakesTheDecoderReportBadChecksumAndNothingElse) {
  Corrupt c;
  c.target = CorruptTarget::checksum;
  const Bytes frame = sp(50);
  const auto run = run_injector("logi", profile_of({rule(c)}), {{0ms, frame}});
  const Bytes out = run.delivered();
  ASSERT_EQ(out.size(), frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (i < frame.size() - 3 || i == frame.size() - 1) {
      EXPECT_EQ(out[i], frame[i]) << "byte " << i;
    }
  }
  EXPECT_NE(out, frame);
  std::vector<logi::Item> items;
  logi::Decoder decoder;
  decoder.feed(out, items);
  ASSERT_EQ(items.size(), 1U);
  ASSERT_TRUE(std::holds_alternative<protocol::DecodeError>(items[0]));
  EXPECT_EQ(std::get<protocol::DecodeError>(items[0]).kind, protocol::ErrorKind::bad_checksum);
  ASSERT_EQ(run.events.size(), 1U);
  EXPECT_EQ(run.events[0].before, frame);
  EXPECT_EQ(run.events[0].after, out);
}

TEST(FaultInjector, CorruptFieldChangesOnlyThatFieldAndKeepsItDigits) {
  Corrupt c;
  c.target = CorruptTarget::field;
  c.field = "value";
  const Bytes frame = sp(50);  // LOGI:SP:050:CS#
  const auto run = run_injector("logi", profile_of({rule(c)}), {{0ms, frame}}, 3);
  const Bytes out = run.delivered();
  ASSERT_EQ(out.size(), frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const bool in_value = i >= 8 && i < 11;
    if (in_value) {
      EXPECT_TRUE(out[i] >= '0' && out[i] <= '9');
    } else {
      EXPECT_EQ(out[i], frame[i]) << "byte " << i;
    }
  }
  EXPECT_NE(out, frame);
  const auto frames = decode("logi", out);
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_THAT(frames[0].text, testing::StartsWith("bad_checksum"));
}

TEST(FaultInjector, CorruptRandomFlipsExactlyTheBitsAsked) {
  Corrupt c;
  c.target = CorruptTarget::random;
  c.bits = 3;
  const Bytes frame = stat();
  const auto run = run_injector("logi", profile_of({rule(c)}), {{0ms, frame}}, 11);
  const Bytes out = run.delivered();
  ASSERT_EQ(out.size(), frame.size());
  int flipped = 0;
  for (std::size_t i = 0; i < frame.size(); ++i)
    flipped += std::popcount(static_cast<unsigned>(out[i] ^ frame[i]));
  EXPECT_EQ(flipped, 3);
}

TEST(FaultInjector, CorruptChecksumLeavesProtocolsWithoutOneAlone) {
  Corrupt c;
  c.target = CorruptTarget::checksum;
  const Bytes task = *protocol::parse_hex("03 01 01 04 64 00 00 00");
  const auto run = run_injector("wr8", profile_of({rule(c)}), {{0ms, task}});
  EXPECT_EQ(run.delivered(), task);
  EXPECT_TRUE(run.events.empty());
}

TEST(FaultInjector, DropTheFirstFeedbackOfAKind) {
  Trigger t;
  t.match = "FB:ST";
  t.first = 1;
  const std::vector<Write> writes = {
      {0ms, stat()}, {10ms, fb_st()}, {20ms, fb_sp()}, {30ms, fb_st()}};
  const auto run = run_injector("logi", profile_of({rule(Drop{}, t)}), writes);
  EXPECT_EQ(run.delivered(), concat({stat(), fb_sp(), fb_st()}));
  ASSERT_EQ(run.events.size(), 1U);
  EXPECT_EQ(run.events[0].kind, FaultKind::drop);
  EXPECT_EQ(run.events[0].frame, 2U);
  EXPECT_EQ(run.events[0].at, Time{10ms});
  EXPECT_EQ(run.events[0].before, fb_st());
  EXPECT_TRUE(run.events[0].after.empty());
}

TEST(FaultInjector, MatchComparesWholeKindParts) {
  Trigger t;
  t.match = "FB:S";  // neither FB:ST nor FB:SP
  const auto run =
      run_injector("logi", profile_of({rule(Drop{}, t)}), {{0ms, fb_st()}, {1ms, fb_sp()}});
  EXPECT_EQ(run.delivered(), concat({fb_st(), fb_sp()}));
  t.match = "FB";
  const auto all =
      run_injector("logi", profile_of({rule(Drop{}, t)}), {{0ms, fb_st()}, {1ms, fb_sp()}});
  EXPECT_TRUE(all.delivered().empty());
}

TEST(FaultInjector, AtFrameEveryAndWindowPickTheirFrames) {
  Trigger at;
  at.at_frame = 2;
  Trigger every;
  every.every = 3;
  const auto writes = sp_writes(7, 1s);  // frames at 0..6 s
  EXPECT_EQ(run_injector("logi", profile_of({rule(Drop{}, at)}), writes).events[0].frame, 2U);
  std::vector<std::uint64_t> dropped;
  for (const auto& e : run_injector("logi", profile_of({rule(Drop{}, every)}), writes).events) {
    dropped.push_back(e.frame);
  }
  EXPECT_THAT(dropped, testing::ElementsAre(3U, 6U));
  dropped.clear();
  for (const auto& e :
       run_injector("logi", profile_of({rule(Drop{}, {}, TimeWindow{2s, 4s})}), writes).events) {
    dropped.push_back(e.frame);
  }
  EXPECT_THAT(dropped, testing::ElementsAre(3U, 4U))
      << "frames at 2 s and 3 s; 4 s is outside [2 s, 4 s)";
}

TEST(FaultInjector, DropBytesRemovesThatManyConsecutiveBytes) {
  Drop d;
  d.unit = DropUnit::bytes;
  d.count = {2, 2};
  const Bytes frame = sp(42);
  const auto run = run_injector("logi", profile_of({rule(d)}), {{0ms, frame}});
  const Bytes out = run.delivered();
  ASSERT_EQ(out.size(), frame.size() - 2);
  std::size_t at = 0;
  while (at < out.size() && out[at] == frame[at])
    ++at;
  EXPECT_TRUE(std::equal(out.begin() + static_cast<std::ptrdiff_t>(at), out.end(),
                         frame.begin() + static_cast<std::ptrdiff_t>(at + 2)));
}

TEST(FaultInjector, DuplicateSendsTheFrameAgainInTheSameWrite) {
  const auto run = run_injector("logi", profile_of({rule(Duplicate{2})}), {{0ms, sp(9)}});
  ASSERT_EQ(run.deliveries().size(), 1U);
  EXPECT_EQ(valid_frames(run.delivered()), (std::vector<Bytes>{sp(9), sp(9), sp(9)}));
}

TEST(FaultInjector, GarbageGoesJustBeforeTheFrame) {
  Garbage g;
  g.fixed = to_bytes("\x01zz");
  const auto run = run_injector("logi", profile_of({rule(g)}), {{0ms, sp(1)}, {5ms, sp(2)}});
  EXPECT_EQ(run.delivered(), concat({to_bytes("\x01zz"), sp(1), to_bytes("\x01zz"), sp(2)}));
  EXPECT_EQ(valid_frames(run.delivered()), (std::vector<Bytes>{sp(1), sp(2)}));
  Garbage random;
  random.length = {4, 4};
  const auto noisy = run_injector("logi", profile_of({rule(random)}), {{0ms, sp(1)}});
  EXPECT_EQ(noisy.delivered().size(), sp(1).size() + 4);
}

TEST(FaultInjector, StallHoldsEverythingUntilItEnds) {
  FaultRule stall = rule(Stall{500ms});
  stall.trigger.at = 1s;
  const std::vector<Write> writes = {
      {900ms, sp(1)}, {1100ms, sp(2)}, {1200ms, sp(3)}, {1600ms, sp(4)}};
  const auto run = run_injector("logi", profile_of({stall}), writes);
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 4U);
  EXPECT_EQ(d[0].at, Time{900ms});
  EXPECT_EQ(d[1].at, Time{1500ms});
  EXPECT_EQ(d[2].at, Time{1500ms});
  EXPECT_EQ(d[3].at, Time{1600ms});
  ASSERT_EQ(run.events_of(FaultKind::stall).size(), 1U);
  EXPECT_EQ(run.events_of(FaultKind::stall)[0].at, Time{1s});
}

TEST(FaultInjector, StallChosenByAFrameHoldsThatFrameAndWhatIsQueued) {
  Trigger t;
  t.at_frame = 2;
  FaultRule delay = rule(Delay{50ms, 0ms});
  const std::vector<Write> writes = {{0ms, sp(1)}, {20ms, sp(2)}, {30ms, sp(3)}};
  const auto run = run_injector("logi", profile_of({delay, rule(Stall{100ms}, t)}), writes);
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 3U);
  EXPECT_EQ(d[0].at, Time{120ms}) << "due at 50 ms, inside the stall [20 ms, 120 ms)";
  EXPECT_EQ(d[1].at, Time{120ms});
  EXPECT_EQ(d[2].at, Time{120ms});
}

TEST(FaultInjector, BandwidthPacesWritesByTheirSize) {
  const Bytes ten = to_bytes("0123456789");
  const auto run = run_injector("raw", profile_of({rule(Bandwidth{1000})}),
                                {{0ms, ten}, {0ms, ten}, {0ms, ten}});
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 3U);
  EXPECT_EQ(d[0].at, Time{10ms});
  EXPECT_EQ(d[1].at, Time{20ms});
  EXPECT_EQ(d[2].at, Time{30ms});
  EXPECT_EQ(run.events_of(FaultKind::bandwidth).size(), 3U);
}

TEST(FaultInjector, ResetAfterFiveFrames) {
  Trigger t;
  t.at_frame = 5;
  const auto writes = sp_writes(8, 10ms);
  const auto run = run_injector("logi", profile_of({rule(Reset{}, t)}), writes);
  ASSERT_EQ(run.deliveries().size(), 5U);
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_TRUE(run.link_break()->reset);
  EXPECT_TRUE(std::holds_alternative<LinkBreak>(run.outputs.back().what));
  EXPECT_EQ(run.outputs.back().at, Time{40ms});
  ASSERT_EQ(run.events_of(FaultKind::reset).size(), 1U);
  EXPECT_EQ(run.events_of(FaultKind::reset)[0].frame, 5U);
}

TEST(FaultInjector, DisconnectAtATimeLosesWhatIsStillInFlight) {
  FaultRule cut = rule(Disconnect{});
  cut.trigger.at = 2s;
  const auto writes = sp_writes(5, 500ms);  // 0, 0.5, ..., 2 s
  const auto run =
      run_injector("logi", profile_of({rule(Delay{700ms, 0ms}), cut}), writes, 1, false);
  // Delivered at 0.7 s, 1.2 s, 1.7 s; the frames due at 2.2 s and later are lost.
  ASSERT_EQ(run.deliveries().size(), 3U);
  ASSERT_NE(run.link_break(), nullptr);
  EXPECT_FALSE(run.link_break()->reset);
  EXPECT_EQ(run.outputs.back().at, Time{2s});
  const auto e = run.events_of(FaultKind::disconnect);
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].at, Time{2s});
  EXPECT_EQ(e[0].before, sp(3))
      << "the frame pushed at 2 s arrives after the break and is not processed";
}

TEST(FaultInjector, RefuseIsActiveForItsDurationAndRecordsEachRefusal) {
  FaultRule refuse = rule(Refuse{2s});
  refuse.trigger.at = 1s;
  std::vector<FaultEvent> events;
  auto injector = make_injector("raw", profile_of({refuse}), events);
  EXPECT_FALSE(injector->refuse_connection(500ms));
  EXPECT_TRUE(injector->refuse_connection(1s));
  EXPECT_TRUE(injector->refuse_connection(2999ms));
  EXPECT_FALSE(injector->refuse_connection(3s));
  ASSERT_EQ(events.size(), 2U);
  EXPECT_EQ(events[0].kind, FaultKind::refuse);
  EXPECT_EQ(injector->faults_injected(), 2U);
}

/// Every delivered byte, in order.
Bytes joined(const std::vector<InjectorOutput>& out) {
  Bytes all;
  for (const auto& o : out) {
    const auto& b = std::get<Delivery>(o).bytes;
    all.insert(all.end(), b.begin(), b.end());
  }
  return all;
}

/// A rule that acts on every frame and changes nothing: the injector
/// frames the stream, as under any rule.
FaultProfile framing_rules() {
  return profile_of({rule(Delay{0ms, 0ms})});
}

TEST(FaultInjector, WithoutRulesAPartialFrameGoesOutAtOnceAsWritten) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("logi", {}, events);
  injector->push(0ms, to_bytes("LOGI:SP"));
  std::vector<InjectorOutput> out;
  injector->poll(0ms, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<Delivery>(out[0]).bytes, to_bytes("LOGI:SP"));
  injector->push(3ms, to_bytes(":0"));
  injector->poll(3ms, out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(std::get<Delivery>(out[1]).bytes, to_bytes(":0"));
  EXPECT_FALSE(injector->next_due());
}

TEST(FaultInjector, RulesArrivingInsideAFrameFrameAfreshAndSendNothingTwice) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("logi", {}, events);
  const Bytes frame = sp(77);
  const auto half = static_cast<std::ptrdiff_t>(frame.size() / 2);
  injector->push(0ms, Bytes(frame.begin(), frame.begin() + half));
  injector->set_profile(framing_rules());
  injector->push(1ms, Bytes(frame.begin() + half, frame.end()));
  injector->push(2ms, sp(40));
  std::vector<InjectorOutput> out;
  injector->poll(1s, out);
  const Bytes delivered = joined(out);
  Bytes written = frame;
  const Bytes next = sp(40);
  written.insert(written.end(), next.begin(), next.end());
  EXPECT_EQ(delivered, written);
}

TEST(FaultInjector, IncompleteFramesAreHeldUntilTheyComplete) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("logi", framing_rules(), events);
  const Bytes frame = sp(77);
  const auto half = static_cast<std::ptrdiff_t>(frame.size() / 2);
  injector->push(0ms, Bytes(frame.begin(), frame.begin() + half));
  EXPECT_EQ(injector->next_due(), Time{0ms} + kPartialFrameHold) << "half a frame is held";
  std::vector<InjectorOutput> out;
  injector->poll(5ms, out);
  EXPECT_TRUE(out.empty());
  injector->push(5ms, Bytes(frame.begin() + half, frame.end()));
  injector->poll(5ms, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<Delivery>(out[0]).bytes, frame);
  EXPECT_FALSE(injector->next_due());
}

TEST(FaultInjector, APartialFrameGoesOutAsWrittenOnceItsHoldEndsAfterTheLastWrite) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("logi", framing_rules(), events);
  injector->push(0ms, to_bytes("LOGI:SP"));
  injector->push(60ms, to_bytes(":0"));  // a later piece restarts the hold
  EXPECT_EQ(injector->next_due(), Time{60ms} + kPartialFrameHold);
  std::vector<InjectorOutput> out;
  injector->poll(159ms, out);
  EXPECT_TRUE(out.empty());
  injector->poll(160ms, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<Delivery>(out[0]).bytes, to_bytes("LOGI:SP:0"));
  EXPECT_FALSE(injector->next_due());
  // The stream goes on framing from the next byte.
  injector->push(200ms, sp(40));
  out.clear();
  injector->poll(200ms, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<Delivery>(out[0]).bytes, sp(40));
}

TEST(FaultInjector, AWr8PacketAndAStrayTrailingByteAreBothDelivered) {
  // A mock `send` behaviour writes bytes as given: a whole AUTH-REPLY and
  // one byte that starts a packet it never finishes. Both go out at once.
  std::vector<FaultEvent> events;
  auto injector = make_injector("wr8", {}, events, 1, Direction::to_client);
  const Bytes written{0x02, 0x08, 0x01, 0x02, 0x06};
  injector->push(0ms, written);
  std::vector<InjectorOutput> out;
  injector->poll(0ms, out);
  const Bytes delivered = joined(out);
  EXPECT_EQ(delivered, written);
  EXPECT_FALSE(injector->next_due());
}

// The real WR8 programs put a length byte before every packet
// (smart_vehicle_gui 8d80e92 and 431e8d4): with their profiles, rules act
// on the length byte and its packet as one frame.
namespace svgui = protocol::wr8::svgui;

std::shared_ptr<const ProtocolAdapter> svgui_head() {
  return protocol_adapter("wr8", "svgui-head");
}
Bytes high_freq(std::uint32_t timestamp_ms) {
  return svgui::encode_prefixed(svgui::HighFreqData{timestamp_ms, 1, 2, 3, 4, 5},
                                svgui::Version::head);
}
Bytes low_freq() {
  return svgui::encode_prefixed(svgui::LowFreqData{protocol::wr8::State::wait, 7, 87, 95, 40},
                                svgui::Version::head);
}
Bytes program_reply() {
  return svgui::encode_prefixed(svgui::kProgramAuthReply, svgui::Version::head);
}

TEST(FaultInjector, SvguiFragmentCutsTheMatchedPacketWithItsLengthByte) {
  Fragment f;
  f.piece_bytes = {10, 10};
  f.gap = {1ms, 1ms};
  Trigger t;
  t.match = "HIGH_FREQ_DATA";
  const Bytes high = high_freq(1000);
  ASSERT_EQ(high.size(), 66U);
  const auto run =
      run_injector(svgui_head(), profile_of({rule(f, t)}), {{0ms, program_reply()}, {10ms, high}});
  const auto d = run.deliveries();
  ASSERT_EQ(d.size(), 8U);  // the reply whole, then 7 pieces of the 66 bytes
  EXPECT_EQ(std::get<Delivery>(d[0].what).bytes, program_reply());
  EXPECT_EQ(std::get<Delivery>(d[1].what).bytes.front(), 0x41)
      << "the first piece opens with the length byte";
  for (std::size_t i = 1; i < d.size(); ++i)
    EXPECT_EQ(d[i].at, Time{10ms} + Time{1ms} * static_cast<int>(i - 1));
  EXPECT_EQ(run.delivered(), concat({program_reply(), high}));
  const auto events = run.events_of(FaultKind::fragment);
  ASSERT_EQ(events.size(), 1U);
  EXPECT_EQ(events[0].before, high);
  EXPECT_EQ(events[0].frame, 2U);
}

TEST(FaultInjector, SvguiCoalesceAndDropWorkOnWholePrefixedPackets) {
  Coalesce c;
  c.count = 3;
  const std::vector<Write> writes = {
      {0ms, high_freq(0)}, {50ms, high_freq(50)}, {100ms, high_freq(100)}};
  const auto coalesced = run_injector(svgui_head(), profile_of({rule(c)}), writes);
  ASSERT_EQ(coalesced.deliveries().size(), 1U);
  EXPECT_EQ(coalesced.deliveries()[0].at, Time{100ms});
  const auto frames = decode(*svgui_head(), coalesced.delivered());
  ASSERT_EQ(frames.size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(frames[i].valid) << frames[i].text;
    EXPECT_EQ(frames[i].raw, writes[i].bytes);
  }

  Trigger t;
  t.match = "LOW_FREQ_DATA";
  const auto dropped = run_injector(svgui_head(), profile_of({rule(Drop{}, t)}),
                                    {{0ms, high_freq(0)}, {1ms, low_freq()}, {2ms, high_freq(2)}});
  EXPECT_EQ(dropped.delivered(), concat({high_freq(0), high_freq(2)}));
  ASSERT_EQ(dropped.events.size(), 1U);
  EXPECT_EQ(dropped.events[0].before, low_freq()) << "the length byte goes with its packet";
}

TEST(FaultInjector, SvguiCorruptTargetsTheLengthByteOrTheCoi) {
  Corrupt length;
  length.target = CorruptTarget::field;
  length.field = "length";
  const Bytes high = high_freq(0);
  const auto run = run_injector(svgui_head(), profile_of({rule(length)}), {{0ms, high}});
  const Bytes out = run.delivered();
  ASSERT_EQ(out.size(), high.size());
  EXPECT_NE(out[0], high[0]);
  EXPECT_EQ(Bytes(out.begin() + 1, out.end()), Bytes(high.begin() + 1, high.end()));
  ASSERT_EQ(run.events.size(), 1U);
  EXPECT_EQ(run.events[0].detail, "field length: 1 byte changed");

  Corrupt coi;
  coi.target = CorruptTarget::field;
  coi.field = "coi";
  const Bytes task = svgui::encode_prefixed(svgui::Task{7, 1, {100}}, svgui::Version::v2019);
  const auto v2019 =
      run_injector(protocol_adapter("wr8", "svgui-2019"), profile_of({rule(coi)}), {{0ms, task}});
  const Bytes changed = v2019.delivered();
  ASSERT_EQ(changed.size(), task.size());
  for (std::size_t i = 0; i < task.size(); ++i) {
    if (i == 2) {
      EXPECT_NE(changed[i], task[i]) << "the COI follows the length byte and the code";
    } else {
      EXPECT_EQ(changed[i], task[i]) << "byte " << i;
    }
  }
  // The head programs' packets have no COI: the rule finds nothing to change.
  const auto head = run_injector(
      svgui_head(), profile_of({rule(coi)}),
      {{0ms, svgui::encode_prefixed(svgui::Answer{std::nullopt, 1}, svgui::Version::head)}});
  EXPECT_TRUE(head.events.empty());
}

TEST(FaultInjector, FinishReleasesAPartialFrame) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("logi", {}, events);
  injector->push(0ms, to_bytes("LOGI:SP:0"));
  injector->finish(1ms);
  std::vector<InjectorOutput> out;
  injector->poll(1ms, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(std::get<Delivery>(out[0]).bytes, to_bytes("LOGI:SP:0"));
  EXPECT_FALSE(injector->next_due());
}

TEST(FaultInjector, RulesForTheOtherDirectionDoNothing) {
  FaultRule drop = rule(Drop{});
  drop.direction = DirectionFilter::to_client;
  std::vector<FaultEvent> events;
  auto to_car = make_injector("logi", profile_of({drop}), events, 1, Direction::to_car);
  auto to_client = make_injector("logi", profile_of({drop}), events, 1, Direction::to_client);
  EXPECT_EQ(drive(*to_car, {{0ms, sp(1)}}).delivered(), sp(1));
  EXPECT_TRUE(drive(*to_client, {{0ms, sp(1)}}).delivered().empty());
  ASSERT_EQ(events.size(), 1U);
  EXPECT_EQ(events[0].direction, Direction::to_client);
}

TEST(FaultInjector, ProfileChangesWhileRunningKeepTheFrameCount) {
  std::vector<FaultEvent> events;
  auto injector = make_injector("logi", {}, events);
  auto first = drive(*injector, sp_writes(3, 1ms), false);
  EXPECT_EQ(first.deliveries().size(), 3U);
  Trigger t;
  t.at_frame = 5;
  injector->set_profile(profile_of({rule(Drop{}, t)}));
  auto second = drive(*injector, sp_writes(3, 1ms, 10ms), false);
  EXPECT_EQ(second.delivered(), concat({sp(0), sp(2)}))
      << "frame 5 is the second of the new writes";
  EXPECT_EQ(injector->frames_seen(), 6U);
  EXPECT_EQ(injector->faults_injected(), 1U);
  ASSERT_EQ(injector->profile().rules.size(), 1U);
}

TEST(FaultInjector, ReplacingTheRulesReleasesABatchBeingGatheredUnderTheOldOnes) {
  // The batch names its rule by index: the coalesce rule is the second of
  // two, and the new profile has none, so reading it later would be past
  // the end of the new rules.
  std::vector<FaultEvent> events;
  Coalesce c;
  c.count = 3;
  Trigger never;
  never.probability = 0.0;
  auto injector = make_injector("logi", profile_of({rule(Drop{}, never), rule(c)}), events);
  auto gathered = drive(*injector, sp_writes(2, 1ms), false, Time{1ms});
  EXPECT_TRUE(gathered.deliveries().empty()) << "two of three frames: still gathering";
  injector->set_profile(profile_of({}));
  auto after = drive(*injector, {{Duration(5ms), sp(7)}}, true);
  EXPECT_EQ(after.delivered(), concat({sp(0), sp(1), sp(7)}));
  ASSERT_EQ(events.size(), 1U);
  EXPECT_EQ(events[0].kind, FaultKind::coalesce);
  EXPECT_NE(events[0].detail.find("2 frames in one write (fault rules replaced)"),
            std::string::npos)
      << events[0].detail;
}

TEST(FaultInjector, ProbabilityFollowsTheSeedAndRoughlyTheRate) {
  Trigger half;
  half.probability = 0.5;
  const auto writes = sp_writes(1000, 1ms);
  const auto a = run_injector("logi", profile_of({rule(Drop{}, half)}), writes, 1234);
  const auto b = run_injector("logi", profile_of({rule(Drop{}, half)}), writes, 1234);
  const auto c = run_injector("logi", profile_of({rule(Drop{}, half)}), writes, 1235);
  EXPECT_EQ(a.delivered(), b.delivered());
  EXPECT_NE(a.delivered(), c.delivered());
  // 1000 fair coin flips: 400..600 holds with probability 1 - 2e-10.
  EXPECT_GE(a.events.size(), 400U);
  EXPECT_LE(a.events.size(), 600U);
}

TEST(FaultInjector, EachDirectionDrawsItsOwnStream) {
  Trigger half;
  half.probability = 0.5;
  std::vector<FaultEvent> events;
  auto to_car =
      make_injector("logi", profile_of({rule(Drop{}, half)}), events, 99, Direction::to_car);
  auto to_client =
      make_injector("logi", profile_of({rule(Drop{}, half)}), events, 99, Direction::to_client);
  EXPECT_NE(drive(*to_car, sp_writes(200, 1ms)).delivered(),
            drive(*to_client, sp_writes(200, 1ms)).delivered());
  EXPECT_EQ(to_car->seed(), 99U);
}

TEST(FaultInjector, InvalidProfilesAreProgrammingErrors) {
  Fragment f;
  f.piece_bytes = {5, 2};
  EXPECT_THROW(FaultInjector(Direction::to_car, protocol_adapter("raw"), profile_of({rule(f)}), 1),
               std::invalid_argument);
  EXPECT_THROW(
      FaultInjector(Direction::to_car, protocol_adapter("raw"), profile_of({rule(Stall{1s})}), 1),
      std::invalid_argument)
      << "a stall needs a time or a frame trigger";
}

}  // namespace
}  // namespace hil::link
