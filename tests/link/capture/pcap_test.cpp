#include "link/capture/pcap.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "protocol/logi/codec.hpp"
#include "tests/link/capture/capture_support.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;
using test::ScratchFile;

using test::kWallUs;

using test::tshark_installed;

#define REQUIRE_TSHARK()                                                                     \
  if (!tshark_installed()) {                                                                 \
    GTEST_SKIP() << "tshark is not installed (ci/install-deps.sh installs it); the pcap is " \
                    "not checked against a real reader";                                     \
  }

/// Runs tshark on the file and returns one row per packet, fields split on
/// tabs. Fails the test (no rows) when tshark exits non-zero.
std::vector<std::vector<std::string>> tshark(const std::filesystem::path& file,
                                             const std::string& args) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(test::tshark_output(file, args).value_or(""));
  std::string line;
  while (std::getline(lines, line)) {
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (std::size_t tab; (tab = line.find('\t', start)) != std::string::npos; start = tab + 1) {
      fields.push_back(line.substr(start, tab - start));
    }
    fields.push_back(line.substr(start));
    rows.push_back(std::move(fields));
  }
  return rows;
}

protocol::Bytes payload_of(std::string tshark_hex) {
  std::erase(tshark_hex, ':');  // some tshark versions separate bytes with colons
  return protocol::parse_hex(tshark_hex).value_or(to_bytes("<bad hex: " + tshark_hex + ">"));
}

struct PcapTest : ::testing::Test {
  ScratchFile file{".pcap"};

  std::shared_ptr<PcapWriter> make(PcapOptions options = {}) {
    options.wall_clock_us = [] { return kWallUs; };
    std::error_code ec;
    auto writer = PcapWriter::open(file.path(), std::move(options), ec);
    EXPECT_FALSE(ec) << ec.message();
    return writer;
  }

  // A short LOGI exchange: the client sets the speed, the car answers with
  // feedback and a status frame cut in two by a fragment fault.
  void write_logi_exchange(PcapWriter& w,
                           const LinkClose& close = {LinkClose::By::car, CloseMode::graceful,
                                                     "car closed"}) {
    w.on_open(seconds(1), "client", "car");
    w.on_sent(seconds(1) + milliseconds(10), Direction::to_car,
              to_bytes("ignored: pcap shows deliveries"));
    w.on_delivered(seconds(1) + milliseconds(10), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
    w.on_delivered(seconds(1) + milliseconds(20), Direction::to_client,
                   to_bytes("LOGI:FB:SP:1:35#"));
    w.on_delivered(seconds(1) + milliseconds(30), Direction::to_client, to_bytes("LOGI:STAT:SP:0"));
    w.on_delivered(seconds(1) + milliseconds(31), Direction::to_client, to_bytes("50,RUN:1:00#"));
    w.on_close(seconds(1) + milliseconds(500), close);
  }
};

TEST_F(PcapTest, FileHeaderIsNanosecondPcapOfRawIpv4) {
  auto w = make();
  write_logi_exchange(*w);
  const auto bytes = file.contents();
  ASSERT_GE(bytes.size(), 24u + 16u);
  std::uint32_t magic = 0;
  std::uint32_t linktype = 0;
  std::uint32_t ts_sec = 0;
  std::uint32_t ts_nsec = 0;
  std::memcpy(&magic, bytes.data(), 4);
  std::memcpy(&linktype, bytes.data() + 20, 4);
  std::memcpy(&ts_sec, bytes.data() + 24, 4);
  std::memcpy(&ts_nsec, bytes.data() + 28, 4);
  EXPECT_EQ(magic, 0xa1b23c4du);
  EXPECT_EQ(linktype, 101u);
  // The SYN is stamped with the wall time at open.
  EXPECT_EQ(ts_sec, 1'700'000'000u);
  EXPECT_EQ(ts_nsec, 0u);
  EXPECT_EQ(bytes[24 + 16], 0x45);  // the packet starts with an IPv4 header
  EXPECT_FALSE(w->error());
}

TEST_F(PcapTest, TsharkReadsThePayloadsInOrderWithPorts) {
  REQUIRE_TSHARK();
  auto w = make();
  write_logi_exchange(*w);
  const auto rows = tshark(
      file.path(), "-Y 'tcp.len > 0' -T fields -e tcp.srcport -e tcp.dstport -e tcp.payload");
  ASSERT_EQ(rows.size(), 4u);
  const std::vector<std::tuple<std::string, std::string, std::string>> expected = {
      {"40000", "9000", "LOGI:SP:050:D7#"},
      {"9000", "40000", "LOGI:FB:SP:1:35#"},
      {"9000", "40000", "LOGI:STAT:SP:0"},
      {"9000", "40000", "50,RUN:1:00#"},
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 3u);
    EXPECT_EQ(rows[i][0], std::get<0>(expected[i])) << "packet " << i;
    EXPECT_EQ(rows[i][1], std::get<1>(expected[i])) << "packet " << i;
    EXPECT_EQ(protocol::to_string(payload_of(rows[i][2])), std::get<2>(expected[i]))
        << "packet " << i;
  }
}

TEST_F(PcapTest, IpAndTcpChecksumsAreRight) {
  REQUIRE_TSHARK();
  auto w = make();
  write_logi_exchange(*w);
  w->on_open(seconds(2), "client", "car");
  w->on_delivered(seconds(2), Direction::to_car, protocol::Bytes(3001, 0xA5));  // odd length
  const std::string args =
      "-o ip.check_checksum:TRUE -o tcp.check_checksum:TRUE -T fields -e ip.checksum.status "
      "-e tcp.checksum.status";
  const auto rows = tshark(file.path(), args);
  ASSERT_EQ(rows.size(), w->packets_written());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i], (std::vector<std::string>{"1", "1"})) << "packet " << i << " (1 = good)";
  }

  // The same check sees a single flipped payload bit: the test can fail.
  w.reset();
  auto bytes = file.contents();
  bytes[bytes.size() - 1] = static_cast<char>(bytes.back() ^ 0x01);
  std::ofstream(file.path(), std::ios::binary | std::ios::trunc) << bytes;
  const auto broken = tshark(file.path(), args);
  ASSERT_FALSE(broken.empty());
  EXPECT_EQ(broken.back(), (std::vector<std::string>{"1", "0"}));
}

TEST_F(PcapTest, HandshakeDataAndGracefulCloseByTheCar) {
  REQUIRE_TSHARK();
  auto w = make();
  write_logi_exchange(*w, {LinkClose::By::car, CloseMode::graceful, "car closed"});
  const auto rows =
      tshark(file.path(), "-T fields -e tcp.srcport -e tcp.flags -e tcp.seq -e tcp.ack -e tcp.len");
  const std::vector<std::vector<std::string>> expected = {
      {"40000", "0x0002", "0", "0", "0"},    // SYN
      {"9000", "0x0012", "0", "1", "0"},     // SYN, ACK
      {"40000", "0x0010", "1", "1", "0"},    // ACK
      {"40000", "0x0018", "1", "1", "15"},   // LOGI:SP:050:D7#
      {"9000", "0x0018", "1", "16", "16"},   // LOGI:FB:SP:1:35#
      {"9000", "0x0018", "17", "16", "14"},  // LOGI:STAT:SP:0
      {"9000", "0x0018", "31", "16", "12"},  // 50,RUN:1:00#
      {"9000", "0x0011", "43", "16", "0"},   // the car's FIN
      {"40000", "0x0011", "16", "44", "0"},  // the client's FIN
      {"9000", "0x0010", "44", "17", "0"},   // last ACK
  };
  EXPECT_EQ(rows, expected);
}

TEST_F(PcapTest, AHalfCloseIsTheSendersFinWithTheOtherSidesDataAfterIt) {
  REQUIRE_TSHARK();
  auto w = make();
  w->on_open(Time{0}, "client", "car");
  w->on_delivered(milliseconds(10), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
  w->on_half_close(milliseconds(11), Direction::to_car);  // shutdown(SHUT_WR)
  w->on_delivered(milliseconds(20), Direction::to_client, to_bytes("LOGI:FB:SP:1:35#"));
  w->on_close(milliseconds(30),
              {LinkClose::By::client, CloseMode::graceful, "client and car closed"});
  const auto rows =
      tshark(file.path(),
             "-T fields -e frame.time_relative -e tcp.srcport -e tcp.flags -e tcp.seq -e tcp.ack "
             "-e tcp.len");
  const std::vector<std::vector<std::string>> expected = {
      {"0.000000000", "40000", "0x0002", "0", "0", "0"},    // SYN
      {"0.000000000", "9000", "0x0012", "0", "1", "0"},     // SYN, ACK
      {"0.000000000", "40000", "0x0010", "1", "1", "0"},    // ACK
      {"0.010000000", "40000", "0x0018", "1", "1", "15"},   // LOGI:SP:050:D7#
      {"0.011000000", "40000", "0x0011", "16", "1", "0"},   // the client's FIN
      {"0.011000000", "9000", "0x0010", "1", "17", "0"},    // the car acks it
      {"0.020000000", "9000", "0x0018", "1", "17", "16"},   // the answer after it
      {"0.030000000", "9000", "0x0011", "17", "17", "0"},   // the car's FIN
      {"0.030000000", "40000", "0x0010", "17", "18", "0"},  // last ACK
  };
  EXPECT_EQ(rows, expected);
  // Wireshark's TCP analysis finds nothing wrong with the stream.
  EXPECT_TRUE(tshark(file.path(), "-Y 'tcp.analysis.flags' -T fields -e frame.number").empty());
}

TEST_F(PcapTest, AResetAfterAHalfCloseIsOneRst) {
  REQUIRE_TSHARK();
  auto w = make();
  w->on_open(Time{0}, "client", "car");
  w->on_half_close(milliseconds(1), Direction::to_client);
  w->on_close(milliseconds(2),
              {LinkClose::By::car, CloseMode::reset, "car connection failed: reset"});
  const auto rows = tshark(file.path(), "-T fields -e tcp.srcport -e tcp.flags");
  const std::vector<std::vector<std::string>> expected = {
      {"40000", "0x0002"}, {"9000", "0x0012"},  {"40000", "0x0010"},
      {"9000", "0x0011"},  {"40000", "0x0010"}, {"9000", "0x0014"},
  };
  EXPECT_EQ(rows, expected);
}

TEST_F(PcapTest, ResetReasonEndsWithOneRst) {
  REQUIRE_TSHARK();
  auto w = make();
  write_logi_exchange(*w,
                      {LinkClose::By::fault, CloseMode::reset, "fault injected: reset (to_car)"});
  const auto rows = tshark(file.path(), "-T fields -e tcp.srcport -e tcp.flags");
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_EQ(rows.back(), (std::vector<std::string>{"40000", "0x0014"}));
}

TEST_F(PcapTest, ResetFaultEndsWithRstWhateverTheReason) {
  REQUIRE_TSHARK();
  auto w = make();
  w->on_open(Time{0}, "client", "car");
  FaultEvent e;
  e.kind = FaultKind::reset;
  w->on_fault(e);
  w->on_close(milliseconds(1), {LinkClose::By::hil, CloseMode::graceful, "closed by hil"});
  const auto rows = tshark(file.path(), "-T fields -e tcp.flags");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows.back(), std::vector<std::string>{"0x0014"});
}

TEST_F(PcapTest, LargeDeliveriesAreSplitIntoFullSizedSegments) {
  REQUIRE_TSHARK();
  auto w = make();
  protocol::Bytes big(4000);
  for (std::size_t i = 0; i < big.size(); ++i)
    big[i] = static_cast<std::uint8_t>(i * 7);
  w->on_open(Time{0}, "client", "car");
  w->on_delivered(milliseconds(1), Direction::to_car, big);
  w->on_delivered(milliseconds(2), Direction::to_client, to_bytes("ok"));
  w->on_close(milliseconds(3), {LinkClose::By::client, CloseMode::graceful, "client closed"});
  const auto rows = tshark(
      file.path(), "-Y 'tcp.len > 0' -T fields -e tcp.len -e tcp.seq -e tcp.ack -e tcp.payload");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0][0], "1460");
  EXPECT_EQ(rows[0][1], "1");
  EXPECT_EQ(rows[1][0], "1460");
  EXPECT_EQ(rows[1][1], "1461");
  EXPECT_EQ(rows[2][0], "1080");
  EXPECT_EQ(rows[2][1], "2921");
  EXPECT_EQ(rows[3][2], "4001");  // the car's answer acks all 4000 bytes
  protocol::Bytes joined;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto piece = payload_of(rows[i][3]);
    joined.insert(joined.end(), piece.begin(), piece.end());
  }
  EXPECT_EQ(joined, big);

  // Wireshark's TCP analysis finds nothing wrong with the stream.
  EXPECT_TRUE(tshark(file.path(), "-Y 'tcp.analysis.flags' -T fields -e frame.number").empty());
}

TEST_F(PcapTest, TimestampsAreWallTimeAtOpenPlusLinkTime) {
  REQUIRE_TSHARK();
  auto w = make();
  write_logi_exchange(*w);
  const auto rows = tshark(file.path(), "-Y 'tcp.len > 0' -T fields -e frame.time_epoch");
  ASSERT_EQ(rows.size(), 4u);
  // Opened at link time 1 s, wall time 1700000000 s.
  EXPECT_EQ(rows[0][0], "1700000000.010000000");
  EXPECT_EQ(rows[1][0], "1700000000.020000000");
  EXPECT_EQ(rows[2][0], "1700000000.030000000");
  EXPECT_EQ(rows[3][0], "1700000000.031000000");
}

TEST_F(PcapTest, RealAddressesAndPortsWhenGiven) {
  REQUIRE_TSHARK();
  PcapOptions options;
  options.client_address = "127.0.0.1";
  options.client_port = 53422;
  options.car_address = "127.0.0.2";
  options.car_port = 9100;
  auto w = make(options);
  write_logi_exchange(*w);
  const auto rows = tshark(
      file.path(), "-Y 'tcp.len > 0' -T fields -e ip.src -e tcp.srcport -e ip.dst -e tcp.dstport");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"127.0.0.1", "53422", "127.0.0.2", "9100"}));
  EXPECT_EQ(rows[1], (std::vector<std::string>{"127.0.0.2", "9100", "127.0.0.1", "53422"}));
}

TEST_F(PcapTest, EachReopenIsANewStreamFromTheNextPort) {
  REQUIRE_TSHARK();
  auto w = make();
  write_logi_exchange(*w);
  write_logi_exchange(*w, {LinkClose::By::client, CloseMode::graceful, "client closed"});
  const auto rows = tshark(file.path(), "-Y 'tcp.len > 0' -T fields -e tcp.stream -e tcp.srcport");
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"0", "40000"}));
  EXPECT_EQ(rows[4], (std::vector<std::string>{"1", "40001"}));
}

TEST_F(PcapTest, ObserverAddedToARunningLinkStillStartsWithAHandshake) {
  REQUIRE_TSHARK();
  auto w = make();
  w->on_delivered(milliseconds(5), Direction::to_client, to_bytes("LOGI:FB:SP:1:35#"));
  const auto rows = tshark(file.path(), "-T fields -e tcp.flags -e tcp.len");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0][0], "0x0002");
  EXPECT_EQ(rows[3], (std::vector<std::string>{"0x0018", "16"}));
}

TEST_F(PcapTest, EveryPacketIsOnDiskWhenTheCallReturns) {
  REQUIRE_TSHARK();
  auto w = make();
  w->on_open(Time{0}, "client", "car");
  for (int i = 1; i <= 5; ++i) {
    w->on_delivered(milliseconds(i), Direction::to_car, to_bytes("LOGI:SP:050:D7#"));
    // Read while the writer is still open.
    EXPECT_EQ(tshark(file.path(), "-T fields -e frame.number").size(),
              static_cast<std::size_t>(3 + i));
  }
}

TEST(PcapOpen, BadAddressOrPathGivesAnError) {
  ScratchFile file(".pcap");
  std::error_code ec;
  PcapOptions options;
  options.car_address = "10.0.0.300";
  EXPECT_EQ(PcapWriter::open(file.path(), options, ec), nullptr);
  EXPECT_EQ(ec, std::errc::invalid_argument);
  EXPECT_EQ(PcapWriter::open("/nonexistent-dir/x.pcap", {}, ec), nullptr);
  EXPECT_EQ(ec, std::errc::no_such_file_or_directory);
}

}  // namespace
}  // namespace hil::link
