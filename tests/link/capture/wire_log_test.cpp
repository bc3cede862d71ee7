#include "link/capture/wire_log.hpp"

#include <cstdlib>
#include <fstream>

#include <gtest/gtest.h>

#include "protocol/common/car_profile.hpp"
#include "protocol/wr8/svgui.hpp"
#include "tests/link/capture/capture_support.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;
using test::ScratchFile;

constexpr std::int64_t kLogWallUs = 1'700'000'000'123'456;

struct LogFixture : ::testing::Test {
  ScratchFile file{".ndjson"};
  std::int64_t wall_us = kLogWallUs;

  std::shared_ptr<WireLog> make(
      std::shared_ptr<const ProtocolAdapter> protocol = protocol_adapter("logi"),
      std::string link_id = "car0") {
    WireLogOptions options;
    options.link_id = std::move(link_id);
    options.protocol = std::move(protocol);
    options.wall_clock_us = [this] { return wall_us; };
    std::error_code ec;
    auto log = WireLog::open(file.path(), std::move(options), ec);
    EXPECT_FALSE(ec) << ec.message();
    return log;
  }
  std::vector<nlohmann::json> records() const { return read_wire_log(file.path()); }
};

using WireLogTest = LogFixture;

/// Expects `record` to hold each (key, value) of `fields`.
void expect_fields(const nlohmann::json& record,
                   const std::vector<std::pair<std::string, nlohmann::json>>& fields) {
  for (const auto& [key, value] : fields) {
    SCOPED_TRACE(key);
    EXPECT_EQ(record[key], value);
  }
}

/// Expects `record` to hold exactly one decoded frame, of `kind` and valid
/// as `valid`; false (for an ASSERT_TRUE) when it holds another number.
bool has_one_frame(const nlohmann::json& record, const std::string& kind, bool valid) {
  const auto& frames = record["frames"];
  EXPECT_EQ(frames.size(), 1u) << record.dump();
  if (frames.size() != 1u) return false;
  EXPECT_EQ(frames[0]["kind"], kind);
  EXPECT_EQ(frames[0]["valid"], valid);
  return true;
}

TEST_F(WireLogTest, OpenRecordCarriesTimesSidesAndProtocol) {
  auto log = make();
  log->on_open(milliseconds(5), "tcp 127.0.0.1:9000 <- 127.0.0.1:53422", "mem car0");
  const auto r = records();
  ASSERT_EQ(r.size(), 1u);
  expect_fields(r[0], {{"event", "open"},
                       {"link", "car0"},
                       {"t_ms", 5.0},
                       {"wall_us", kLogWallUs},
                       {"client", "tcp 127.0.0.1:9000 <- 127.0.0.1:53422"},
                       {"car", "mem car0"},
                       {"protocol", "logi"},
                       {"profile", "guide"}});
  // A person reading the file sees which link, what and when first.
  EXPECT_EQ(file.contents().rfind(R"({"link":"car0","event":"open","t_ms":5.0,"wall_us":)", 0), 0u)
      << file.contents();
}

TEST_F(WireLogTest, LinkTimeIsMillisecondsRoundedToMicroseconds) {
  auto log = make(nullptr);
  log->on_sent(Time{12'345'678}, Direction::to_car, to_bytes("a"));
  log->on_sent(seconds(90), Direction::to_car, to_bytes("b"));
  log->on_sent(Time{999}, Direction::to_car, to_bytes("c"));
  const auto r = records();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0]["t_ms"].get<double>(), 12.346);
  EXPECT_EQ(r[1]["t_ms"].get<double>(), 90000.0);
  EXPECT_EQ(r[2]["t_ms"].get<double>(), 0.001);
  // The number is written as a person would read it, with no float noise.
  EXPECT_NE(file.contents().find("\"t_ms\":12.346,"), std::string::npos) << file.contents();
}

TEST_F(WireLogTest, PrintableBytesAreTextAndAnythingElseIsHex) {
  auto log = make(nullptr);
  log->on_sent(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
  log->on_sent(milliseconds(2), Direction::to_client, protocol::Bytes{0x2A, 0x2B, 0x00, 0xFF});
  log->on_sent(milliseconds(3), Direction::to_client, to_bytes("OK\r\n\t\"q\"\\"));
  const auto r = records();
  ASSERT_EQ(r.size(), 3u);

  EXPECT_EQ(r[0]["event"], "sent");
  EXPECT_EQ(r[0]["dir"], "to_car");
  EXPECT_EQ(r[0]["bytes"], 15);
  EXPECT_EQ(r[0]["text"], "LOGI:SP:050:D7#");
  EXPECT_FALSE(r[0].contains("hex"));

  EXPECT_EQ(r[1]["dir"], "to_client");
  EXPECT_EQ(r[1]["bytes"], 4);
  EXPECT_EQ(r[1]["hex"], "2A 2B 00 FF");
  EXPECT_FALSE(r[1].contains("text"));

  // CR, LF and tab stay text: JSON escapes them exactly.
  EXPECT_EQ(r[2]["text"], "OK\r\n\t\"q\"\\");
  EXPECT_EQ(bytes_of(r[2]), to_bytes("OK\r\n\t\"q\"\\"));
  EXPECT_EQ(bytes_of(r[1]), (protocol::Bytes{0x2A, 0x2B, 0x00, 0xFF}));
}

TEST_F(WireLogTest, WithoutAProtocolNoFramesAreWritten) {
  auto log = make(nullptr);
  log->on_delivered(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
  const auto r = records();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0]["event"], "delivered");
  EXPECT_FALSE(r[0].contains("frames"));
}

TEST_F(WireLogTest, LogiFrameSplitAcrossTwoDeliveriesIsDecodedWhenItCompletes) {
  auto log = make();
  log->on_sent(milliseconds(10), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
  log->on_delivered(milliseconds(11), Direction::to_car, to_bytes("LOGI:SP:0"));
  log->on_delivered(milliseconds(14), Direction::to_car, to_bytes("50:D7#LOGI:"));
  const auto r = records();
  ASSERT_EQ(r.size(), 3u);

  // What the client wrote was one whole frame.
  ASSERT_TRUE(has_one_frame(r[0], "SP", true));
  EXPECT_EQ(r[0]["held"], 0);

  // The car got it in two pieces: no frame yet, then the frame, with the
  // start of the next one held.
  EXPECT_EQ(r[1]["frames"].size(), 0u);
  EXPECT_EQ(r[1]["held"], 9);
  ASSERT_TRUE(has_one_frame(r[2], "SP", true));
  EXPECT_FALSE(r[2]["frames"][0]["text"].get<std::string>().empty());
  EXPECT_EQ(r[2]["held"], 5);
}

TEST_F(WireLogTest, DirectionsAndSentVersusDeliveredAreSplitSeparately) {
  auto log = make();
  // Half a frame each way, then the rest: had one splitter served both
  // directions, the halves would glue into garbage.
  log->on_delivered(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:"));
  log->on_delivered(milliseconds(1), Direction::to_client, to_bytes("LOGI:FB:"));
  log->on_sent(milliseconds(1), Direction::to_car, to_bytes("LOGI:"));
  log->on_delivered(milliseconds(2), Direction::to_car, to_bytes("050:D7#"));
  log->on_delivered(milliseconds(2), Direction::to_client, to_bytes("SP:1:35#"));
  const auto r = records();
  ASSERT_EQ(r.size(), 5u);
  ASSERT_TRUE(has_one_frame(r[3], "SP", true));
  ASSERT_EQ(r[4]["frames"].size(), 1u);
  EXPECT_EQ(r[4]["frames"][0]["valid"], true);
  EXPECT_EQ(r[4]["frames"][0]["kind"].get<std::string>().rfind("FB", 0), 0u) << r[4].dump();
}

TEST_F(WireLogTest, CorruptedFrameIsLoggedAsInvalid) {
  auto log = make();
  log->on_delivered(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:050:D8#"));
  const auto r = records();
  ASSERT_EQ(r[0]["frames"].size(), 1u);
  EXPECT_EQ(r[0]["frames"][0]["valid"], false);
  EXPECT_FALSE(r[0]["frames"][0]["text"].get<std::string>().empty());
}

TEST_F(WireLogTest, FaultRecordShowsRuleAndBytesBeforeAndAfter) {
  auto log = make();
  FaultEvent e;
  e.at = Time{2'500'000};
  e.direction = Direction::to_client;
  e.kind = FaultKind::corrupt;
  e.rule = "flip-checksum";
  e.before = to_bytes("LOGI:FB:SP:1:35#");
  e.after = protocol::Bytes{'L', 'O', 0x00};
  e.detail = "checksum field flipped";
  log->on_fault(e);
  const auto r = records();
  ASSERT_EQ(r.size(), 1u);
  expect_fields(r[0], {{"event", "fault"},
                       {"t_ms", 2.5},
                       {"wall_us", kLogWallUs},
                       {"dir", "to_client"},
                       {"kind", "corrupt"},
                       {"rule", "flip-checksum"},
                       {"detail", "checksum field flipped"}});
  expect_fields(r[0]["before"], {{"bytes", 16}, {"text", "LOGI:FB:SP:1:35#"}});
  expect_fields(r[0]["after"], {{"bytes", 3}, {"hex", "4C 4F 00"}});
}

TEST_F(WireLogTest, DropFaultHasEmptyAfter) {
  auto log = make();
  FaultEvent e;
  e.kind = FaultKind::drop;
  e.before = to_bytes("LOGI:SP:050:D7#");
  log->on_fault(e);
  const auto r = records();
  EXPECT_EQ(r[0]["after"]["bytes"], 0);
  EXPECT_EQ(r[0]["after"]["text"], "");
}

TEST_F(WireLogTest, CloseRecordListsAPartialFrameStillHeld) {
  auto log = make();
  log->on_delivered(milliseconds(1), Direction::to_client, to_bytes("LOGI:STAT:1:"));
  wall_us = kLogWallUs + 7;
  log->on_close(milliseconds(3), {LinkClose::By::car, CloseMode::graceful, "car closed"});
  const auto r = records();
  ASSERT_EQ(r.size(), 2u);
  expect_fields(r[1], {{"event", "close"},
                       {"reason", "car closed"},
                       {"by", "car"},
                       {"mode", "graceful"},
                       {"t_ms", 3.0},
                       {"wall_us", kLogWallUs + 7}});
  ASSERT_EQ(r[1]["unfinished"].size(), 1u);
  EXPECT_EQ(r[1]["unfinished"][0]["event"], "delivered");
  EXPECT_EQ(r[1]["unfinished"][0]["dir"], "to_client");
  ASSERT_EQ(r[1]["unfinished"][0]["frames"].size(), 1u);
  EXPECT_EQ(r[1]["unfinished"][0]["frames"][0]["valid"], false);
}

TEST_F(WireLogTest, AHalfCloseIsARecordOfItsDirectionWithItsPartialFrame) {
  auto log = make();
  log->on_sent(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:05"));
  log->on_delivered(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:05"));
  log->on_delivered(milliseconds(2), Direction::to_client, to_bytes("LOGI:STAT:1:"));
  log->on_half_close(milliseconds(3), Direction::to_car);
  log->on_close(milliseconds(4),
                {LinkClose::By::client, CloseMode::graceful, "client and car closed"});
  const auto r = records();
  ASSERT_EQ(r.size(), 5u);
  expect_fields(r[3], {{"link", "car0"},
                       {"event", "half_close"},
                       {"t_ms", 3.0},
                       {"wall_us", kLogWallUs},
                       {"dir", "to_car"},
                       {"by", "client"}});
  // The client's half frame is final once it half-closed, in both stages;
  // the car's is still open until the close.
  ASSERT_EQ(r[3]["unfinished"].size(), 2u);
  EXPECT_EQ(r[3]["unfinished"][0]["event"], "sent");
  EXPECT_EQ(r[3]["unfinished"][1]["event"], "delivered");
  for (const auto& u : r[3]["unfinished"]) {
    EXPECT_EQ(u["dir"], "to_car");
    ASSERT_EQ(u["frames"].size(), 1u);
    EXPECT_EQ(u["frames"][0]["valid"], false);
  }
  ASSERT_EQ(r[4]["unfinished"].size(), 1u) << "listed once, at the half-close";
  EXPECT_EQ(r[4]["unfinished"][0]["dir"], "to_client");
  EXPECT_EQ(r[4]["reason"], "client and car closed");
}

TEST_F(WireLogTest, ACleanHalfCloseOfTheCarHasNoUnfinishedField) {
  auto log = make();
  log->on_delivered(milliseconds(1), Direction::to_client, to_bytes("LOGI:FB:SP:1:35#"));
  log->on_half_close(milliseconds(2), Direction::to_client);
  const auto r = records();
  ASSERT_EQ(r.size(), 2u);
  expect_fields(r[1], {{"event", "half_close"}, {"dir", "to_client"}, {"by", "car"}});
  EXPECT_FALSE(r[1].contains("unfinished"));
}

TEST_F(WireLogTest, CleanCloseHasNoUnfinishedField) {
  auto log = make();
  log->on_delivered(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
  log->on_close(milliseconds(3), {LinkClose::By::hil, CloseMode::graceful, "closed by hil"});
  EXPECT_FALSE(records().back().contains("unfinished"));
}

TEST_F(WireLogTest, EveryRecordIsOnDiskWhenTheCallReturns) {
  auto log = make();
  log->on_open(Time{0}, "client", "car");
  for (int i = 1; i <= 20; ++i) {
    log->on_sent(milliseconds(i), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
    // Read back through a separate descriptor, the writer still open.
    const auto text = file.contents();
    ASSERT_FALSE(text.empty());
    EXPECT_EQ(text.back(), '\n');
    const auto r = records();
    ASSERT_EQ(r.size(), static_cast<std::size_t>(i + 1));
    EXPECT_EQ(r.back()["t_ms"], static_cast<double>(i));
  }
  EXPECT_EQ(log->records_written(), 21u);
  EXPECT_FALSE(log->error());
}

TEST_F(WireLogTest, ACrashLosesNothingAlreadyLogged) {
  auto log = make();
  // A forked child logs and aborts: no destructor, no flush, no close.
  EXPECT_DEATH(
      {
        log->on_open(Time{0}, "client", "car");
        log->on_sent(milliseconds(1), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
        log->on_delivered(milliseconds(2), Direction::to_car, to_bytes("LOGI:SP:0"));
        std::abort();
      },
      "");
  const auto r = records();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[2]["text"], "LOGI:SP:0");
}

TEST_F(WireLogTest, SeveralLinksShareOneFileLineByLine) {
  auto a = make(protocol_adapter("logi"), "a");
  auto b = make(nullptr, "b");
  for (int i = 0; i < 50; ++i) {
    a->on_sent(milliseconds(i), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
    b->on_sent(milliseconds(i), Direction::to_client, protocol::Bytes(300, 0xAB));
  }
  const auto r = records();
  ASSERT_EQ(r.size(), 100u);
  for (std::size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(r[i]["link"], i % 2 == 0 ? "a" : "b");
  }
  EXPECT_EQ(bytes_of(r[1]), protocol::Bytes(300, 0xAB));
}

TEST_F(WireLogTest, AppendsToAnExistingLog) {
  make()->on_open(Time{0}, "c", "k");
  make()->on_open(Time{0}, "c", "k");
  EXPECT_EQ(records().size(), 2u);
}

// A capture of the real WR8 programs (smart_vehicle_gui, profile
// svgui-head) names its profile, its frames are the length byte and the
// packet, and a reader of the file gets the adapter that framed them.
TEST_F(WireLogTest, SvguiCaptureNamesItsProfileAndIsFramedByItsLengthBytes) {
  namespace svgui = protocol::wr8::svgui;
  const auto head = svgui::Version::head;
  const protocol::Bytes auth =
      svgui::encode_prefixed(svgui::Auth{to_bytes(std::string("konnichiwa\0", 11))}, head);
  const protocol::Bytes reply = svgui::encode_prefixed(svgui::kProgramAuthReply, head);
  const protocol::Bytes high =
      svgui::encode_prefixed(svgui::HighFreqData{36000000, 1.5, -10, 0.25, 0.5, 90}, head);
  auto log = make(protocol_adapter("wr8", "svgui-head"));
  log->on_open(milliseconds(0), "client", "car");
  log->on_sent(milliseconds(1), Direction::to_car, auth);
  // The vehicle's reply and a DATA packet in one write, the DATA cut short.
  protocol::Bytes write = reply;
  write.insert(write.end(), high.begin(), high.begin() + 30);
  log->on_sent(milliseconds(2), Direction::to_client, write);
  log->on_sent(milliseconds(3), Direction::to_client, protocol::ByteView(high).subspan(30));
  log.reset();

  const auto r = records();
  ASSERT_EQ(r.size(), 4u);
  EXPECT_EQ(r[0]["protocol"], "wr8");
  EXPECT_EQ(r[0]["profile"], "svgui-head");
  ASSERT_EQ(r[1]["frames"].size(), 1u);
  EXPECT_EQ(r[1]["frames"][0]["kind"], "AUTH");
  EXPECT_EQ(r[1]["frames"][0]["valid"], true);
  EXPECT_EQ(r[1]["frames"][0]["text"], "Auth text=**********");
  EXPECT_EQ(r[1]["hex"], "0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00");
  ASSERT_EQ(r[2]["frames"].size(), 1u);
  EXPECT_EQ(r[2]["frames"][0]["kind"], "AUTH_REPLY");
  EXPECT_EQ(r[2]["held"], 30);
  ASSERT_EQ(r[3]["frames"].size(), 1u);
  EXPECT_EQ(r[3]["frames"][0]["kind"], "HIGH_FREQ_DATA");
  EXPECT_EQ(r[3]["frames"][0]["text"],
            svgui::describe(svgui::HighFreqData{36000000, 1.5, -10, 0.25, 0.5, 90}));

  // Read back, the log gives the adapter it was written with, which finds
  // the same frames in its bytes.
  const auto adapter = adapter_of_log(r[0]);
  EXPECT_EQ(adapter->name(), "wr8");
  EXPECT_EQ(adapter->profile(), "svgui-head");
  auto splitter = adapter->splitter_for(Direction::to_client);
  std::vector<WireFrame> frames;
  for (std::size_t i = 2; i < r.size(); ++i)
    splitter->feed(bytes_of(r[i]), frames);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].raw, reply);
  EXPECT_EQ(frames[1].raw, high);
  EXPECT_TRUE(frames[1].valid) << frames[1].text;
}

TEST(AdapterOfLog, NamesTheProfileOrTheDefaultAndRefusesOtherRecords) {
  using nlohmann::json;
  EXPECT_EQ(adapter_of_log(json{{"event", "open"}, {"protocol", "wr8"}, {"profile", "svgui-2019"}})
                ->profile(),
            "svgui-2019");
  // A log with no profile was written with the protocol's default.
  EXPECT_EQ(adapter_of_log(json{{"event", "open"}, {"protocol", "wr8"}})->profile(), "document");
  EXPECT_EQ(adapter_of_log(json{{"event", "open"}, {"protocol", "raw"}})->name(), "raw");
  EXPECT_THROW(adapter_of_log(json{{"event", "sent"}, {"protocol", "wr8"}}), std::invalid_argument);
  EXPECT_THROW(adapter_of_log(json{{"event", "open"}}), std::invalid_argument);
  EXPECT_THROW(
      adapter_of_log(json{{"event", "open"}, {"protocol", "wr8"}, {"profile", "svgui-2020"}}),
      protocol::ProfileError);
}

TEST(WireLogOpen, UnwritablePathGivesAnErrorNotAnException) {
  std::error_code ec;
  auto log = WireLog::open("/nonexistent-dir/for/hil/wire.ndjson", {}, ec);
  EXPECT_EQ(log, nullptr);
  EXPECT_EQ(ec, std::errc::no_such_file_or_directory);
}

TEST(ReadWireLog, FinalPartialLineIsSkipped) {
  ScratchFile file(".ndjson");
  {
    std::ofstream out(file.path());
    out << R"({"event":"open","link":"a"})" << '\n'
        << R"({"event":"sent","link":"a","text":"LOGI"})" << '\n'
        << R"({"event":"sent","li)";
  }
  const auto r = read_wire_log(file.path());
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[1]["text"], "LOGI");
}

TEST(ReadWireLog, FinalLineWithoutNewlineThatParsesIsKept) {
  ScratchFile file(".ndjson");
  {
    std::ofstream out(file.path());
    out << R"({"event":"open"})" << '\n' << R"({"event":"close"})";
  }
  EXPECT_EQ(read_wire_log(file.path()).size(), 2u);
}

TEST(ReadWireLog, BrokenLineInTheMiddleNamesFileAndLine) {
  ScratchFile file(".ndjson");
  {
    std::ofstream out(file.path());
    out << R"({"event":"open"})" << '\n'
        << "not json\n"
        << R"({"event":"close"})" << '\n';
  }
  try {
    read_wire_log(file.path());
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.path().string() + ":2:"), std::string::npos)
        << e.what();
  }
}

TEST(ReadWireLog, MissingFileThrows) {
  EXPECT_THROW(read_wire_log("/nonexistent-dir/wire.ndjson"), std::runtime_error);
}

}  // namespace
}  // namespace hil::link
