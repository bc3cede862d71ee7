// The WR8 client core for the real smart_vehicle_gui dialects (svgui-2019,
// svgui-head) on its own, fed bytes in exact virtual time: the AUTH of each
// version and the fixed AUTH-REPLY, the login timeout, v2019 tasks matched by
// COI and their timeouts, SETTINGS never answered, head CONTROL every 100 ms,
// SET and its read-back, the DATA streams and their stale flags, the MAP, and
// bytes that must never become a message. Every packet the fidelity notes
// quote is a vector here, written out byte by byte.

#include "client/wr8/svgui_core.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <string>
#include <vector>

#include "tests/client/client_test_support.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;
using svgui::Version;

protocol::Bytes hex(std::string_view text) {
  auto b = protocol::parse_hex(text);
  EXPECT_TRUE(b) << text;
  return b.value_or(protocol::Bytes{});
}

using test::events_of;
using test::has;

std::vector<protocol::Bytes> sent(const std::vector<Action>& actions) {
  return test::sent_bytes<SendBytes>(actions);
}

SvguiConfig config_for(Version version) {
  SvguiConfig c;
  c.version = version;
  return c;
}

// The fidelity notes' vectors, length byte first.
const char* const kAuth2019 = "0B 01 6B 6F 6E 6E 69 63 68 69 77 61";
const char* const kAuthHead = "0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00";
const char* const kAuthReply = "04 02 01 02 03";
// v2019 DATA, 42 bytes: RUN, 36000000 ms, encoder 150, steering 12.5,
// motor battery 87, computer battery 93.
const char* const kData2019 =
    "2A 06 01 02 25 51 00  00 00 00 01 00 00 00 96  00 00 00 02 40 29 00 00 00 00 00 00"
    "  00 00 00 03 00 00 00 57  00 00 00 04 00 00 00 5D";
// head HIGH-FREQ DATA, 65 bytes: 36000050 ms, encoder 1.5, steering -0.25,
// x 2, y 0.5, angle 90.
const char* const kHighFreq =
    "41 09 02 25 51 32  00 00 00 01 3F F8 00 00 00 00 00 00  00 00 00 02 BF D0 00 00 00 00 00 00"
    "  00 00 00 03 40 00 00 00 00 00 00 00  00 00 00 04 3F E0 00 00 00 00 00 00"
    "  00 00 00 05 40 56 80 00 00 00 00 00";
// head LOW-FREQ DATA, 34 bytes: WAIT, 36000000 ms, motor 80, computer 75,
// temperature 41.5.
const char* const kLowFreq =
    "22 08 03 02 25 51 00  00 00 00 01 00 00 00 50  00 00 00 02 00 00 00 4B"
    "  00 00 00 03 40 44 C0 00 00 00 00 00";

// head MAP of 8 x 6 (79 bytes): walls around the edge.
protocol::Bytes map_8x6() {
  std::string text = "4F 07 08 06 00 00 00 06";
  for (int row = 0; row < 6; ++row) {
    text += " 00 00 00 08";
    for (int col = 0; col < 8; ++col)
      text += (row == 0 || row == 5 || col == 0 || col == 7) ? " 01" : " 00";
  }
  return hex(text);
}

/// A core of `version` logged in at 0 ms, its actions and events taken.
/// Packets go out at once (no send_gap): the spacing has its own test.
SvguiClientCore logged_in(Version version, SvguiConfig config = {}) {
  config.version = version;
  config.send_gap = Duration{0};
  SvguiClientCore core(std::move(config));
  core.connect(Time{0});
  core.on_connected(Time{0});
  core.on_bytes(Time{0}, hex(kAuthReply));
  EXPECT_EQ(core.state(), ConnectionState::connected);
  core.take_actions();
  core.take_events();
  return core;
}

TEST(SvguiCore, V2019LogsInWithTheTenLetterAuthAndTheFixedReply) {
  SvguiClientCore core(config_for(Version::v2019));
  core.connect(Time{0});
  EXPECT_TRUE(has(core.take_actions(), OpenConnection{}));
  core.on_connected(milliseconds(2));
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex(kAuth2019));
  EXPECT_EQ(core.state(), ConnectionState::authenticating);
  EXPECT_EQ(core.next_wakeup(), milliseconds(3002));
  EXPECT_EQ(core.forward(milliseconds(3), 10).refusal, Refusal::not_connected);

  core.on_bytes(milliseconds(5), hex(kAuthReply));
  EXPECT_EQ(core.state(), ConnectionState::connected);
  const auto logins = events_of<LoginEvent>(core.take_events());
  ASSERT_EQ(logins.size(), 1u);
  EXPECT_EQ(logins[0].reply, svgui::kProgramAuthReply);
  EXPECT_EQ(logins[0].reply.device_code, 1);
  EXPECT_EQ(logins[0].reply.device_id, 2);
  EXPECT_EQ(logins[0].reply.state, proto::State::wait);
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
}

TEST(SvguiCore, WithoutWaitingForLoginTheConnectionIsUsedOnceAuthIsOut) {
  // The real v2019 vehicle answers no login; its own GUI sends tasks anyway.
  SvguiConfig config = config_for(Version::v2019);
  config.wait_for_login = false;
  SvguiClientCore core(config);
  core.connect(Time{0});
  core.take_actions();
  core.on_connected(milliseconds(2));
  EXPECT_EQ(sent(core.take_actions()), std::vector<protocol::Bytes>{hex(kAuth2019)});
  EXPECT_EQ(core.state(), ConnectionState::connected);
  EXPECT_TRUE(events_of<LoginEvent>(core.take_events()).empty());  // no phantom login
  EXPECT_EQ(core.next_wakeup(), std::nullopt);                     // no login timeout
  const auto f = core.forward(milliseconds(60), 10);
  EXPECT_EQ(f.refusal, Refusal::none);
  core.on_timer(milliseconds(60));
  EXPECT_EQ(sent(core.take_actions()),
            std::vector<protocol::Bytes>{hex("08 03 01 01 01 0A 00 00 00")});
  // A reply that does come is still the login, once.
  core.on_bytes(milliseconds(70), hex(kAuthReply));
  EXPECT_EQ(events_of<LoginEvent>(core.take_events()).size(), 1u);
  core.on_bytes(milliseconds(80), hex(kAuthReply));
  EXPECT_TRUE(events_of<LoginEvent>(core.take_events()).empty());
}

TEST(SvguiCore, HeadAuthCarriesTheTrailingNul) {
  SvguiClientCore core(config_for(Version::head));
  core.connect(Time{0});
  core.on_connected(Time{0});
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex(kAuthHead));
  EXPECT_EQ(svgui_auth_text(Version::head).size(), 11u);
  EXPECT_EQ(svgui_auth_text(Version::v2019).size(), 10u);
}

TEST(SvguiCore, NoReplyWithinTheLoginTimeoutClosesAndRetriesOnTheBackoff) {
  SvguiClientCore core(config_for(Version::head));
  test::connected_at_zero(core);
  core.on_timer(milliseconds(2999));
  EXPECT_EQ(core.state(), ConnectionState::authenticating);
  core.on_timer(seconds(3));
  EXPECT_TRUE(has(core.take_actions(), CloseConnection{}));
  const auto failed = events_of<LoginFailedEvent>(core.take_events());
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0].reason, "AUTH-REPLY timeout");
  EXPECT_EQ(core.state(), ConnectionState::reconnecting);
  EXPECT_EQ(core.next_wakeup(), seconds(4));
  core.on_timer(seconds(4));
  EXPECT_TRUE(has(core.take_actions(), OpenConnection{}));

  // The timeout is a setting with its unit.
  SvguiConfig quick = config_for(Version::v2019);
  quick.login_timeout = milliseconds(500);
  SvguiClientCore other(quick);
  other.connect(Time{0});
  other.on_connected(milliseconds(10));
  EXPECT_EQ(other.next_wakeup(), milliseconds(510));
}

TEST(SvguiCore, V2019TasksGoOutLittleEndianAndEndByTheirCoi) {
  auto core = logged_in(Version::v2019);
  const auto f = core.forward(milliseconds(10), 100);
  const auto w = core.wheels(milliseconds(10), -15);
  const auto s = core.signals(milliseconds(10));
  EXPECT_EQ(f.coi, 1);  // COI 0 means "idle" to the vehicle: never used
  EXPECT_EQ(w.coi, 2);
  EXPECT_EQ(s.coi, 3);
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], hex("08 03 01 01 01 64 00 00 00"));
  EXPECT_EQ(out[1], hex("08 03 02 02 01 F1 FF FF FF"));
  EXPECT_EQ(out[2], hex("04 03 03 03 00"));
  auto sent_events = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(sent_events.size(), 3u);
  EXPECT_EQ(sent_events[0].state, RequestState::sent);
  EXPECT_EQ(sent_events[0].task, proto::TaskCode::drive);
  EXPECT_TRUE(sent_events[0].note.empty());
  // Sent while another is open: the vehicle would drop it, and the event says so.
  EXPECT_NE(sent_events[1].note.find("drops this one"), std::string::npos);

  // "Started" (1) is in the protocol, though the vehicle never sends it:
  // the task stays open on its deadline.
  core.on_bytes(milliseconds(15), hex("03 05 03 01"));
  const auto started = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(started.size(), 1u);
  EXPECT_EQ(started[0].coi, 3);
  EXPECT_EQ(started[0].state, RequestState::started);
  EXPECT_EQ(core.open_requests(), 3u);

  // Answers in any order, each to its COI: 2 done, 0 error.
  core.on_bytes(milliseconds(20), hex("03 05 02 02"));
  core.on_bytes(milliseconds(30), hex("03 05 01 00"));
  const auto ends = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(ends.size(), 2u);
  EXPECT_EQ(ends[0].coi, 2);
  EXPECT_EQ(ends[0].state, RequestState::completed);
  EXPECT_EQ(ends[1].coi, 1);
  EXPECT_EQ(ends[1].state, RequestState::error);
  EXPECT_EQ(core.open_requests(), 1u);
  EXPECT_EQ(core.next_wakeup(), milliseconds(5010));  // signals: 5 s from the send
}

TEST(SvguiCore, AV2019TaskWithoutAnswerTimesOutAndSaysWhy) {
  auto core = logged_in(Version::v2019);
  const auto f = core.forward(seconds(1), 50);
  core.take_events();
  EXPECT_EQ(core.next_wakeup(), seconds(31));
  core.on_timer(seconds(31) - milliseconds(1));
  EXPECT_TRUE(core.take_events().empty());
  core.on_timer(seconds(31));
  const auto ends = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_EQ(ends[0].coi, f.coi);
  EXPECT_EQ(ends[0].state, RequestState::timed_out);
  EXPECT_NE(ends[0].note.find("no ANSWER within 30s"), std::string::npos) << ends[0].note;
  EXPECT_NE(ends[0].note.find("sends no \"started\""), std::string::npos) << ends[0].note;
  EXPECT_NE(ends[0].note.find("drops a task"), std::string::npos) << ends[0].note;

  // A late answer, or another GUI's (ANSWER goes to every connection), changes nothing.
  core.on_bytes(seconds(32), hex("03 05 01 02"));
  const auto events = core.take_events();
  EXPECT_TRUE(events_of<RequestEvent>(events).empty());
  ASSERT_EQ(events_of<PacketIgnoredEvent>(events).size(), 1u);
}

TEST(SvguiCore, V2019CoisRunFrom1To126AndSkipOpenOnes) {
  auto core = logged_in(Version::v2019);
  const auto first = core.forward(Time{0}, 1);  // stays open: COI 1
  EXPECT_EQ(first.coi, 1);
  for (int i = 2; i <= 126; ++i) {
    const auto r = core.signals(Time{0});
    ASSERT_EQ(r.coi, i);
    core.on_bytes(Time{0}, protocol::Bytes{0x03, 0x05, r.coi, 0x02});
  }
  // Wraps past 126 to 1, which is open, so 2.
  EXPECT_EQ(core.signals(Time{0}).coi, 2);
  EXPECT_EQ(core.open_requests(), 2u);
}

TEST(SvguiCore, V2019SettingsAreSentNeverAnsweredAndLeaveNothingOpen) {
  auto core = logged_in(Version::v2019);
  const auto r = core.settings(milliseconds(10), {1, 2, 3, 90});
  ASSERT_TRUE(r);
  EXPECT_EQ(r.coi, 1);
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0],
            hex("12 04 01  01 00 00 00  02 00 00 00  03 00 00 00  5A 00 00 00"));  // 18 bytes
  const auto events = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, RequestKind::settings);
  EXPECT_EQ(events[0].state, RequestState::sent);
  EXPECT_NE(events[0].note.find("never answers SETTINGS"), std::string::npos) << events[0].note;
  EXPECT_EQ(core.open_requests(), 0u);
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
  EXPECT_EQ(core.forward(milliseconds(20), 5).coi, 2);  // the COI was used
}

TEST(SvguiCore, V2019DataFillsTheLiveStateAndGoesStaleAfter500Ms) {
  auto core = logged_in(Version::v2019);
  const auto packet = hex(kData2019);
  ASSERT_EQ(packet.size(), 43u);  // 42 and the length byte
  core.on_bytes(milliseconds(100), packet);
  const auto data = events_of<DataEvent>(core.take_events());
  ASSERT_EQ(data.size(), 1u);
  const svgui::Data want{proto::State::run, 36000000, 150, 12.5, 87, 93};
  EXPECT_EQ(data[0].data, want);
  ASSERT_TRUE(core.data());
  EXPECT_EQ(core.data()->at, milliseconds(100));
  EXPECT_EQ(core.next_wakeup(), milliseconds(600));
  core.on_timer(milliseconds(600));
  const auto stale = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_TRUE(stale[0].stale);
  EXPECT_EQ(stale[0].stream, DataStream::data);
  EXPECT_TRUE(core.stale(DataStream::data));
  core.on_bytes(milliseconds(700), packet);
  const auto again = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(again.size(), 1u);
  EXPECT_FALSE(again[0].stale);
}

TEST(SvguiCore, HeadStreamsFillTheirStateEachWithItsOwnStaleFlag) {
  auto core = logged_in(Version::head);
  const auto high = hex(kHighFreq);
  const auto low = hex(kLowFreq);
  ASSERT_EQ(high.size(), 66u);
  ASSERT_EQ(low.size(), 35u);
  core.on_bytes(milliseconds(50), high);
  core.on_bytes(milliseconds(50), low);
  auto events = core.take_events();
  const auto h = events_of<HighFreqEvent>(events);
  const auto l = events_of<LowFreqEvent>(events);
  ASSERT_EQ(h.size(), 1u);
  ASSERT_EQ(l.size(), 1u);
  EXPECT_EQ(h[0].data, (svgui::HighFreqData{36000050, 1.5, -0.25, 2.0, 0.5, 90.0}));
  EXPECT_EQ(l[0].data, (svgui::LowFreqData{proto::State::wait, 36000000, 80, 75, 41.5}));
  EXPECT_EQ(core.high_freq()->at, milliseconds(50));
  EXPECT_EQ(core.low_freq()->value.temperature, 41.5);

  // HIGH-FREQ stale 250 ms (five periods) after its last packet; LOW-FREQ keeps going.
  EXPECT_EQ(core.next_wakeup(), milliseconds(300));
  core.on_timer(milliseconds(300));
  auto stale = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].stream, DataStream::high_freq);
  EXPECT_TRUE(core.stale(DataStream::high_freq));
  EXPECT_FALSE(core.stale(DataStream::low_freq));
  EXPECT_EQ(core.next_wakeup(), milliseconds(5050));
  core.on_timer(milliseconds(5050));
  stale = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].stream, DataStream::low_freq);
  core.on_bytes(milliseconds(5100), high);
  stale = events_of<StaleEvent>(core.take_events());
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].stream, DataStream::high_freq);
  EXPECT_FALSE(stale[0].stale);
  EXPECT_TRUE(core.stale(DataStream::low_freq));
}

TEST(SvguiCore, HeadMapIsKept) {
  auto core = logged_in(Version::head);
  const auto packet = map_8x6();
  ASSERT_EQ(packet.size(), 80u);  // 79 and the length byte
  core.on_bytes(milliseconds(1), packet);
  const auto maps = events_of<MapEvent>(core.take_events());
  ASSERT_EQ(maps.size(), 1u);
  ASSERT_TRUE(core.map());
  EXPECT_EQ(core.map()->width, 8);
  EXPECT_EQ(core.map()->height, 6);
  ASSERT_EQ(core.map()->rows.size(), 6u);
  EXPECT_EQ(core.map()->rows[0], std::vector<std::int8_t>(8, 1));
  EXPECT_EQ(core.map()->rows[2], (std::vector<std::int8_t>{1, 0, 0, 0, 0, 0, 0, 1}));
}

TEST(SvguiCore, HeadControlRepeatsEvery100MsUntilReleased) {
  auto core = logged_in(Version::head);
  ASSERT_EQ(core.control(seconds(1), 0.5, -0.25), Refusal::none);
  const protocol::Bytes first =
      hex("19 0A 00 00 00 01 3F E0 00 00 00 00 00 00 00 00 00 02 BF D0 00 00 00 00 00 00");
  auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], first);
  EXPECT_EQ(core.next_wakeup(), milliseconds(1100));
  core.on_timer(milliseconds(1100));
  out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], first);
  // A change goes out at once; the grid stays.
  ASSERT_EQ(core.control(milliseconds(1150), 0.0, 1.0), Refusal::none);
  EXPECT_EQ(sent(core.take_actions()).size(), 1u);
  EXPECT_EQ(core.next_wakeup(), milliseconds(1200));
  // A late timer sends once and keeps to the grid.
  core.on_timer(milliseconds(1450));
  EXPECT_EQ(sent(core.take_actions()).size(), 1u);
  EXPECT_EQ(core.next_wakeup(), milliseconds(1500));

  ASSERT_EQ(core.release_control(milliseconds(1460)), Refusal::none);
  out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex("19 0A 00 00 00 01 00 00 00 00 00 00 00 00 00 00 00 02 00 00 00 00 00 "
                        "00 00 00"));
  EXPECT_EQ(core.next_wakeup(), std::nullopt);
  EXPECT_FALSE(core.held_control());

  EXPECT_EQ(core.control(seconds(2), 1.5, 0), Refusal::bad_request);
  EXPECT_EQ(core.control(seconds(2), 0, -1.01), Refusal::bad_request);
  EXPECT_TRUE(core.take_actions().empty());
}

TEST(SvguiCore, HeadSetWaitsForAnswerAndTimesOutAfterASecond) {
  auto core = logged_in(Version::head);
  svgui::Set set;
  set.values[0] = 1.5;
  set.values[4] = 2;
  ASSERT_TRUE(core.set(milliseconds(10), set));
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].size(), 98u);
  EXPECT_EQ(out[0][0], 0x61);  // 97 bytes: the code and twelve doubles
  EXPECT_EQ(out[0][1], 0x04);
  EXPECT_EQ(protocol::Bytes(out[0].begin() + 2, out[0].begin() + 10),
            hex("3F F8 00 00 00 00 00 00"));
  EXPECT_EQ(core.set(milliseconds(11), set).refusal, Refusal::busy);
  core.on_bytes(milliseconds(20), hex("02 05 01"));
  auto ends = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(ends.size(), 2u);
  EXPECT_EQ(ends[1].state, RequestState::completed);
  EXPECT_EQ(ends[1].kind, RequestKind::settings);
  EXPECT_EQ(ends[1].coi, 0);

  ASSERT_TRUE(core.set(seconds(1), set));
  core.on_bytes(milliseconds(1500), hex("02 05 00"));
  ends = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(ends.size(), 2u);
  EXPECT_EQ(ends[1].state, RequestState::error);

  ASSERT_TRUE(core.set(seconds(2), set));
  core.take_events();
  core.on_timer(seconds(3));
  ends = events_of<RequestEvent>(core.take_events());
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_EQ(ends[0].state, RequestState::timed_out);
  EXPECT_NE(ends[0].note.find("answer no SET"), std::string::npos) << ends[0].note;
  // An ANSWER with nothing open is ignored, not a phantom success.
  core.on_bytes(seconds(4), hex("02 05 01"));
  EXPECT_EQ(events_of<PacketIgnoredEvent>(core.take_events()).size(), 1u);
}

TEST(SvguiCore, HeadSetRequestIsAnsweredByASetPacket) {
  auto core = logged_in(Version::head);
  ASSERT_TRUE(core.set_request(milliseconds(5)));
  const auto out = sent(core.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex("01 06"));
  svgui::Set back;
  for (std::size_t i = 0; i < back.values.size(); ++i)
    back.values[i] = static_cast<double>(i) + 0.5;
  core.on_bytes(milliseconds(30), svgui::encode_prefixed(back, Version::head));
  const auto events = core.take_events();
  const auto read = events_of<SetReadEvent>(events);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].set, back);
  const auto req = events_of<RequestEvent>(events);
  ASSERT_EQ(req.size(), 2u);
  EXPECT_EQ(req[1].task, proto::TaskCode::get_settings);
  EXPECT_EQ(req[1].state, RequestState::completed);
  EXPECT_EQ(core.read_settings(), back);
}

TEST(SvguiCore, PacketsAreSpaced50MsSoTheRealProgramsReadEachAlone) {
  // v2019 reads whatever has come as one packet: a TASK right behind the
  // AUTH would be read as part of it.
  SvguiClientCore v2019(config_for(Version::v2019));
  v2019.connect(Time{0});
  v2019.on_connected(Time{0});
  v2019.on_bytes(milliseconds(2), hex(kAuthReply));
  v2019.take_actions();
  const auto f = v2019.forward(milliseconds(10), 100);
  const auto w = v2019.wheels(milliseconds(20), 5);
  EXPECT_TRUE(sent(v2019.take_actions()).empty());
  EXPECT_EQ(v2019.queued(), 2u);
  EXPECT_EQ(f.coi, 1);
  EXPECT_EQ(w.coi, 2);
  EXPECT_EQ(v2019.next_wakeup(), milliseconds(50));
  v2019.on_timer(milliseconds(50));
  auto out = sent(v2019.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex("08 03 01 01 01 64 00 00 00"));
  EXPECT_EQ(v2019.next_wakeup(), milliseconds(100));
  v2019.on_timer(milliseconds(100));
  out = sent(v2019.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex("08 03 02 02 01 05 00 00 00"));
  EXPECT_EQ(v2019.queued(), 0u);
  // The deadlines count from the request, not from the write.
  EXPECT_EQ(v2019.next_wakeup(), milliseconds(3020));

  // head: a newer CONTROL replaces a waiting one; a disconnect sends what
  // waits, the release last, and then closes.
  SvguiClientCore head(config_for(Version::head));
  head.connect(Time{0});
  head.on_connected(Time{0});
  head.on_bytes(milliseconds(2), hex(kAuthReply));
  head.take_actions();
  ASSERT_TRUE(head.set_request(milliseconds(10)));
  ASSERT_EQ(head.control(milliseconds(20), 0.5, 0.5), Refusal::none);
  ASSERT_EQ(head.control(milliseconds(30), 0.25, 0.25), Refusal::none);
  EXPECT_EQ(head.queued(), 2u);
  head.on_timer(milliseconds(50));
  out = sent(head.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], hex("01 06"));
  head.on_timer(milliseconds(100));
  out = sent(head.take_actions());
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], svgui::encode_prefixed(svgui::Control{0.25, 0.25}, Version::head));
  ASSERT_EQ(head.control(milliseconds(110), 1, 1), Refusal::none);
  head.disconnect(milliseconds(120));
  const auto actions = head.take_actions();
  ASSERT_EQ(actions.size(), 2u);
  EXPECT_EQ(sent(actions).at(0), svgui::encode_prefixed(svgui::Control{0, 0}, Version::head));
  EXPECT_EQ(actions[1], Action(CloseConnection{}));
}

TEST(SvguiCore, EachVersionRefusesTheOthersRequests) {
  auto v2019 = logged_in(Version::v2019);
  EXPECT_EQ(v2019.control(Time{0}, 0, 0), Refusal::bad_request);
  EXPECT_EQ(v2019.set(Time{0}, {}).refusal, Refusal::bad_request);
  EXPECT_EQ(v2019.set_request(Time{0}).refusal, Refusal::bad_request);
  auto head = logged_in(Version::head);
  EXPECT_EQ(head.forward(Time{0}, 10).refusal, Refusal::bad_request);
  EXPECT_EQ(head.signals(Time{0}).refusal, Refusal::bad_request);
  EXPECT_EQ(head.settings(Time{0}, {}).refusal, Refusal::bad_request);
  EXPECT_TRUE(v2019.take_actions().empty());
  EXPECT_TRUE(head.take_actions().empty());
}

TEST(SvguiCore, UndecodableBytesAreParseErrorsNeverMessages) {
  auto core = logged_in(Version::v2019);
  // A zero length byte, a negative one, DATA cut short by its length byte,
  // a head-only code, and a TASK (a GUI packet) from the vehicle.
  core.on_bytes(milliseconds(1), hex("00  80  05 06 01 00 00 00  02 09 00  04 03 01 01 00"));
  const auto events = core.take_events();
  const auto errors = events_of<ParseErrorEvent>(events);
  ASSERT_EQ(errors.size(), 4u);
  EXPECT_EQ(errors[0].error.kind, protocol::ErrorKind::bad_format);
  EXPECT_EQ(errors[0].error.raw, hex("00"));
  EXPECT_EQ(errors[1].error.kind, protocol::ErrorKind::oversized);
  EXPECT_EQ(errors[2].error.kind, protocol::ErrorKind::bad_format);
  EXPECT_EQ(errors[2].error.raw, hex("05 06 01 00 00 00"));
  EXPECT_EQ(errors[3].error.kind, protocol::ErrorKind::unknown_code);
  const auto ignored = events_of<PacketIgnoredEvent>(events);
  ASSERT_EQ(ignored.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<svgui::Task>(ignored[0].message));
  EXPECT_TRUE(events_of<DataEvent>(events).empty());
  EXPECT_EQ(core.state(), ConnectionState::connected);
}

TEST(SvguiCore, AHeadHighFreqStreamFullOf02BytesNeverLogsIn) {
  SvguiClientCore core(config_for(Version::head));
  core.connect(Time{0});
  core.on_connected(Time{0});
  core.take_events();
  // Every value holds the bytes of an AUTH-REPLY ("04 02 01 02 03") and more 02s.
  const double v = std::bit_cast<double>(std::uint64_t{0x0402010203020202});
  const auto packet =
      svgui::encode_prefixed(svgui::HighFreqData{0x02020202, v, v, v, v, v}, Version::head);
  protocol::Bytes stream;
  for (int i = 0; i < 59; ++i)
    stream.insert(stream.end(), packet.begin(), packet.end());
  // One packet per 50 ms, then everything again at once, then byte by byte.
  for (int i = 0; i < 59; ++i)
    core.on_bytes(milliseconds(50 * i), packet);
  core.on_bytes(milliseconds(2960), stream);
  for (const std::uint8_t b : stream)
    core.on_bytes(milliseconds(2990), protocol::ByteView(&b, 1));
  auto events = core.take_events();
  EXPECT_TRUE(events_of<LoginEvent>(events).empty());
  EXPECT_TRUE(events_of<ParseErrorEvent>(events).empty());
  EXPECT_EQ(events_of<PacketIgnoredEvent>(events).size(), 3u * 59u);  // "before login"
  EXPECT_TRUE(events_of<HighFreqEvent>(events).empty());
  EXPECT_EQ(core.state(), ConnectionState::authenticating);
  core.on_timer(seconds(3));
  EXPECT_EQ(events_of<LoginFailedEvent>(core.take_events()).size(), 1u);
}

/// Every event as a line, for comparing runs.
std::vector<std::string> lines(const std::vector<SvguiEvent>& events) {
  std::vector<std::string> out;
  for (const auto& e : events)
    out.push_back(describe(e));
  return out;
}

TEST(SvguiCore, CoalescedAndByteSplitStreamsGiveTheSameEvents) {
  protocol::Bytes stream = hex(kAuthReply);
  for (const auto& part : {map_8x6(), hex(kHighFreq), hex(kLowFreq), hex("80"), hex(kHighFreq),
                           hex("02 05 01"), hex("03 0B 00 00"), hex(kHighFreq)})
    stream.insert(stream.end(), part.begin(), part.end());

  auto run = [&](const std::vector<std::size_t>& cuts) {
    SvguiClientCore core(config_for(Version::head));
    core.connect(Time{0});
    core.on_connected(Time{0});
    std::size_t from = 0;
    for (const std::size_t cut : cuts) {
      core.on_bytes(milliseconds(10), protocol::ByteView(stream.data() + from, cut - from));
      from = cut;
    }
    return lines(core.take_events());
  };
  const auto whole = run({stream.size()});
  std::vector<std::size_t> every_byte;
  for (std::size_t i = 1; i <= stream.size(); ++i)
    every_byte.push_back(i);
  std::vector<std::size_t> odd = {3, 4, 70, 71, 150, 151, 152, stream.size()};
  EXPECT_EQ(run(every_byte), whole);
  EXPECT_EQ(run(odd), whole);

  ASSERT_GE(whole.size(), 4u);
  // The login comes first; then one event per packet, in order.
  EXPECT_EQ(whole[2], "connection connected");
  EXPECT_EQ(whole[3], "logged in: device 1, id 2, WAIT");
  ASSERT_EQ(whole.size(), 12u) << ::testing::PrintToString(whole);
  EXPECT_EQ(whole[4], "Map 8x6 (6 rows)");
  EXPECT_EQ(whole[5].rfind("HighFreqData t=36000050ms", 0), 0u) << whole[5];
  EXPECT_EQ(whole[6].rfind("LowFreqData state=WAIT", 0), 0u) << whole[6];
  EXPECT_EQ(whole[7].rfind("bad bytes received (oversized)", 0), 0u) << whole[7];
  EXPECT_EQ(whole[8].rfind("HighFreqData", 0), 0u) << whole[8];
  EXPECT_EQ(whole[9], "ignored Answer code=1 (ANSWER with no SET open)");
  EXPECT_EQ(whole[10].rfind("bad bytes received (unknown_code)", 0), 0u) << whole[10];
  EXPECT_EQ(whole[11].rfind("HighFreqData", 0), 0u) << whole[11];
}

TEST(SvguiCore, ADropCancelsWhatIsOpenStopsControlAndReconnects) {
  auto core = logged_in(Version::head);
  ASSERT_TRUE(core.set_request(milliseconds(1)));
  ASSERT_EQ(core.control(milliseconds(1), 0.1, 0.2), Refusal::none);
  core.take_actions();
  core.take_events();
  core.on_closed(milliseconds(50));
  const auto events = core.take_events();
  const auto req = events_of<RequestEvent>(events);
  ASSERT_EQ(req.size(), 1u);
  EXPECT_EQ(req[0].state, RequestState::cancelled);
  EXPECT_FALSE(core.held_control());
  EXPECT_EQ(core.state(), ConnectionState::reconnecting);
  EXPECT_EQ(core.next_wakeup(), milliseconds(1050));

  // disconnect() releases a held control first: CONTROL 0 0, then the close.
  auto other = logged_in(Version::head);
  ASSERT_EQ(other.control(milliseconds(1), 0.1, 0.2), Refusal::none);
  other.take_actions();
  other.disconnect(milliseconds(5));
  const auto actions = other.take_actions();
  ASSERT_EQ(actions.size(), 2u);
  EXPECT_EQ(sent(actions).at(0)[17], 0x02);
  EXPECT_EQ(sent(actions).at(0), svgui::encode_prefixed(svgui::Control{0, 0}, Version::head));
  EXPECT_EQ(actions[1], Action(CloseConnection{}));
  EXPECT_EQ(other.state(), ConnectionState::disconnected);
}

TEST(SvguiCore, TheLogHoldsEveryPacketWithItsLengthByte) {
  auto core = logged_in(Version::v2019);
  core.forward(milliseconds(1), 100);
  const auto entries = core.log()->entries();
  ASSERT_GE(entries.size(), 3u);
  const auto& auth = entries[entries.size() - 3];
  EXPECT_EQ(auth.kind, LogKind::tx);
  EXPECT_EQ(auth.raw, "0B 01 6B 6F 6E 6E 69 63 68 69 77 61");
  const auto& reply = entries[entries.size() - 2];
  EXPECT_EQ(reply.kind, LogKind::rx);
  EXPECT_EQ(reply.raw, "04 02 01 02 03");
  EXPECT_EQ(reply.description, "AuthReply device=1 id=2 state=WAIT");
  EXPECT_EQ(entries.back().raw, "08 03 01 01 01 64 00 00 00");
  EXPECT_EQ(entries.back().description, "Task coi=1 type=1 100");
}

}  // namespace
}  // namespace hil::client::wr8
