// The control API's handlers, without sockets: a hub of routes on the
// virtual-time driver over mem:// endpoints, a client writing through it to
// an echoing car, and every endpoint's status and reply as a Toxiproxy
// client or a hil user sees them. Times are exact.
#include "control/proxy_api.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "link/executor.hpp"
#include "link/faults/profile_yaml.hpp"
#include "link/transport.hpp"

namespace hil::control {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

/// A car on mem://car that echoes every byte back.
struct EchoCar {
  std::unique_ptr<link::Listener> listener;
  std::vector<link::BytePipePtr> pipes;
  std::string received;

  EchoCar(link::TransportContext& context, const std::string& uri) {
    listener = link::listen(context, link::parse_endpoint(uri));
    listener->start([this](link::BytePipePtr pipe) {
      pipes.push_back(pipe);
      std::weak_ptr<link::BytePipe> weak = pipe;
      pipe->start({[this, weak](link::ByteView bytes) {
                     received.append(bytes.begin(), bytes.end());
                     if (auto self = weak.lock()) self->write(bytes);
                   },
                   [](std::error_code) {}});
    });
  }
};

/// A client of a route, with what it got back and when.
struct Client {
  link::BytePipePtr pipe;
  std::string received;
  std::vector<link::Time> arrivals;
  bool closed = false;

  void connect(link::TransportContext& context, const std::string& uri) {
    link::connect(context, link::parse_endpoint(uri),
                  [this, &context](std::error_code ec, link::BytePipePtr p) {
                    if (ec) return;
                    pipe = p;
                    p->start({[this, &context](link::ByteView bytes) {
                                received.append(bytes.begin(), bytes.end());
                                arrivals.push_back(context.executor.now());
                              },
                              [this](std::error_code) { closed = true; }});
                  });
  }
  void send(const std::string& text) { pipe->write(protocol::to_bytes(text)); }
};

class ProxyApi : public ::testing::Test {
 protected:
  link::VirtualExecutor ex;
  link::TransportContext ctx{ex};
  ProxyHub hub{ctx, ProxyHubOptions{}};
  EchoCar car{ctx, "mem://car"};

  ApiReply call(const std::string& method, const std::string& path, const std::string& body = "",
                const std::string& content_type = "application/json",
                std::vector<std::pair<std::string, std::string>> query = {}) {
    ApiRequest request{method, path, std::move(query), content_type, body};
    ApiInfo info;
    info.version = "1.2.3";
    return handle_api_request(hub, request, info);
  }
  static json body(const ApiReply& reply) { return json::parse(reply.body); }

  /// The route "car": clients at mem://front, the echo car behind it.
  void create_car_route(const std::string& protocol = "raw") {
    const ApiReply reply = call("POST", "/proxies",
                                json{{"name", "car"},
                                     {"listen", "mem://front"},
                                     {"upstream", "mem://car"},
                                     {"protocol", protocol}}
                                    .dump());
    ASSERT_EQ(reply.status, 201) << reply.body;
  }

  /// A client connected through the route, its first bytes echoed.
  void connect_client(Client& client) {
    client.connect(ctx, "mem://front");
    ex.run_for(link::milliseconds(1));
    ASSERT_TRUE(client.pipe);
    client.send("hello");
    ex.run_for(link::milliseconds(1));
    ASSERT_EQ(client.received, "hello");
  }

  /// The error reply's message, after checking its shape and status.
  static std::string error_of(const ApiReply& reply, int status) {
    EXPECT_EQ(reply.status, status) << reply.body;
    EXPECT_EQ(reply.content_type, "application/json");
    const json j = json::parse(reply.body);
    EXPECT_EQ(j.at("status"), status);
    return j.at("error").get<std::string>();
  }
};

// ------------------------------------------------------------- Toxiproxy's

TEST_F(ProxyApi, VersionIsPlainText) {
  const ApiReply reply = call("GET", "/version");
  EXPECT_EQ(reply.status, 200);
  EXPECT_THAT(reply.content_type, StartsWith("text/plain"));
  EXPECT_EQ(reply.body, "hil 1.2.3 (Toxiproxy API 2.x)");
}

TEST_F(ProxyApi, ARouteIsCreatedListedAndShownAsToxiproxyShowsAProxy) {
  EXPECT_EQ(body(call("GET", "/proxies")), json::object());
  create_car_route();
  const json proxy = body(call("GET", "/proxies/car"));
  EXPECT_EQ(proxy.at("name"), "car");
  EXPECT_EQ(proxy.at("listen"), "mem://front");
  EXPECT_EQ(proxy.at("enabled"), true);
  EXPECT_EQ(proxy.at("toxics"), json::array());
  EXPECT_EQ(proxy.at("protocol"), "raw");
  EXPECT_TRUE(proxy.contains("upstream"));
  EXPECT_TRUE(proxy.contains("profile"));
  const json all = body(call("GET", "/proxies"));
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all.at("car"), proxy);
  // A trailing slash is the same path.
  EXPECT_EQ(body(call("GET", "/proxies/car/")), proxy);
}

TEST_F(ProxyApi, CreateRefusesBadBodiesNamingWhatIsWrong) {
  EXPECT_THAT(error_of(call("POST", "/proxies", "{\"name\": \"car\",\n \"listen\" 1}"), 400),
              StartsWith("body: not JSON (2:"));
  EXPECT_THAT(error_of(call("POST", "/proxies", ""), 400), StartsWith("body: not JSON (1:1"));
  // A number no double holds is not JSON hil can read (found by the fuzz target).
  EXPECT_THAT(error_of(call("POST", "/proxies", R"({"name": 8e899})"), 400),
              StartsWith("body: not JSON (number overflow"));
  EXPECT_THAT(error_of(call("POST", "/proxies", "[1, 2]"), 400),
              StartsWith("body: expected an object"));
  EXPECT_THAT(
      error_of(call("POST", "/proxies", R"({"name": "car", "listen": "mem://front"})"), 400),
      StartsWith("upstream: "));
  EXPECT_EQ(body(call("GET", "/proxies")), json::object());
}

TEST_F(ProxyApi, ANameTakenIsAConflict) {
  create_car_route();
  const std::string again =
      json{{"name", "car"}, {"listen", "mem://other"}, {"upstream", "mem://car"}}.dump();
  EXPECT_THAT(error_of(call("POST", "/proxies", again), 409), HasSubstr("car"));
}

TEST_F(ProxyApi, AnUnknownRouteIsNotFound) {
  EXPECT_EQ(error_of(call("GET", "/proxies/nope"), 404), "proxy not found: nope");
  EXPECT_EQ(error_of(call("DELETE", "/proxies/nope"), 404), "proxy not found: nope");
  EXPECT_EQ(error_of(call("GET", "/proxies/nope/toxics"), 404), "proxy not found: nope");
  EXPECT_EQ(error_of(call("GET", "/hil/proxies/nope/links"), 404), "proxy not found: nope");
  EXPECT_EQ(error_of(call("PUT", "/hil/proxies/nope/faults", "rules: []"), 404),
            "proxy not found: nope");
}

TEST_F(ProxyApi, AnUnknownPathNamesItAndAWrongMethodListsTheAllowedOnes) {
  EXPECT_THAT(error_of(call("GET", "/toxics"), 404), HasSubstr("/toxics"));
  EXPECT_THAT(error_of(call("GET", "/"), 404), HasSubstr("nothing at /"));
  const ApiReply wrong = call("DELETE", "/version");
  EXPECT_EQ(error_of(wrong, 405), "method: DELETE is not allowed on /version (allowed: GET)");
  ASSERT_EQ(wrong.headers.size(), 1u);
  EXPECT_EQ(wrong.headers[0], (std::pair<std::string, std::string>{"Allow", "GET"}));
  EXPECT_THAT(error_of(call("PUT", "/proxies/car"), 405),
              HasSubstr("(allowed: GET, POST, PATCH, DELETE)"));
}

TEST_F(ProxyApi, PathSegmentsArePercentDecodedOneByOne) {
  const std::string spec =
      json{{"name", "car.1"}, {"listen", "mem://front"}, {"upstream", "mem://car"}}.dump();
  ASSERT_EQ(call("POST", "/proxies", spec).status, 201);
  EXPECT_EQ(body(call("GET", "/proxies/car%2E1")).at("name"), "car.1");
  // An encoded '/' stays in the name: no such route, not another path.
  EXPECT_EQ(error_of(call("GET", "/proxies/car%2F1"), 404), "proxy not found: car/1");
  EXPECT_THAT(error_of(call("GET", "/proxies/car%zz"), 400), StartsWith("path: "));
  EXPECT_THAT(error_of(call("GET", "/proxies/car%4"), 400), StartsWith("path: "));
}

TEST_F(ProxyApi, UpdateDisablesAndChecksTypes) {
  create_car_route();
  Client client;
  connect_client(client);
  EXPECT_THAT(error_of(call("POST", "/proxies/car", R"({"enabled": "no"})"), 400),
              StartsWith("enabled: expected true or false"));
  EXPECT_THAT(error_of(call("POST", "/proxies/car", R"({"listen": 5})"), 400),
              StartsWith("listen: expected a string"));
  EXPECT_FALSE(client.closed);
  const ApiReply off = call("POST", "/proxies/car", R"({"enabled": false})");
  EXPECT_EQ(off.status, 200) << off.body;
  EXPECT_EQ(body(off).at("enabled"), false);
  ex.run_for(link::milliseconds(1));
  EXPECT_TRUE(client.closed);
  EXPECT_EQ(body(call("PATCH", "/proxies/car", R"({"enabled": true})")).at("enabled"), true);
}

TEST_F(ProxyApi, DeleteRemovesTheRoute) {
  create_car_route();
  const ApiReply reply = call("DELETE", "/proxies/car");
  EXPECT_EQ(reply.status, 204);
  EXPECT_TRUE(reply.body.empty());
  EXPECT_EQ(call("GET", "/proxies/car").status, 404);
}

TEST_F(ProxyApi, PopulateCreatesAllOrNothing) {
  const json good =
      json::array({{{"name", "a"}, {"listen", "mem://a"}, {"upstream", "mem://car"}},
                   {{"name", "b"}, {"listen", "mem://b"}, {"upstream", "mem://car"}}});
  const ApiReply reply = call("POST", "/populate", good.dump());
  ASSERT_EQ(reply.status, 201) << reply.body;
  ASSERT_EQ(body(reply).at("proxies").size(), 2u);
  EXPECT_EQ(body(reply).at("proxies")[1].at("name"), "b");
  const json bad = json::array({{{"name", "c"}, {"listen", "mem://c"}, {"upstream", "mem://car"}},
                                {{"name", "d"}, {"listen", "mem://d"}}});
  EXPECT_THAT(error_of(call("POST", "/populate", bad.dump()), 400), StartsWith("[1].upstream: "));
  EXPECT_THAT(error_of(call("POST", "/populate", R"({"name": "x"})"), 400),
              StartsWith("body: expected an array"));
  EXPECT_EQ(body(call("GET", "/proxies")).size(), 2u);
}

TEST_F(ProxyApi, AToxicIsAddedListedChangedAndRemoved) {
  create_car_route();
  const ApiReply added =
      call("POST", "/proxies/car/toxics", R"({"type": "latency", "attributes": {"latency": 100}})");
  ASSERT_EQ(added.status, 200) << added.body;
  const json toxic = body(added);
  EXPECT_EQ(toxic.at("name"), "latency_downstream");
  EXPECT_EQ(toxic.at("type"), "latency");
  EXPECT_EQ(toxic.at("stream"), "downstream");
  EXPECT_EQ(toxic.at("toxicity"), 1.0);
  EXPECT_EQ(toxic.at("attributes").at("latency"), 100);
  EXPECT_EQ(body(call("GET", "/proxies/car/toxics")), json::array({toxic}));
  EXPECT_EQ(body(call("GET", "/proxies/car/toxics/latency_downstream")), toxic);
  EXPECT_EQ(body(call("GET", "/proxies/car")).at("toxics"), json::array({toxic}));
  EXPECT_THAT(error_of(call("POST", "/proxies/car/toxics",
                            R"({"type": "latency", "attributes": {"latency": 5}})"),
                       409),
              HasSubstr("latency_downstream"));
  const json changed = body(call("POST", "/proxies/car/toxics/latency_downstream",
                                 R"({"attributes": {"latency": 250}})"));
  EXPECT_EQ(changed.at("attributes").at("latency"), 250);
  EXPECT_EQ(call("DELETE", "/proxies/car/toxics/latency_downstream").status, 204);
  EXPECT_EQ(error_of(call("GET", "/proxies/car/toxics/latency_downstream"), 404),
            "toxic not found: latency_downstream");
  EXPECT_EQ(body(call("GET", "/proxies/car/toxics")), json::array());
}

TEST_F(ProxyApi, ALatencyToxicDelaysTheCarsBytesByItsMilliseconds) {
  create_car_route();
  Client client;
  connect_client(client);
  ASSERT_EQ(call("POST", "/proxies/car/toxics",
                 R"({"type": "latency", "stream": "downstream", "attributes": {"latency": 100}})")
                .status,
            200);
  const link::Time sent = ex.now();
  client.send("ping");
  ex.run_for(link::milliseconds(99));
  EXPECT_EQ(client.received, "hello");
  ex.run_for(link::milliseconds(1));
  EXPECT_EQ(client.received, "helloping");
  EXPECT_EQ(client.arrivals.back() - sent, link::milliseconds(100));
  EXPECT_EQ(car.received, "helloping");
}

TEST_F(ProxyApi, ToxicErrorsNameTheField) {
  create_car_route();
  EXPECT_THAT(error_of(call("POST", "/proxies/car/toxics", R"({"type": "nope"})"), 400),
              StartsWith("type: "));
  EXPECT_THAT(error_of(call("POST", "/proxies/car/toxics",
                            R"({"type": "latency", "attributes": {"latency": -5}})"),
                       400),
              StartsWith("attributes.latency: "));
  EXPECT_THAT(
      error_of(call("POST", "/proxies/car/toxics", R"({"type": "latency", "toxicity": 2})"), 400),
      StartsWith("toxicity: "));
  EXPECT_THAT(error_of(call("POST", "/proxies/car/toxics", "\"latency\""), 400),
              StartsWith("body: expected an object"));
  EXPECT_EQ(error_of(call("POST", "/proxies/car/toxics/nope", R"({"attributes": {}})"), 404),
            "toxic not found: nope");
}

TEST_F(ProxyApi, ResetRemovesToxicsMadeThroughTheApiAndEnablesEveryRoute) {
  create_car_route();
  ASSERT_EQ(call("POST", "/proxies/car/toxics", R"({"type": "latency"})").status, 200);
  ASSERT_EQ(call("POST", "/proxies/car", R"({"enabled": false})").status, 200);
  const ApiReply reply = call("POST", "/reset");
  EXPECT_EQ(reply.status, 204);
  const json proxy = body(call("GET", "/proxies/car"));
  EXPECT_EQ(proxy.at("toxics"), json::array());
  EXPECT_EQ(proxy.at("enabled"), true);
}

// ------------------------------------------------------------------- hil's

TEST_F(ProxyApi, LinksAreListedWithTheirBytes) {
  create_car_route();
  EXPECT_EQ(body(call("GET", "/hil/links")), json::array());
  Client client;
  connect_client(client);
  const json links = body(call("GET", "/hil/links"));
  ASSERT_EQ(links.size(), 1u);
  const json& l = links[0];
  EXPECT_EQ(l.at("route"), "car");
  EXPECT_EQ(l.at("link"), 1);
  EXPECT_EQ(l.at("open"), true);
  EXPECT_EQ(l.at("bytes").at("to_car"), 5);
  EXPECT_EQ(l.at("bytes").at("to_client"), 5);
  for (const char* key :
       {"client", "car", "opened_at_ms", "close_reason", "frames", "bad_frames", "faults"})
    EXPECT_TRUE(l.contains(key)) << key;
  EXPECT_EQ(body(call("GET", "/hil/proxies/car/links")), links);
}

TEST_F(ProxyApi, FaultsArePutAsYamlOrJsonAndReadBack) {
  create_car_route();
  const std::string yaml =
      "rules:\n"
      "  - kind: delay\n"
      "    delay: 40ms\n"
      "    direction: to_client\n";
  const ApiReply put = call("PUT", "/hil/proxies/car/faults", yaml, "application/yaml");
  ASSERT_EQ(put.status, 200) << put.body;
  EXPECT_EQ(body(put), json({{"rules", 1}}));
  const json got = body(call("GET", "/hil/proxies/car/faults"));
  EXPECT_EQ(got.at("rules"), 1);
  EXPECT_EQ(link::parse_fault_profile_text(got.at("yaml").get<std::string>(), "reply"),
            link::parse_fault_profile_text(yaml, "sent"));

  const std::string as_json = R"({"rules": [{"kind": "drop", "match": "STAT"},
                                            {"kind": "duplicate", "copies": 2}]})";
  const ApiReply put_json = call("PUT", "/hil/proxies/car/faults", as_json, "application/json");
  ASSERT_EQ(put_json.status, 200) << put_json.body;
  EXPECT_EQ(body(put_json).at("rules"), 2);
  // Anything that is not JSON is read as YAML.
  EXPECT_EQ(body(call("PUT", "/hil/proxies/car/faults", "[]", "")).at("rules"), 0);
}

TEST_F(ProxyApi, BadFaultsNameTheLineAndChangeNothing) {
  create_car_route();
  ASSERT_EQ(call("PUT", "/hil/proxies/car/faults", "- kind: duplicate\n", "text/yaml").status, 200);
  const std::string yaml = "rules:\n  - kind: delay\n    delya: 40ms\n";
  EXPECT_THAT(error_of(call("PUT", "/hil/proxies/car/faults", yaml, "application/yaml"), 400),
              AllOf(StartsWith("body:3:"), HasSubstr("delya")));
  EXPECT_THAT(
      error_of(call("PUT", "/hil/proxies/car/faults", "{\"rules\": [", "application/json"), 400),
      StartsWith("body: not JSON (1:"));
  EXPECT_EQ(body(call("GET", "/hil/proxies/car/faults")).at("rules"), 1);
}

TEST_F(ProxyApi, AStallHoldsTheLinksBytesForItsDuration) {
  create_car_route();
  Client client;
  connect_client(client);
  const ApiReply stall = call("POST", "/hil/proxies/car/links/1/stall",
                              R"({"duration_ms": 500, "direction": "to_client"})");
  ASSERT_EQ(stall.status, 204) << stall.body;
  const link::Time stalled_at = ex.now();
  client.send("ping");
  ex.run_for(link::milliseconds(499));
  EXPECT_EQ(car.received, "helloping");
  EXPECT_EQ(client.received, "hello");
  ex.run_for(link::milliseconds(1));
  EXPECT_EQ(client.received, "helloping");
  EXPECT_EQ(client.arrivals.back() - stalled_at, link::milliseconds(500));
}

TEST_F(ProxyApi, StallAndResetNameTheirFields) {
  create_car_route();
  Client client;
  connect_client(client);
  EXPECT_THAT(error_of(call("POST", "/hil/proxies/car/links/1/stall", "{}"), 400),
              StartsWith("duration_ms: missing"));
  EXPECT_THAT(
      error_of(call("POST", "/hil/proxies/car/links/1/stall", R"({"duration_ms": "2s"})"), 400),
      StartsWith("duration_ms: expected a number"));
  EXPECT_THAT(
      error_of(call("POST", "/hil/proxies/car/links/1/stall", R"({"duration_ms": -1})"), 400),
      StartsWith("duration_ms: -1 is out of range"));
  EXPECT_THAT(error_of(call("POST", "/hil/proxies/car/links/1/stall",
                            R"({"duration_ms": 5, "direction": "up"})"),
                       400),
              StartsWith("direction: 'up' is not a direction"));
  EXPECT_THAT(
      error_of(call("POST", "/hil/proxies/car/links/x/stall", R"({"duration_ms": 5})"), 400),
      StartsWith("link: 'x' is not a link number"));
  EXPECT_EQ(call("POST", "/hil/proxies/car/links/9/stall", R"({"duration_ms": 5})").status, 404);
  EXPECT_EQ(call("POST", "/hil/proxies/car/links/9/reset").status, 404);
  EXPECT_EQ(call("GET", "/hil/proxies/car/links/1/reset").status, 405);
}

TEST_F(ProxyApi, AResetClosesThatLinkOnly) {
  create_car_route();
  Client first;
  connect_client(first);
  Client second;
  connect_client(second);
  ASSERT_EQ(call("POST", "/hil/proxies/car/links/1/reset").status, 204);
  ex.run_for(link::milliseconds(1));
  EXPECT_TRUE(first.closed);
  EXPECT_FALSE(second.closed);
  second.send("still");
  ex.run_for(link::milliseconds(1));
  EXPECT_EQ(second.received, "hellostill");
  EXPECT_EQ(call("POST", "/hil/proxies/car/links/1/reset").status, 404);
}

TEST_F(ProxyApi, RecentFramesAreTheRouteProtocolsOldestFirst) {
  create_car_route("logi");
  Client client;
  client.connect(ctx, "mem://front");
  ex.run_for(link::milliseconds(1));
  ASSERT_TRUE(client.pipe);
  client.send("LOGI:SP:050:D7#LOGI:MV:FWD:23#");
  ex.run_for(link::milliseconds(1));
  const json frames = body(call("GET", "/hil/proxies/car/frames", "", "", {{"limit", "50"}}));
  ASSERT_GE(frames.size(), 2u);
  EXPECT_EQ(frames[0].at("direction"), "to_car");
  EXPECT_EQ(frames[0].at("kind"), "SP");
  EXPECT_EQ(frames[0].at("valid"), true);
  EXPECT_EQ(frames[0].at("link"), 1);
  EXPECT_THAT(frames[0].at("hex").get<std::string>(), StartsWith("4C 4F 47 49"));
  for (const char* key : {"at_ms", "text"})
    EXPECT_TRUE(frames[0].contains(key)) << key;
  EXPECT_EQ(body(call("GET", "/hil/proxies/car/frames", "", "", {{"limit", "1"}})).size(), 1u);
  EXPECT_THAT(error_of(call("GET", "/hil/proxies/car/frames", "", "", {{"limit", "0"}}), 400),
              StartsWith("limit: '0'"));
  EXPECT_THAT(error_of(call("GET", "/hil/proxies/car/frames", "", "", {{"limit", "lots"}}), 400),
              StartsWith("limit: 'lots'"));
}

TEST_F(ProxyApi, MetricsArePrometheusText) {
  create_car_route();
  Client client;
  connect_client(client);
  const ApiReply reply = call("GET", "/metrics");
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.content_type, "text/plain; version=0.0.4; charset=utf-8");
  EXPECT_THAT(reply.body, HasSubstr("# TYPE hil_proxy_bytes_total counter\n"));
  EXPECT_THAT(reply.body,
              HasSubstr("hil_proxy_bytes_total{route=\"car\",direction=\"to_car\"} 5\n"));
  EXPECT_THAT(reply.body,
              HasSubstr("hil_proxy_bytes_total{route=\"car\",direction=\"to_client\"} 5\n"));
  EXPECT_THAT(reply.body, HasSubstr("hil_proxy_connections_total{route=\"car\"} 1\n"));
  EXPECT_THAT(reply.body, HasSubstr("# TYPE hil_proxy_open_links gauge\n"));
  EXPECT_THAT(reply.body, HasSubstr("hil_proxy_open_links{route=\"car\"} 1\n"));
  EXPECT_THAT(reply.body, HasSubstr("hil_proxy_route_enabled{route=\"car\"} 1\n"));
  EXPECT_THAT(reply.body, HasSubstr("hil_proxy_faults_total{route=\"car\",kind=\"drop\"} 0\n"));
  for (const char* family : {"hil_proxy_frames_total", "hil_proxy_bad_frames_total",
                             "hil_proxy_refused_connections_total"})
    EXPECT_THAT(reply.body, HasSubstr(std::string("# HELP ") + family + " "));
}

// ------------------------------------------------------- bad requests

TEST_F(ProxyApi, OversizedAndDeeplyNestedBodiesAreRefusedBeforeParsing) {
  create_car_route();
  const std::string huge(kMaxApiBodyBytes + 1, ' ');
  EXPECT_EQ(error_of(call("POST", "/proxies", huge), 413),
            "body: 262145 bytes is over the limit of 262144");
  const std::string deep = std::string(100'000, '[') + std::string(100'000, ']');
  EXPECT_THAT(error_of(call("POST", "/proxies", deep), 400), StartsWith("body: nested deeper"));
  EXPECT_THAT(error_of(call("PUT", "/hil/proxies/car/faults", deep, "application/yaml"), 400),
              StartsWith("body: nested deeper"));
  // Brackets inside JSON strings are text, not nesting: the name is what
  // is refused.
  const std::string name_with_brackets = json{
      {"name", std::string(100, '[')},
      {"listen", "mem://x"},
      {"upstream", "mem://car"}}.dump();
  EXPECT_THAT(error_of(call("POST", "/proxies", name_with_brackets), 400), StartsWith("name: "));
}

TEST_F(ProxyApi, BadRequestsLeaveALiveLinkOpenAndCarrying) {
  create_car_route();
  Client client;
  connect_client(client);
  const std::vector<ApiRequest> bad = {
      {"POST", "/proxies/car/toxics", {}, "application/json", "{\"type\": \"latency\", "},
      {"POST", "/proxies/car/toxics", {}, "application/json", R"({"type": "nope"})"},
      {"POST",
       "/proxies/car/toxics",
       {},
       "application/json",
       R"({"type": "timeout", "attributes": {"timeout": "soon"}})"},
      {"POST",
       "/proxies/car/toxics",
       {},
       "application/json",
       R"({"type": "reset_peer", "attributes": {"timeout": 0}, "toxicity": -1})"},
      {"PUT", "/hil/proxies/car/faults", {}, "application/yaml", "rules:\n  - kind: reset\n  bad"},
      {"PUT",
       "/hil/proxies/car/faults",
       {},
       "application/yaml",
       "- kind: disconnect\n  at: soon\n"},
      {"POST",
       "/hil/proxies/car/links/1/stall",
       {},
       "application/json",
       R"({"duration_ms": 1e99})"},
      {"POST", "/hil/proxies/car/links/1/reset/now", {}, "", ""},
      {"POST", "/proxies/car", {}, "application/json", R"({"enabled": 0})"},
      {"POST", "/proxies/car", {}, "application/json", R"({"upstream": "rfc2217://1.2.3.4:5"})"},
      {"POST", "/proxies/car", {}, "application/json", R"({"listen": "nonsense://"})"},
      {"DELETE", "/proxies/car/toxics/none", {}, "", ""},
      {"POST", "/populate", {}, "application/json", R"([{"name": "car", "listen": 7}])"},
      {"DELETE", "/proxies", {}, "", ""},
      {"GET", "/hil/proxies/car/frames", {{"limit", "-1"}}, "", ""},
  };
  for (const ApiRequest& request : bad) {
    const ApiReply reply = handle_api_request(hub, request);
    EXPECT_GE(reply.status, 400) << request.method << ' ' << request.path << ' ' << request.body;
    EXPECT_LT(reply.status, 500) << request.method << ' ' << request.path << ": " << reply.body;
  }
  ex.run_for(link::milliseconds(1));
  EXPECT_FALSE(client.closed);
  client.send(" again");
  ex.run_for(link::milliseconds(1));
  EXPECT_EQ(client.received, "hello again");
  const json links = body(call("GET", "/hil/links"));
  ASSERT_EQ(links.size(), 1u);
  EXPECT_EQ(links[0].at("open"), true);
  EXPECT_EQ(links[0].at("faults"), json::object());
  const json proxy = body(call("GET", "/proxies/car"));
  EXPECT_EQ(proxy.at("toxics"), json::array());
  EXPECT_EQ(proxy.at("enabled"), true);
  EXPECT_EQ(proxy.at("listen"), "mem://front");
  EXPECT_EQ(body(call("GET", "/hil/proxies/car/faults")).at("rules"), 0);
}

TEST_F(ProxyApi, BytesThatAreNotUtf8ComeBackReplacedNotAsAFailure) {
  const ApiReply reply = call("GET", "/proxies/\xff\xfe");
  EXPECT_EQ(reply.status, 404);
  EXPECT_NO_THROW((void)json::parse(reply.body));
}

// -------------------------------------------------- a profile as YAML

TEST(FaultProfileYaml, EveryKindReadsBackToTheSameRules) {
  const std::string yaml = R"(rules:
  - kind: fragment
    name: cut
    sizes: [2, 5]
    gap: [1ms, 3ms]
  - kind: coalesce
    count: 3
    window: 20ms
  - kind: corrupt
    target: field
    field: payload
    bits: 2
    match: "FB:ST"
  - kind: drop
    unit: bytes
    count: [1, 4]
    direction: to_car
    every: 3
  - kind: duplicate
    copies: 2
    first: 5
  - kind: garbage
    hex: "DE AD"
    probability: 0.125
  - kind: garbage
    length: [3, 7]
    at_frame: 9
  - kind: delay
    delay: 40ms
    jitter: 1500us
    from: 1s
    to: 2.5s
  - kind: stall
    for: 2s
    at: 3s
  - kind: bandwidth
    bytes_per_second: 960
  - kind: disconnect
    at: 10s
  - kind: reset
    at_frame: 50
  - kind: refuse
    for: 1s
    at: 7s
  - kind: limit_data
    bytes: 4096
    direction: to_client
  - kind: slow_close
    delay: 250ms
)";
  const link::FaultProfile profile = link::parse_fault_profile_text(yaml, "sent");
  const std::string written = fault_profile_yaml(profile);
  EXPECT_EQ(link::parse_fault_profile_text(written, "written"), profile) << written;
  EXPECT_EQ(fault_profile_yaml({}), "rules: []\n");
}

TEST(PercentDecode, DecodesEscapesAndRefusesBrokenOnes) {
  EXPECT_EQ(percent_decode("a%20b%2Fc"), "a b/c");
  EXPECT_EQ(percent_decode("plain+text"), "plain+text");
  EXPECT_EQ(percent_decode("%"), std::nullopt);
  EXPECT_EQ(percent_decode("%4"), std::nullopt);
  EXPECT_EQ(percent_decode("%G0"), std::nullopt);
}

}  // namespace
}  // namespace hil::control
