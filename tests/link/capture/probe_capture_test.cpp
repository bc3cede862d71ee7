#include "link/capture/probe_capture.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "protocol/common/bytes.hpp"
#include "tests/link/capture/capture_support.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;
using std::chrono::milliseconds;
using test::ScratchFile;

CaptureHeader header() {
  return {"logi-probe/1", "logi", "guide", "tcp://127.0.0.1:9000", 1'700'000'000'000'000};
}

// A capture of two exchanges, recorded in memory and to `path`.
Capture record(const std::filesystem::path& path) {
  CaptureRecorder recorder(header(), open_capture_log(path, protocol_adapter("logi", "guide")));
  recorder.begin_exchange(Time{0}, "connect", ExchangeKind::connect, "open the connection");
  recorder.opened(milliseconds(1), "probe", "tcp 127.0.0.1:1 -> 127.0.0.1:9000");
  recorder.end_exchange(milliseconds(300));
  recorder.begin_exchange(milliseconds(300), "sp-020", ExchangeKind::command, "SP:020");
  recorder.sent(milliseconds(300), to_bytes("LOGI:SP:020:D4#"));
  // A nanosecond time is kept to the microsecond, as the file keeps it.
  recorder.received(milliseconds(312) + std::chrono::nanoseconds(400),
                    to_bytes("LOGI:FB:SP:1:35#"));
  recorder.received(milliseconds(313), to_bytes("\x01\x02 binary"));
  recorder.closed(milliseconds(400), {LinkClose::By::car, CloseMode::reset, "car closed"});
  recorder.end_exchange(milliseconds(600));
  recorder.closed(milliseconds(601), {LinkClose::By::client, CloseMode::graceful, "probe"});
  return recorder.take();
}

TEST(ProbeCapture, ReadsBackWhatWasRecorded) {
  ScratchFile file(".ndjson");
  const auto recorded = record(file.path());
  const auto read = read_capture(file.path());
  EXPECT_EQ(read, recorded);
  ASSERT_EQ(read.exchanges.size(), 2u);
  EXPECT_EQ(read.header, header());
  const auto& sp = read.exchanges[1];
  EXPECT_EQ(sp.name, "sp-020");
  EXPECT_EQ(sp.kind, ExchangeKind::command);
  EXPECT_EQ(sp.start, milliseconds(300));
  EXPECT_EQ(sp.end, milliseconds(600));
  ASSERT_EQ(sp.events.size(), 4u);
  EXPECT_EQ(sp.events[1].kind, CaptureEvent::Kind::received);
  EXPECT_EQ(sp.events[1].at, milliseconds(312));
  EXPECT_EQ(sp.events[1].bytes, to_bytes("LOGI:FB:SP:1:35#"));
  EXPECT_EQ(sp.events[2].bytes, to_bytes("\x01\x02 binary"));
  EXPECT_EQ(sp.events[3].kind, CaptureEvent::Kind::closed);
  EXPECT_EQ(sp.events[3].by, LinkClose::By::car);
}

TEST(ProbeCapture, IsAWireLogWithDecodedFrames) {
  ScratchFile file(".ndjson");
  record(file.path());
  const auto records = read_wire_log(file.path());
  ASSERT_GE(records.size(), 4u);
  EXPECT_EQ(records[0]["event"], "probe");
  EXPECT_EQ(records[0]["probe"], "logi-probe/1");
  EXPECT_EQ(records[1]["event"], "exchange");
  EXPECT_EQ(records[1]["kind"], "connect");
  bool saw_feedback = false;
  for (const auto& r : records) {
    if (r["event"] == "delivered" && r.contains("frames") && !r["frames"].empty())
      saw_feedback = saw_feedback || r["frames"][0]["kind"] == "FB:SP";
  }
  EXPECT_TRUE(saw_feedback);
}

void write_lines(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string error_of(const std::filesystem::path& path) {
  try {
    read_capture(path);
  } catch (const CaptureError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ProbeCapture, RefusesAWireLogThatNoProbeWrote) {
  ScratchFile file(".ndjson");
  write_lines(file.path(),
              R"({"link":"car0","event":"open","t_ms":0,"wall_us":1,"client":"a","car":"b",)"
              R"("protocol":"logi"})"
              "\n");
  EXPECT_EQ(error_of(file.path()),
            file.path().string() +
                ":1: not a probe capture: its first record is \"open\", not \"probe\" (hil "
                "conform probe writes captures)");
}

TEST(ProbeCapture, NamesTheLineOfABadRecord) {
  ScratchFile file(".ndjson");
  write_lines(file.path(),
              R"({"link":"probe","event":"probe","t_ms":0,"wall_us":1,"probe":"logi-probe/1",)"
              R"("car":"logi","profile":"guide","target":"x"})"
              "\n"
              R"({"link":"probe","event":"exchange","t_ms":0,"wall_us":1,"index":0,"name":"a",)"
              R"("kind":"chat","what":"w"})"
              "\n");
  EXPECT_EQ(error_of(file.path()),
            file.path().string() + ":2: an exchange of unknown kind \"chat\"");
}

TEST(ProbeCapture, SaysWhenTheFileIsEmptyOrMissing) {
  ScratchFile file(".ndjson");
  write_lines(file.path(), "");
  EXPECT_EQ(error_of(file.path()), file.path().string() + ": empty: no probe record");
  EXPECT_NE(error_of(file.path().string() + ".missing").find(".missing"), std::string::npos);
}

TEST(ProbeCapture, KeepsWhatAProbeCutShortRecorded) {
  ScratchFile file(".ndjson");
  record(file.path());
  // A probe killed mid-record leaves a last line without its end.
  std::ofstream(file.path(), std::ios::app) << R"({"link":"probe","event":"exch)";
  const auto read = read_capture(file.path());
  EXPECT_EQ(read.exchanges.size(), 2u);
}

}  // namespace
}  // namespace hil::link
