// hil proxy's control API abused over real HTTP while a client talks to a
// LOGI mock car through the proxy: bodies over the limit (declared and
// sent), JSON that is not JSON or nests thousands deep, unknown toxics and
// attributes, fault profiles that do not parse, broken HTTP, requests
// that stop half-way, and a storm of requests past the rate limit. After
// each: the process is alive, the client's link is still the same open
// link and gets its answers, the route has no toxic and no fault rule that
// a refused request could have left, and the API still answers.

#include <gtest/gtest.h>

#include <memory>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/abuse/abuse_support.hpp"

namespace hil::test {
namespace {

using nlohmann::json;

std::string logi_frame(const std::string& payload) {
  const std::string head = "LOGI:" + payload;
  unsigned sum = 0;
  for (const char c : head)
    sum += static_cast<unsigned char>(c);
  char cs[3];
  std::snprintf(cs, sizeof cs, "%02X", sum & 0xFFu);
  return head + ":" + cs + "#";
}

/// One HTTP exchange on a new connection, whatever the bytes sent: the
/// whole reply (the request asks the server to close after it).
std::string raw_exchange(int port, const std::string& bytes,
                         std::chrono::milliseconds limit = std::chrono::seconds(15)) {
  Conn c = tcp_connect(port);
  if (!c.ok()) return {};
  c.send(bytes);
  c.read_to_end(limit);
  return c.received;
}

int status_of(const std::string& reply) {
  std::smatch m;
  if (!std::regex_search(reply, m, std::regex(R"(^HTTP/1\.[01] (\d{3}))"))) return 0;
  return std::stoi(m[1]);
}

std::string body_of(const std::string& reply) {
  const auto end = reply.find("\r\n\r\n");
  return end == std::string::npos ? std::string() : reply.substr(end + 4);
}

std::string request(const std::string& method, const std::string& path, const std::string& body,
                    const std::string& content_type = "application/json") {
  std::string text = method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n";
  if (!body.empty() || method != "GET") {
    text += "Content-Type: " + content_type + "\r\nContent-Length: " + std::to_string(body.size()) +
            "\r\n";
  }
  return text + "\r\n" + body;
}

class ProxyApiAbuse : public ::testing::Test {
 protected:
  void SetUp() override {
    mock_ = std::make_unique<Process>(
        HIL_BINARY,
        std::vector<std::string>{"mock", "logi", "--port", "0", "--seed", "1", "--no-status"});
    const auto car = mock_->wait_for_line("connect to tcp://");
    ASSERT_TRUE(car) << mock_->output();
    proxy_ = std::make_unique<Process>(
        HIL_BINARY, std::vector<std::string>{"proxy", "--protocol", "logi", "--name", "car",
                                             "--listen", "tcp://127.0.0.1:0", "--upstream",
                                             "tcp://127.0.0.1:" + std::to_string(port_in(*car)),
                                             "--api", "0", "--seed", "1", "-q"});
    const auto route = proxy_->wait_for_line("clients connect to");
    ASSERT_TRUE(route) << proxy_->output();
    route_port_ = port_in(*route);
    const auto api = proxy_->wait_for_line("control API at");
    ASSERT_TRUE(api) << proxy_->output();
    std::smatch m;
    ASSERT_TRUE(std::regex_search(*api, m, std::regex(R"(http://127\.0\.0\.1:(\d+))"))) << *api;
    api_port_ = std::stoi(m[1]);
    client_ = tcp_connect(route_port_);
    ASSERT_TRUE(client_.ok());
    ASSERT_TRUE(answers(0));
  }

  /// The client's command `n` gets the car's answer on the same link.
  ::testing::AssertionResult answers(int n) {
    client_.received.clear();
    const std::string speed = std::to_string(100 + n % 100);
    if (!client_.send(logi_frame("SP:" + speed.substr(speed.size() - 3))))
      return ::testing::AssertionFailure() << "the link closed under the client";
    if (!client_.read_until("LOGI:FB:SP:"))
      return ::testing::AssertionFailure() << "no answer on the link; got " << client_.received;
    return ::testing::AssertionSuccess();
  }

  json get(const std::string& path) {
    const std::string reply = raw_exchange(api_port_, request("GET", path, ""));
    EXPECT_EQ(status_of(reply), 200) << path << ": " << reply;
    try {
      return json::parse(body_of(reply));
    } catch (const std::exception&) {
      ADD_FAILURE() << path << ": not JSON: " << reply;
      return json();
    }
  }

  /// What every test ends with: alive, same link, nothing left behind.
  void expect_untouched(int n) {
    ASSERT_TRUE(proxy_->alive()) << proxy_->output();
    EXPECT_TRUE(answers(n));
    const json links = get("/hil/links");
    ASSERT_EQ(links.size(), 1u) << links.dump();
    EXPECT_EQ(links[0].at("link"), 1);
    EXPECT_EQ(links[0].at("open"), true);
    const json route = get("/proxies/car");
    EXPECT_EQ(route.at("toxics"), json::array());
    EXPECT_EQ(route.at("enabled"), true);
    EXPECT_EQ(get("/hil/proxies/car/faults").at("rules"), 0);
  }

  std::unique_ptr<Process> mock_;
  std::unique_ptr<Process> proxy_;
  int route_port_ = 0;
  int api_port_ = 0;
  Conn client_;
};

TEST_F(ProxyApiAbuse, BodiesOverTheLimit) {
  // Declared over the limit, and sent whole.
  const std::string big(600 * 1024, '{');
  const std::string reply = raw_exchange(api_port_, request("POST", "/proxies/car/toxics", big));
  EXPECT_EQ(status_of(reply), 413) << reply.substr(0, 300);
  EXPECT_NE(body_of(reply).find("over the limit of 262144"), std::string::npos) << reply;
  // Declared huge, then only a little sent and the connection dropped.
  {
    Conn c = tcp_connect(api_port_);
    ASSERT_TRUE(c.ok());
    c.send("PUT /hil/proxies/car/faults HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000000\r\n\r\n" +
           std::string(1000, 'a'));
  }
  expect_untouched(1);
}

TEST_F(ProxyApiAbuse, BadAndDeepJsonAndUnknownToxics) {
  const std::vector<std::pair<std::string, std::string>> bodies = {
      {"/proxies/car/toxics", "{\"type\": "},
      {"/proxies/car/toxics", std::string(200'000, '[')},
      {"/proxies/car/toxics", std::string(100'000, '[') + std::string(100'000, ']')},
      {"/proxies/car/toxics", R"({"type": "nonsense"})"},
      {"/proxies/car/toxics", R"({"type": "latency", "attributes": {"latency": -1}})"},
      {"/proxies/car/toxics", R"({"type": "latency", "attributes": {"latnecy": 10}})"},
      {"/proxies/car/toxics", R"({"type": "latency", "stream": "sideways"})"},
      {"/proxies/car/toxics", R"({"type": "timeout", "toxicity": 7})"},
      {"/proxies/car/toxics", R"({"type": "corrupt", "attributes": {"target": "everything"}})"},
      {"/proxies/car/toxics", "[1,2,3]"},
      {"/proxies/car/toxics", "\xff\xfe\x00garbage"},
      {"/proxies", R"({"name": "car", "listen": "127.0.0.1:0", "upstream": "127.0.0.1:9"})"},
      {"/proxies", R"({"name": "bad name!", "listen": "127.0.0.1:0", "upstream": "x"})"},
      {"/proxies/car", R"({"enabled": "false"})"},
      {"/proxies/car", R"({"listen": 12})"},
      {"/populate", R"([{"name": "car", "listen": "127.0.0.1:0"}])"},
      {"/hil/proxies/car/links/1/stall", R"({"duration_ms": "forever"})"},
      {"/hil/proxies/car/links/1/stall", R"({"duration_ms": 1e300})"},
      {"/hil/proxies/car/links/99/reset", ""},
  };
  int n = 1;
  for (const auto& [path, body] : bodies) {
    const std::string reply = raw_exchange(api_port_, request("POST", path, body));
    const int status = status_of(reply);
    EXPECT_GE(status, 400) << path << " " << body.substr(0, 80) << ": " << reply.substr(0, 300);
    EXPECT_LT(status, 500) << path << " " << body.substr(0, 80) << ": " << reply.substr(0, 300);
    EXPECT_TRUE(json::accept(body_of(reply))) << reply.substr(0, 300);
    ASSERT_TRUE(answers(n++)) << path;
  }
  expect_untouched(n);
}

TEST_F(ProxyApiAbuse, FaultProfilesThatDoNotParse) {
  const std::vector<std::pair<std::string, std::string>> bodies = {
      {"application/yaml", "rules:\n  - kind: drop\n    frist: 1\n"},
      {"application/yaml", "rules: [" + std::string(50'000, '{')},
      {"application/yaml", "&a [*a]"},
      {"text/yaml", "- kind: stall\n"},
      {"application/json", "{\"rules\": [{\"kind\": \"delay\"}]"},
      {"application/json", R"({"rules": [{"kind": "delay", "delay": 100}]})"},
      {"", std::string("\0\0\0\x01\x02", 5)},
  };
  int n = 1;
  for (const auto& [type, body] : bodies) {
    const std::string reply =
        raw_exchange(api_port_, request("PUT", "/hil/proxies/car/faults", body, type));
    EXPECT_EQ(status_of(reply), 400) << type << " " << body.substr(0, 60) << ": " << reply;
    ASSERT_TRUE(answers(n++));
  }
  expect_untouched(n);
}

TEST_F(ProxyApiAbuse, BrokenHttpAndRequestsLeftHalfWay) {
  // Every broken request goes out at once, so the server's read timeouts
  // run side by side.
  std::vector<Conn> broken;
  for (const std::string& bytes :
       {std::string("\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03", 11),  // a TLS hello
        std::string("GET /version\r\n\r\n"), std::string("FROB /proxies HTTP/1.1\r\n\r\n"),
        std::string("GET /") + std::string(100'000, 'a') + " HTTP/1.1\r\n\r\n",
        std::string("POST /proxies HTTP/1.1\r\nContent-Length: -5\r\n\r\n"),
        std::string("POST /proxies HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n"),
        std::string("GET /proxies HTTP/1.1\r\n") + std::string(20'000, 'X') + ": y\r\n\r\n"}) {
    broken.push_back(tcp_connect(api_port_));
    ASSERT_TRUE(broken.back().ok());
    broken.back().send(bytes);
  }
  for (Conn& c : broken) {
    // The server keeps a connection open a while after an error reply:
    // its status line and headers are enough.
    c.read_until("\r\n\r\n", std::chrono::seconds(3));
    const std::string& reply = c.received;
    if (!reply.empty()) EXPECT_GE(status_of(reply), 400) << reply.substr(0, 200);
  }
  // Connections that send half a request and wait.
  std::vector<Conn> idle;
  for (int i = 0; i < 20; ++i) {
    idle.push_back(tcp_connect(api_port_));
    idle.back().send("POST /proxies HTTP/1.1\r\nContent-Length: 100\r\n\r\n{\"na");
  }
  expect_untouched(1);
}

TEST_F(ProxyApiAbuse, AStormOfRequestsIsLimitedAndTheLinkCarriesOn) {
  // 300 requests as fast as they go: past the burst of 100, the rate limit
  // answers 429 with Retry-After instead of the handlers.
  int limited = 0;
  int answered = 0;
  const auto began = Clock::now();
  for (int i = 0; i < 300; ++i) {
    const std::string reply = raw_exchange(api_port_, request("GET", "/proxies", ""));
    const int status = status_of(reply);
    if (status == 429) {
      ++limited;
      EXPECT_NE(reply.find("Retry-After: 1\r\n"), std::string::npos) << reply;
      EXPECT_TRUE(json::accept(body_of(reply))) << reply;
    } else {
      EXPECT_EQ(status, 200) << reply.substr(0, 300);
      ++answered;
    }
    if (i % 50 == 0) ASSERT_TRUE(answers(i));
  }
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - began).count();
  EXPECT_EQ(limited + answered, 300);
  EXPECT_LE(answered, 100 + static_cast<int>(200 * elapsed_s) + 2);
  if (elapsed_s < 0.9) EXPECT_GT(limited, 0) << elapsed_s << " s";
  // The limit fills again at 200 a second.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  expect_untouched(1);
}

}  // namespace
}  // namespace hil::test
