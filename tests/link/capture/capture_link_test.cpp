// The capture observers on a real Link in virtual time: mem pipes, the LOGI
// adapter and a fragment fault, so every record and packet time is exact.

#include <gtest/gtest.h>

#include "link/capture/pcap.hpp"
#include "link/capture/wire_log.hpp"
#include "link/mem_pipe.hpp"
#include "protocol/wr8/svgui.hpp"
#include "tests/link/capture/capture_support.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;

using test::kWallUs;

/// A pcap writer at `path` whose packets carry kWallUs.
std::shared_ptr<PcapWriter> open_pcap(const std::string& path, std::error_code& ec) {
  PcapOptions options;
  options.wall_clock_us = [] { return kWallUs; };
  return PcapWriter::open(path, options, ec);
}

/// A rule that cuts every write into `size`-byte pieces 1 ms apart.
FaultRule split_into(std::size_t size) {
  FaultRule fragment;
  fragment.name = "split";
  fragment.action = Fragment{{size, size}, {milliseconds(1), milliseconds(1)}};
  return fragment;
}

struct Collected {
  std::string data;
  bool ended = false;  // on_end: the peer half-closed
  /// With `half_close`, the peer's half-close is on_end.
  BytePipe::Handlers handlers(bool half_close = false) {
    BytePipe::Handlers h{[this](ByteView b) { data.append(b.begin(), b.end()); },
                         [](std::error_code) {}};
    if (half_close) h.on_end = [this] { ended = true; };
    return h;
  }
};

struct CaptureLinkTest : ::testing::Test {
  test::ScratchFile log_file{".ndjson"};
  test::ScratchFile pcap_file{".pcap"};
  VirtualExecutor ex;
  Collected at_client;
  Collected at_car;

  // The client writes one frame at 10 ms, the car answers at 20 ms, the
  // client hangs up at 30 ms. to_car bytes are cut into 5-byte pieces 1 ms
  // apart. With `half_close` the client half-closes right after its frame
  // and the car half-closes after its answer instead.
  void run_exchange(bool half_close = false) {
    std::error_code ec;
    WireLogOptions log_options;
    log_options.link_id = "logi0";
    log_options.protocol = protocol_adapter("logi");
    log_options.wall_clock_us = [] { return kWallUs; };
    auto log = WireLog::open(log_file.path(), log_options, ec);
    ASSERT_TRUE(log) << ec.message();
    auto pcap = open_pcap(pcap_file.path(), ec);
    ASSERT_TRUE(pcap) << ec.message();

    LinkOptions options;
    options.protocol = protocol_adapter("logi");
    options.to_car.rules.push_back(split_into(5));
    options.observers = {log, pcap};

    auto [client_app, link_client] = make_mem_pipe(ex, "client");
    auto [link_car, car_app] = make_mem_pipe(ex, "car");
    auto link = Link::create(ex, link_client, link_car, std::move(options));
    client_app->start(at_client.handlers(half_close));
    car_app->start(at_car.handlers(half_close));
    link->start();

    ex.run_until(milliseconds(10));
    client_app->write(to_bytes("LOGI:SP:050:D7#"));
    if (half_close) client_app->shutdown_send();
    ex.run_until(milliseconds(20));
    car_app->write(to_bytes("LOGI:FB:SP:1:35#"));
    if (half_close) car_app->shutdown_send();
    ex.run_until(milliseconds(30));
    if (!half_close) client_app->close();
    ex.run_until_idle();
    EXPECT_FALSE(log->error());
    EXPECT_FALSE(pcap->error());
  }

  /// One line per wire log record: event, time, direction, text, frames.
  std::vector<std::string> log_summary() const {
    std::vector<std::string> summary;
    for (const auto& r : read_wire_log(log_file.path())) {
      EXPECT_EQ(r["link"], "logi0");
      EXPECT_EQ(r["wall_us"], kWallUs);
      std::string line = r["event"].get<std::string>() + " " + r["t_ms"].dump();
      if (r.contains("dir")) line += " " + r["dir"].get<std::string>();
      if (r["event"] == "fault") line += " " + r["kind"].get<std::string>();
      if (r.contains("text")) line += " " + r["text"].get<std::string>();
      if (r.contains("frames")) line += " frames=" + std::to_string(r["frames"].size());
      if (r.contains("reason")) line += " (" + r["reason"].get<std::string>() + ")";
      summary.push_back(line);
    }
    return summary;
  }
};

TEST_F(CaptureLinkTest, WireLogShowsSentFaultAndDeliveredPiecesAtVirtualTimes) {
  run_exchange();
  ASSERT_EQ(at_car.data, "LOGI:SP:050:D7#");
  const auto summary = log_summary();
  const std::vector<std::string> expected = {
      "open 0.0",
      "sent 10.0 to_car LOGI:SP:050:D7# frames=1",
      "fault 10.0 to_car fragment",
      "delivered 10.0 to_car LOGI: frames=0",
      "delivered 11.0 to_car SP:05 frames=0",
      "delivered 12.0 to_car 0:D7# frames=1",
      "sent 20.0 to_client LOGI:FB:SP:1:35# frames=1",
      "delivered 20.0 to_client LOGI:FB:SP:1:35# frames=1",
      "close 30.0 (client closed)",
  };
  EXPECT_EQ(summary, expected);
}

TEST_F(CaptureLinkTest, PcapHoldsTheDeliveredPiecesAtWallTimePlusVirtualTime) {
  if (!test::tshark_installed()) {
    GTEST_SKIP() << "tshark is not installed (ci/install-deps.sh installs it)";
  }
  run_exchange();
  const auto out = test::tshark_output(
      pcap_file.path(), "-Y 'tcp.len > 0' -T fields -e frame.time_epoch -e tcp.srcport -e tcp.len");
  ASSERT_TRUE(out);
  EXPECT_EQ(*out,
            "1700000000.010000000\t40000\t5\n"
            "1700000000.011000000\t40000\t5\n"
            "1700000000.012000000\t40000\t5\n"
            "1700000000.020000000\t9000\t16\n");
}

TEST_F(CaptureLinkTest, AHalfCloseIsLoggedWhenItIsPassedOnAndTheLinkClosesWithTheCar) {
  run_exchange(true);
  ASSERT_EQ(at_car.data, "LOGI:SP:050:D7#");
  ASSERT_EQ(at_client.data, "LOGI:FB:SP:1:35#");
  EXPECT_TRUE(at_car.ended && at_client.ended);
  const std::vector<std::string> expected = {
      "open 0.0",
      "sent 10.0 to_car LOGI:SP:050:D7# frames=1",
      "fault 10.0 to_car fragment",
      "delivered 10.0 to_car LOGI: frames=0",
      "delivered 11.0 to_car SP:05 frames=0",
      "delivered 12.0 to_car 0:D7# frames=1",
      "half_close 12.0 to_car",  // after the last piece the fault held
      "sent 20.0 to_client LOGI:FB:SP:1:35# frames=1",
      "delivered 20.0 to_client LOGI:FB:SP:1:35# frames=1",
      "close 20.0 (client and car closed)",
  };
  EXPECT_EQ(log_summary(), expected);
}

TEST_F(CaptureLinkTest, APcapShowsTheClientsFinBeforeTheCarsAnswer) {
  if (!test::tshark_installed()) {
    GTEST_SKIP() << "tshark is not installed (ci/install-deps.sh installs it)";
  }
  run_exchange(true);
  const auto out = test::tshark_output(
      pcap_file.path(), "-T fields -e frame.time_epoch -e tcp.srcport -e tcp.flags -e tcp.len");
  ASSERT_TRUE(out);
  EXPECT_EQ(*out,
            "1700000000.000000000\t40000\t0x0002\t0\n"
            "1700000000.000000000\t9000\t0x0012\t0\n"
            "1700000000.000000000\t40000\t0x0010\t0\n"
            "1700000000.010000000\t40000\t0x0018\t5\n"
            "1700000000.011000000\t40000\t0x0018\t5\n"
            "1700000000.012000000\t40000\t0x0018\t5\n"
            "1700000000.012000000\t40000\t0x0011\t0\n"  // the client's FIN
            "1700000000.012000000\t9000\t0x0010\t0\n"
            "1700000000.020000000\t9000\t0x0018\t16\n"  // the answer after it
            "1700000000.020000000\t9000\t0x0011\t0\n"   // the car's FIN
            "1700000000.020000000\t40000\t0x0010\t0\n");
}

TEST(CaptureLinkSvgui, APcapOfTheRealWr8ProgramsDecodesByTheLengthByteWhateverTheSegments) {
  if (!test::tshark_installed()) {
    GTEST_SKIP() << "tshark is not installed (ci/install-deps.sh installs it)";
  }
  namespace svgui = protocol::wr8::svgui;
  test::ScratchFile pcap_file{".pcap"};
  VirtualExecutor ex;
  std::error_code ec;
  auto pcap = open_pcap(pcap_file.path(), ec);
  ASSERT_TRUE(pcap) << ec.message();
  // The head vehicle's AUTH-REPLY and a HIGH-FREQ DATA, cut into 3-byte
  // segments on their way to the client.
  LinkOptions options;
  options.protocol = protocol_adapter("wr8", "svgui-head");
  options.to_client.rules.push_back(split_into(3));
  options.observers = {pcap};
  auto [client_app, link_client] = make_mem_pipe(ex, "client");
  auto [link_car, car_app] = make_mem_pipe(ex, "car");
  auto link = Link::create(ex, link_client, link_car, std::move(options));
  Collected at_client;
  Collected at_car;
  client_app->start(at_client.handlers());
  car_app->start(at_car.handlers());
  link->start();
  protocol::Bytes sent = svgui::encode_prefixed(svgui::kProgramAuthReply, svgui::Version::head);
  const protocol::Bytes data = svgui::encode_prefixed(
      svgui::HighFreqData{36000050, 1.5, -0.25, 2, 0.5, 90}, svgui::Version::head);
  sent.insert(sent.end(), data.begin(), data.end());
  ex.run_until(milliseconds(10));
  car_app->write(sent);
  ex.run_until(milliseconds(200));
  client_app->close();
  ex.run_until_idle();
  ASSERT_FALSE(pcap->error());

  // tshark gives the payload of each segment; joined, the length byte cuts
  // them back into the two packets.
  const auto out =
      test::tshark_output(pcap_file.path(), "-Y 'tcp.len > 0' -T fields -e tcp.payload");
  ASSERT_TRUE(out);
  std::string hex;
  int segments = 0;
  for (const char c : *out) {
    if (c == '\n') {
      ++segments;
    } else if (c != ':') {
      hex += c;
    }
  }
  EXPECT_EQ(segments, 24);  // 5 + 66 bytes in 3-byte pieces
  const auto payload = protocol::parse_hex(hex);
  ASSERT_TRUE(payload) << hex;
  EXPECT_EQ(*payload, sent);
  std::vector<WireFrame> frames;
  auto splitter = protocol_adapter("wr8", "svgui-head")->splitter();
  splitter->feed(*payload, frames);
  splitter->finish(frames);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].kind, "AUTH_REPLY");
  EXPECT_EQ(frames[1].kind, "HIGH_FREQ_DATA");
  EXPECT_TRUE(frames[0].valid && frames[1].valid);
}

}  // namespace
}  // namespace hil::link
