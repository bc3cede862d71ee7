// The control API over real HTTP on 127.0.0.1, as a Toxiproxy client uses
// it: JSON errors for what the server refuses itself (a path it does not
// know, a body over the limit, too many requests), and a toxic added,
// felt by a client on a real TCP link, and removed. Real time: the
// bounds are generous.
#include "control/api_server.hpp"

#include <httplib.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>

#include <nlohmann/json.hpp>

#include <chrono>
#include <future>
#include <string>
#include <thread>

#include "link/asio_executor.hpp"
#include "link/transport.hpp"
#include "tests/support/connection.hpp"

namespace hil::control {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;
using Clock = std::chrono::steady_clock;

// ------------------------------------------------------ pieces alone

TEST(RequestRateLimit, ABurstThenTheRate) {
  RequestRateLimit limit(200, 100);
  const std::chrono::nanoseconds start{std::chrono::seconds(7)};
  for (int i = 0; i < 100; ++i)
    ASSERT_TRUE(limit.allow(start)) << i;
  EXPECT_FALSE(limit.allow(start));
  // 200 a second: one more every 5 ms.
  EXPECT_FALSE(limit.allow(start + std::chrono::milliseconds(4)));
  EXPECT_TRUE(limit.allow(start + std::chrono::milliseconds(5)));
  EXPECT_FALSE(limit.allow(start + std::chrono::milliseconds(5)));
  // A quiet second fills the bucket again, but no fuller than the burst.
  const auto later = start + std::chrono::seconds(10);
  for (int i = 0; i < 100; ++i)
    ASSERT_TRUE(limit.allow(later)) << i;
  EXPECT_FALSE(limit.allow(later));
}

TEST(RequestRateLimit, TimeGoingBackwardsGivesNothing) {
  RequestRateLimit limit(1, 1);
  EXPECT_TRUE(limit.allow(std::chrono::seconds(10)));
  EXPECT_FALSE(limit.allow(std::chrono::seconds(5)));
  EXPECT_FALSE(limit.allow(std::chrono::seconds(10)));
  EXPECT_TRUE(limit.allow(std::chrono::seconds(11)));
}

TEST(IsLoopbackHost, LoopbackAndNot) {
  for (const char* host : {"127.0.0.1", "127.1.2.3", "localhost", "::1", "[::1]"})
    EXPECT_TRUE(is_loopback_host(host)) << host;
  for (const char* host : {"0.0.0.0", "192.168.1.10", "::", "", "127.0.0", "127.0.0.1.5",
                           "127.0.0.256", "127.evil.com", "localhost.example.org"})
    EXPECT_FALSE(is_loopback_host(host)) << host;
}

// ------------------------------------------------------ over HTTP

/// The proxies' io_context on a thread of its own, a hub on it, the API
/// server in front, and an echoing TCP car.
class ApiServerTest : public ::testing::Test {
 protected:
  void SetUp() override { start({}); }

  void start(ApiServerOptions options) {
    options.host = "127.0.0.1";
    options.port = 0;
    options.info.version = "9.9.9";
    car_listener = link::listen(context, link::parse_endpoint("tcp://127.0.0.1:0"));
    car_listener->start([this](link::BytePipePtr pipe) {
      car_pipes.push_back(pipe);
      std::weak_ptr<link::BytePipe> weak = pipe;
      pipe->start({[weak](link::ByteView bytes) {
                     if (auto self = weak.lock()) self->write(bytes);
                   },
                   [](std::error_code) {}});
    });
    server = std::make_unique<ApiServer>(io, hub, options);
    server->start();
    io_thread = std::thread([this] { io.run(); });
    client = std::make_unique<httplib::Client>("127.0.0.1", server->port());
    client->set_read_timeout(10, 0);
    client->set_write_timeout(10, 0);
  }

  void TearDown() override {
    client.reset();
    if (server) server->stop();
    // The hub and the car are closed on their own thread.
    std::promise<void> closed;
    asio::post(io, [&] {
      hub.close();
      car_pipes.clear();
      car_listener.reset();
      closed.set_value();
    });
    closed.get_future().wait_for(std::chrono::seconds(10));
    work.reset();
    io.stop();
    if (io_thread.joinable()) io_thread.join();
  }

  std::string car_address() const { return car_listener->address(); }

  asio::io_context io;
  asio::executor_work_guard<asio::io_context::executor_type> work = asio::make_work_guard(io);
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  ProxyHub hub{context, ProxyHubOptions{}};
  std::unique_ptr<link::Listener> car_listener;
  std::vector<link::BytePipePtr> car_pipes;
  std::unique_ptr<ApiServer> server;
  std::thread io_thread;
  std::unique_ptr<httplib::Client> client;
};

json error_body(const httplib::Result& result, int status) {
  EXPECT_TRUE(result) << httplib::to_string(result.error());
  if (!result) return json::object();
  EXPECT_EQ(result->status, status) << result->body;
  EXPECT_THAT(result->get_header_value("Content-Type"), StartsWith("application/json"));
  json body = json::parse(result->body);
  EXPECT_EQ(body.at("status"), status);
  return body;
}

TEST_F(ApiServerTest, VersionAndAnUnknownPathAsJson) {
  const auto version = client->Get("/version");
  ASSERT_TRUE(version);
  EXPECT_EQ(version->status, 200);
  EXPECT_EQ(version->body, "hil 9.9.9 (Toxiproxy API 2.x)");
  EXPECT_THAT(server->url(), StartsWith("http://127.0.0.1:"));
  const json missing = error_body(client->Get("/nothing/here"), 404);
  EXPECT_THAT(missing.at("error").get<std::string>(), HasSubstr("/nothing/here"));
}

TEST_F(ApiServerTest, ABrowsersRequestIsRefusedAndChangesNothing) {
  const json refused =
      error_body(client->Post("/proxies", {{"User-Agent", "Mozilla/5.0 (X11; Linux x86_64)"}},
                              R"({"name": "car", "upstream": "127.0.0.1:9"})", "application/json"),
                 403);
  EXPECT_THAT(refused.at("error").get<std::string>(), StartsWith("User-Agent: browsers"));
  const auto proxies = client->Get("/proxies");
  ASSERT_TRUE(proxies);
  EXPECT_EQ(proxies->status, 200);
  EXPECT_EQ(proxies->body, "{}");
}

TEST_F(ApiServerTest, ABodyOverTheLimitIs413AsJson) {
  const std::string big(300'000, 'x');
  const auto result = client->Post("/proxies", big, "application/json");
  const json body = error_body(result, 413);
  EXPECT_EQ(body.at("error"), "body: 300000 bytes is over the limit of 262144");
  // The server still answers.
  const auto after = client->Get("/proxies");
  ASSERT_TRUE(after);
  EXPECT_EQ(after->status, 200);
}

TEST_F(ApiServerTest, TooManyRequestsAre429WithRetryAfter) {
  // 300 requests: the burst of 100 and 200 a second answer all of them
  // only if they take more than a second; a 429 is expected only then.
  int ok = 0;
  int refused = 0;
  std::string retry_after;
  const auto began = Clock::now();
  for (int i = 0; i < 300; ++i) {
    const auto result = client->Get("/version");
    ASSERT_TRUE(result) << i;
    if (result->status == 200) {
      ++ok;
    } else {
      ASSERT_EQ(result->status, 429) << result->body;
      ++refused;
      retry_after = result->get_header_value("Retry-After");
      const json body = json::parse(result->body);
      EXPECT_EQ(body.at("status"), 429);
      EXPECT_THAT(body.at("error").get<std::string>(), StartsWith("requests: "));
    }
  }
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - began).count();
  EXPECT_GE(ok, 100);
  EXPECT_LE(ok, 100 + static_cast<int>(200 * elapsed_s) + 2);
  if (elapsed_s < 0.9) {
    EXPECT_GT(refused, 0);
    EXPECT_EQ(retry_after, "1");
  }
}

TEST_F(ApiServerTest, AToxicRoundTripOnARealLink) {
  const json spec = {{"name", "car"}, {"listen", "127.0.0.1:0"}, {"upstream", car_address()}};
  const auto created = client->Post("/proxies", spec.dump(), "application/json");
  ASSERT_TRUE(created);
  ASSERT_EQ(created->status, 201) << created->body;
  const std::string listen = json::parse(created->body).at("listen");
  ASSERT_THAT(listen, StartsWith("127.0.0.1:"));
  const int port = std::stoi(listen.substr(listen.rfind(':') + 1));

  test::Conn conn = test::tcp_connect(port);
  ASSERT_TRUE(conn.ok());
  ASSERT_TRUE(conn.send("one"));
  ASSERT_TRUE(conn.read_until("one"));

  const auto added =
      client->Post("/proxies/car/toxics", R"({"type": "latency", "attributes": {"latency": 300}})",
                   "application/json");
  ASSERT_TRUE(added);
  ASSERT_EQ(added->status, 200) << added->body;
  auto sent = Clock::now();
  ASSERT_TRUE(conn.send("two"));
  ASSERT_TRUE(conn.read_until("onetwo"));
  EXPECT_GE(Clock::now() - sent, std::chrono::milliseconds(290));

  const auto removed = client->Delete("/proxies/car/toxics/latency_downstream");
  ASSERT_TRUE(removed);
  EXPECT_EQ(removed->status, 204);
  const auto toxics = client->Get("/proxies/car/toxics");
  ASSERT_TRUE(toxics);
  EXPECT_EQ(json::parse(toxics->body), json::array());
  ASSERT_TRUE(conn.send("three"));
  ASSERT_TRUE(conn.read_until("onetwothree"));

  const auto links = client->Get("/hil/links");
  ASSERT_TRUE(links);
  const json list = json::parse(links->body);
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].at("bytes").at("to_client"), 11);
  const auto metrics = client->Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_THAT(metrics->get_header_value("Content-Type"), StartsWith("text/plain; version=0.0.4"));
  EXPECT_THAT(metrics->body,
              HasSubstr("hil_proxy_bytes_total{route=\"car\",direction=\"to_client\"} 11\n"));
}

TEST_F(ApiServerTest, BadJsonOverHttpIs400AndTheLinkCarriesOn) {
  const json spec = {{"name", "car"}, {"listen", "127.0.0.1:0"}, {"upstream", car_address()}};
  const auto created = client->Post("/proxies", spec.dump(), "application/json");
  ASSERT_TRUE(created);
  const std::string listen = json::parse(created->body).at("listen");
  test::Conn conn = test::tcp_connect(std::stoi(listen.substr(listen.rfind(':') + 1)));
  ASSERT_TRUE(conn.ok());
  ASSERT_TRUE(conn.send("a"));
  ASSERT_TRUE(conn.read_until("a"));
  const json bad =
      error_body(client->Post("/proxies/car/toxics", "{\"type\":", "application/json"), 400);
  EXPECT_THAT(bad.at("error").get<std::string>(), StartsWith("body: not JSON (1:"));
  ASSERT_TRUE(conn.send("b"));
  ASSERT_TRUE(conn.read_until("ab"));
}

TEST(ApiServerStop, RightAfterStartAndTwice) {
  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  ProxyHub hub{context, ProxyHubOptions{}};
  ApiServerOptions options;
  options.port = 0;
  for (int i = 0; i < 5; ++i) {
    ApiServer server(io, hub, options);
    server.start();
    EXPECT_GT(server.port(), 0);
    server.stop();
    server.stop();
  }
}

TEST(ApiServerStop, APortInUseIsNamed) {
  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  ProxyHub hub{context, ProxyHubOptions{}};
  ApiServerOptions options;
  options.port = 0;
  ApiServer first(io, hub, options);
  first.start();
  options.port = first.port();
  ApiServer second(io, hub, options);
  try {
    second.start();
    FAIL() << "two servers on one port";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("127.0.0.1:" + std::to_string(first.port())));
  }
}

}  // namespace
}  // namespace hil::control
