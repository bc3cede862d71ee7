// `hil mock logi --view 0` scraped as Prometheus scrapes it: GET /metrics
// over real HTTP while a plain TCP client sends the car good frames and a
// bad one, and the text read back by the Prometheus Python client.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "protocol/logi/codec.hpp"
#include "tests/view/view_test_support.hpp"

namespace hil::view::test {
namespace {

namespace logi = protocol::logi;

// A TCP client with nothing of hil in it: sends bytes, keeps what it reads.
class RawClient {
 public:
  explicit RawClient(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
    timeval timeout{0, 100'000};
    if (fd_ >= 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  }
  ~RawClient() { close(); }
  bool connected() const { return fd_ >= 0; }
  void send(const std::string& bytes) {
    ASSERT_EQ(::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(bytes.size()));
  }
  // Reads what has come (up to 100 ms of waiting).
  const std::string& read() {
    char buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
    if (n > 0) received_.append(buffer, static_cast<std::size_t>(n));
    return received_;
  }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
  std::string received_;
};

std::string text_of(const protocol::Bytes& bytes) {
  return std::string(bytes.begin(), bytes.end());
}

std::size_t count_of(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1))
    ++n;
  return n;
}

// The samples of a /metrics body: `name{labels}` -> value.
std::map<std::string, double> samples_of(const std::string& body) {
  std::map<std::string, double> samples;
  std::istringstream lines(body);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.rfind(' ');
    if (space != std::string::npos)
      samples[line.substr(0, space)] = std::stod(line.substr(space + 1));
  }
  return samples;
}

struct Scrape {
  int status = 0;
  std::string content_type;
  std::string body;
  std::map<std::string, double> samples;
  double at(const std::string& key) const {
    const auto it = samples.find(key);
    return it == samples.end() ? -1 : it->second;
  }
};

Scrape scrape(const ViewedMock& mock) {
  auto c = mock.client();
  Scrape s;
  if (const auto res = c.Get("/metrics")) {
    s.status = res->status;
    s.content_type = res->get_header_value("Content-Type");
    s.body = res->body;
    s.samples = samples_of(s.body);
  }
  return s;
}

constexpr const char* kBytesToCar = R"(hil_mock_bytes_total{car="car0",direction="to_car"})";
constexpr const char* kBytesToClient = R"(hil_mock_bytes_total{car="car0",direction="to_client"})";
constexpr const char* kFramesToCar = R"(hil_mock_frames_total{car="car0",direction="to_car"})";
constexpr const char* kFramesToClient =
    R"(hil_mock_frames_total{car="car0",direction="to_client"})";
constexpr const char* kBadFrames = R"(hil_mock_bad_frames_total{car="car0"})";
constexpr const char* kConnections = R"(hil_mock_connections_total{car="car0"})";
constexpr const char* kOpen = R"(hil_mock_open_connections{car="car0"})";

TEST(LiveViewMetrics, CountWhatARealClientSentExactly) {
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  Scrape s = scrape(mock);
  ASSERT_EQ(s.status, 200) << s.body;
  EXPECT_EQ(s.content_type, "text/plain; version=0.0.4; charset=utf-8");
  EXPECT_EQ(s.at(kConnections), 0) << s.body;
  EXPECT_EQ(s.at(kOpen), 0) << s.body;

  RawClient client(std::stoi(mock.car_port()));
  ASSERT_TRUE(client.connected());
  const std::string speed = text_of(logi::encode(logi::SetSpeed{50}));
  const std::string mode = text_of(logi::encode(logi::SetMode{logi::Mode::manual}));
  const std::string bad_checksum = "LOGI:SP:050:D8#";
  client.send(speed);
  client.send(bad_checksum);
  client.send(mode);
  // Both good frames answered: the car has read everything sent.
  ASSERT_TRUE(wait_until([&] {
    const std::string& got = client.read();
    return count_of(got, "FB:SP") == 1 && count_of(got, "FB:MD") == 1;
  })) << client.read();

  s = scrape(mock);
  ASSERT_EQ(s.status, 200) << s.body;
  EXPECT_EQ(s.at(kBytesToCar),
            static_cast<double>(speed.size() + bad_checksum.size() + mode.size()))
      << s.body;
  EXPECT_EQ(s.at(kFramesToCar), 2) << s.body;
  EXPECT_EQ(s.at(kBadFrames), 1) << s.body;
  EXPECT_EQ(s.at(kConnections), 1) << s.body;
  EXPECT_EQ(s.at(kOpen), 1) << s.body;
  // The car streams STAT as well: at least what the client has read came.
  EXPECT_GE(s.at(kBytesToClient), static_cast<double>(client.read().size())) << s.body;
  EXPECT_GE(s.at(kFramesToClient), 2) << s.body;
  EXPECT_EQ(s.at(R"(hil_mock_faults_total{car="car0",kind="drop"})"), 0) << s.body;

  client.close();
  ASSERT_TRUE(wait_until([&] { return scrape(mock).at(kOpen) == 0; })) << scrape(mock).body;
  s = scrape(mock);
  EXPECT_EQ(s.at(kConnections), 1) << s.body;
  EXPECT_EQ(s.at(kFramesToCar), 2) << s.body;
  EXPECT_EQ(s.at(kBadFrames), 1) << s.body;
}

TEST(LiveViewMetrics, CountFaultsByKindAcrossConnections) {
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  // Every SP the client sends is dropped before the car.
  const auto [status, body] = mock.post(
      "faults", {{"profile", "rules:\n  - kind: drop\n    direction: to_car\n    match: SP\n"}});
  ASSERT_EQ(status, 200) << body;
  const std::string speed = text_of(logi::encode(logi::SetSpeed{50}));
  const std::string mode = text_of(logi::encode(logi::SetMode{logi::Mode::manual}));
  for (int i = 0; i < 2; ++i) {
    RawClient client(std::stoi(mock.car_port()));
    ASSERT_TRUE(client.connected());
    client.send(speed);
    client.send(mode);
    ASSERT_TRUE(wait_until([&] { return count_of(client.read(), "FB:MD") == 1; })) << client.read();
    EXPECT_EQ(count_of(client.read(), "FB:SP"), 0U) << client.read();
    client.close();
    ASSERT_TRUE(wait_until([&] { return scrape(mock).at(kOpen) == 0; }));
  }
  const Scrape s = scrape(mock);
  EXPECT_EQ(s.at(R"(hil_mock_faults_total{car="car0",kind="drop"})"), 2) << s.body;
  EXPECT_EQ(s.at(R"(hil_mock_faults_total{car="car0",kind="corrupt"})"), 0) << s.body;
  EXPECT_EQ(s.at(kConnections), 2) << s.body;
  EXPECT_EQ(s.at(kFramesToCar), 2) << s.body;
  EXPECT_EQ(s.at(kBytesToCar), static_cast<double>(2 * mode.size())) << s.body;
  // The page's own count agrees.
  EXPECT_EQ(mock.state()["faults_injected"].get<int>(), 2);
}

// The Prometheus Python client (Debian python3-prometheus-client) reads the
// text as a scraper would; a line it cannot parse fails the test.
TEST(LiveViewMetrics, PrometheusOwnParserReadsTheText) {
  constexpr const char* kPython = "/usr/bin/python3";
  if (std::system("/usr/bin/python3 -c 'import prometheus_client' 2>/dev/null") != 0)
    GTEST_SKIP() << "no prometheus_client for /usr/bin/python3 (python3-prometheus-client)";
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  RawClient client(std::stoi(mock.car_port()));
  ASSERT_TRUE(client.connected());
  client.send(text_of(logi::encode(logi::SetSpeed{50})));
  ASSERT_TRUE(wait_until([&] { return count_of(client.read(), "FB:SP") == 1; }));
  const Scrape s = scrape(mock);
  ASSERT_EQ(s.status, 200);

  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-view-metrics-" + std::to_string(::getpid()) + ".txt");
  std::ofstream(path) << s.body;
  const std::string script =
      "import sys\n"
      "from prometheus_client.parser import text_string_to_metric_families\n"
      "for f in text_string_to_metric_families(open(sys.argv[1]).read()):\n"
      "    print(f.name, f.type, len(f.samples), sum(x.value for x in f.samples))\n";
  hil::test::HilProcess python(kPython, {"-c", script, path.string()});
  python.wait_exit(std::chrono::seconds(30));
  std::filesystem::remove(path);
  const std::string out = python.output();
  // Counters lose "_total" in the client's family names; sums over labels.
  EXPECT_NE(out.find("hil_mock_bytes counter 2 "), std::string::npos) << out;
  EXPECT_NE(out.find("hil_mock_frames counter 2 "), std::string::npos) << out;
  EXPECT_NE(out.find("hil_mock_bad_frames counter 1 0.0"), std::string::npos) << out;
  // Every fault kind hil knows, each at zero.
  const std::size_t kinds = count_of(s.body, "\nhil_mock_faults_total{");
  EXPECT_GE(kinds, 12U) << s.body;
  EXPECT_NE(out.find("hil_mock_faults counter " + std::to_string(kinds) + " 0.0"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("hil_mock_connections counter 1 1.0"), std::string::npos) << out;
  EXPECT_NE(out.find("hil_mock_open_connections gauge 1 1.0"), std::string::npos) << out;
  EXPECT_EQ(count_of(out, "\n"), 6U) << out;
}

}  // namespace
}  // namespace hil::view::test
