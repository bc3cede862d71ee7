// Several proxy routes in one hub, in virtual time over mem:// pipes: each
// route's links, toxics drawn per link, populate and reset, and the errors
// the control API answers with. A few checks need real TCP ports.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <asio/io_context.hpp>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "control/proxy_hub.hpp"
#include "link/asio_executor.hpp"
#include "link/capture/wire_log.hpp"
#include "link/executor.hpp"
#include "link/faults/profile_yaml.hpp"

namespace hil::control {
namespace {

using link::Time;
using protocol::to_bytes;
using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;

// A car on mem://NAME that echoes every byte at once.
struct HubEchoCar {
  std::unique_ptr<link::Listener> listener;
  std::vector<link::BytePipePtr> pipes;

  HubEchoCar(link::TransportContext& ctx, const std::string& name) {
    listener = link::listen(ctx, link::parse_endpoint("mem://" + name));
    listener->start([this](link::BytePipePtr p) {
      pipes.push_back(p);
      std::weak_ptr<link::BytePipe> weak = p;
      p->start({[weak](link::ByteView b) {
                  if (auto self = weak.lock()) self->write(b);
                },
                [](std::error_code) {}});
    });
  }
};

// A client of a route: what came back and when.
struct HubClient {
  link::Executor* executor = nullptr;
  link::BytePipePtr pipe;
  std::string received;
  std::vector<Time> arrivals;
  std::optional<std::error_code> closed;
  std::error_code connect_error;

  void send(const std::string& text) { pipe->write(to_bytes(text)); }
};

RouteSpec route(const std::string& name, const std::string& listen, const std::string& upstream,
                const std::string& protocol = "logi") {
  RouteSpec spec;
  spec.name = name;
  spec.listen = listen;
  spec.upstream = upstream;
  spec.protocol = protocol;
  return spec;
}

// The ApiError `f` throws: its status and message.
template <class F>
std::pair<int, std::string> api_error(F f) {
  try {
    f();
  } catch (const ApiError& e) {
    return {e.status(), e.what()};
  }
  return {0, "no error"};
}

class ProxyHubTest : public ::testing::Test {
 protected:
  link::VirtualExecutor ex;
  link::TransportContext ctx{ex};
  HubEchoCar car_a{ctx, "car-a"};
  HubEchoCar car_b{ctx, "car-b"};
  ProxyHub hub{ctx, ProxyHubOptions{}};

  std::unique_ptr<HubClient> client(const std::string& uri) {
    auto c = std::make_unique<HubClient>();
    c->executor = &ex;
    HubClient* raw = c.get();
    link::connect(ctx, link::parse_endpoint(uri), [raw](std::error_code ec, link::BytePipePtr p) {
      raw->connect_error = ec;
      if (ec) return;
      raw->pipe = p;
      p->start({[raw](link::ByteView b) {
                  raw->received.append(b.begin(), b.end());
                  raw->arrivals.push_back(raw->executor->now());
                },
                [raw](std::error_code e) { raw->closed = e; }});
    });
    ex.run_for(milliseconds(1));
    return c;
  }
  // A round trip through a client: what came back within 2 s.
  std::string echo(HubClient& c, const std::string& text = "LOGI:SP:050:D7#") {
    c.received.clear();
    c.send(text);
    ex.run_for(seconds(2));
    return c.received;
  }
};

TEST_F(ProxyHubTest, TwoRoutesCarryTheirOwnLinks) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  hub.create(route("b", "mem://b", "mem://car-b", "raw"));
  auto ca = client("mem://a");
  auto cb = client("mem://b");
  EXPECT_EQ(echo(*ca), "LOGI:SP:050:D7#");
  EXPECT_EQ(echo(*cb, "hello"), "hello");

  ASSERT_EQ(hub.routes().size(), 2u);
  EXPECT_EQ(hub.get("a").proxy->counters().frames[0], 1u);
  EXPECT_EQ(hub.get("b").proxy->counters().bytes[0], 5u);
  EXPECT_EQ(hub.get("a").proxy->links().size(), 1u);

  const auto json = to_json(hub.get("a"));
  EXPECT_EQ(json["name"], "a");
  EXPECT_EQ(json["listen"], "mem://a");
  EXPECT_EQ(json["upstream"], "mem://car-a");
  EXPECT_EQ(json["enabled"], true);
  EXPECT_EQ(json["toxics"], nlohmann::json::array());
  EXPECT_EQ(json["protocol"], "logi");
  EXPECT_EQ(json["profile"], "guide");  // LOGI's default profile

  // Each route draws from its own seed.
  EXPECT_NE(hub.get("a").proxy->links()[0].seed, hub.get("b").proxy->links()[0].seed);
}

TEST_F(ProxyHubTest, ToxicsActOnOpenLinksAndGoAwayWhenRemoved) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  auto c = client("mem://a");
  const Toxic& toxic = hub.add_toxic(
      "a", {{"type", "latency"}, {"stream", "downstream"}, {"attributes", {{"latency", 300}}}});
  EXPECT_EQ(toxic.name, "latency_downstream");
  const Time sent = ex.now();
  EXPECT_EQ(echo(*c), "LOGI:SP:050:D7#");
  EXPECT_EQ(c->arrivals.back() - sent, milliseconds(300));

  hub.update_toxic("a", "latency_downstream", {{"attributes", {{"latency", 100}}}});
  EXPECT_EQ(hub.get_toxic("a", "latency_downstream").attributes["latency"], 100);
  const Time again = ex.now();
  echo(*c);
  EXPECT_EQ(c->arrivals.back() - again, milliseconds(100));

  hub.remove_toxic("a", "latency_downstream");
  const Time clean = ex.now();
  echo(*c);
  EXPECT_EQ(c->arrivals.back() - clean, milliseconds(0));
  EXPECT_TRUE(hub.get("a").spec.toxics.empty());
}

TEST_F(ProxyHubTest, ToxicityIsDrawnOncePerLink) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  hub.add_toxic("a", {{"type", "latency"}, {"toxicity", 0.5}, {"attributes", {{"latency", 200}}}});
  std::vector<std::unique_ptr<HubClient>> clients;
  for (int i = 0; i < 20; ++i)
    clients.push_back(client("mem://a"));
  for (auto& c : clients)
    c->send("LOGI:SP:050:D7#");
  const Time sent = ex.now();
  ex.run_for(seconds(1));
  const auto links = hub.get("a").proxy->links();
  ASSERT_EQ(links.size(), 20u);
  const Toxic& toxic = hub.get_toxic("a", "latency_downstream");
  std::size_t delayed = 0;
  for (std::size_t i = 0; i < clients.size(); ++i) {
    ASSERT_EQ(clients[i]->arrivals.size(), 1u);
    const bool slow = clients[i]->arrivals[0] - sent == milliseconds(200);
    EXPECT_EQ(slow, acts_on_link(toxic, links[i].seed)) << "link " << links[i].number;
    delayed += slow ? 1 : 0;
  }
  EXPECT_GT(delayed, 0u);
  EXPECT_LT(delayed, 20u);
}

TEST_F(ProxyHubTest, StallAndResetActOnOneLink) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  auto first = client("mem://a");
  auto second = client("mem://a");
  hub.stall_link("a", 1, seconds(1), link::DirectionFilter::both);
  const Time stalled_at = ex.now();
  first->send("LOGI:SP:050:D7#");
  second->send("LOGI:SP:050:D7#");
  ex.run_for(seconds(2));
  ASSERT_EQ(first->arrivals.size(), 1u);
  EXPECT_EQ(first->arrivals[0] - stalled_at, seconds(1));
  EXPECT_EQ(second->arrivals[0], stalled_at);

  hub.reset_link("a", 2);
  ex.run_for(milliseconds(1));
  EXPECT_EQ(second->closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_FALSE(first->closed.has_value());
  EXPECT_EQ(api_error([&] { hub.reset_link("a", 2); }),
            std::make_pair(404, std::string("link: proxy a has no open link 2")));
  EXPECT_EQ(
      api_error([&] { hub.stall_link("a", 9, seconds(1), link::DirectionFilter::both); }).first,
      404);
}

TEST_F(ProxyHubTest, DisablingCutsTheLinksAndEnablingListensAgain) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  auto c = client("mem://a");
  hub.update("a", std::nullopt, std::nullopt, false);
  ex.run_for(milliseconds(1));
  EXPECT_EQ(c->closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_EQ(to_json(hub.get("a"))["enabled"], false);
  EXPECT_EQ(client("mem://a")->connect_error, std::errc::connection_refused);

  hub.update("a", std::nullopt, std::nullopt, true);
  auto d = client("mem://a");
  EXPECT_EQ(echo(*d), "LOGI:SP:050:D7#");
}

TEST_F(ProxyHubTest, ANewUpstreamRestartsTheRouteAndKeepsItsToxics) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  hub.add_toxic("a", {{"type", "latency"}, {"attributes", {{"latency", 50}}}});
  auto c = client("mem://a");
  const auto& updated = hub.update("a", std::nullopt, "mem://car-b", std::nullopt);
  EXPECT_EQ(updated.spec.upstream, "mem://car-b");
  EXPECT_EQ(updated.spec.toxics.size(), 1u);
  ex.run_for(milliseconds(1));
  EXPECT_TRUE(c->closed.has_value());
  auto d = client("mem://a");
  const Time sent = ex.now();
  EXPECT_EQ(echo(*d), "LOGI:SP:050:D7#");
  EXPECT_EQ(d->arrivals.back() - sent, milliseconds(50));

  // A bad new upstream leaves the route as it was, its links open.
  EXPECT_EQ(api_error([&] { hub.update("a", std::nullopt, "nope://x", std::nullopt); }).first, 400);
  EXPECT_FALSE(d->closed.has_value());
  EXPECT_EQ(hub.get("a").spec.upstream, "mem://car-b");
}

TEST_F(ProxyHubTest, ResetRestoresTheDeclaredFaultsAndToxics) {
  RouteSpec spec = route("a", "mem://a", "mem://car-a");
  spec.toxics.push_back(
      parse_toxic({{"type", "latency"}, {"attributes", {{"latency", 100}}}}, Time{0}));
  spec.faults = link::parse_fault_profile_text("rules: [{kind: drop, match: MV}]", "t");
  hub.create(spec);
  hub.remove_toxic("a", "latency_downstream");
  hub.add_toxic("a", {{"type", "latency"}, {"name", "slow"}, {"attributes", {{"latency", 700}}}});
  hub.set_faults("a", link::FaultProfile{});
  hub.update("a", std::nullopt, std::nullopt, false);

  hub.reset();
  const auto& a = hub.get("a");
  ASSERT_EQ(a.spec.toxics.size(), 1u);
  EXPECT_EQ(a.spec.toxics[0].name, "latency_downstream");
  EXPECT_EQ(a.spec.faults, spec.faults);
  EXPECT_TRUE(a.spec.enabled);
  auto c = client("mem://a");
  const Time sent = ex.now();
  EXPECT_EQ(echo(*c, "LOGI:MV:FWD:23#LOGI:SP:050:D7#"), "LOGI:SP:050:D7#");
  EXPECT_EQ(c->arrivals.back() - sent, milliseconds(100));

  // A route made through the API has nothing declared: reset clears it.
  hub.create(route("b", "mem://b", "mem://car-b"));
  hub.add_toxic("b", {{"type", "latency"}, {"attributes", {{"latency", 100}}}});
  hub.reset();
  EXPECT_TRUE(hub.get("b").spec.toxics.empty());
}

TEST_F(ProxyHubTest, PopulateKeepsRoutesDeclaredAlikeWithTheirLinks) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  hub.add_toxic("a", {{"type", "latency"}, {"attributes", {{"latency", 10}}}});
  const auto* proxy_before = hub.get("a").proxy.get();
  auto c = client("mem://a");

  const auto made =
      hub.populate({route("a", "mem://a", "mem://car-a"), route("b", "mem://b", "mem://car-b")});
  ASSERT_EQ(made.size(), 2u);
  EXPECT_EQ(made[0]->spec.name, "a");
  EXPECT_EQ(made[1]->spec.name, "b");
  EXPECT_EQ(hub.get("a").proxy.get(), proxy_before);
  EXPECT_EQ(hub.get("a").spec.toxics.size(), 1u);
  EXPECT_EQ(echo(*c), "LOGI:SP:050:D7#");
  EXPECT_FALSE(c->closed.has_value());

  // Declared otherwise on the same address: replaced, its links closed.
  hub.populate({route("a", "mem://a", "mem://car-b")});
  ex.run_for(milliseconds(1));
  EXPECT_TRUE(c->closed.has_value());
  EXPECT_EQ(hub.get("a").spec.upstream, "mem://car-b");
  EXPECT_TRUE(hub.get("a").spec.toxics.empty());
  EXPECT_EQ(echo(*client("mem://a")), "LOGI:SP:050:D7#");
  EXPECT_EQ(hub.routes().size(), 2u);  // b stays: populate adds, it does not prune
}

TEST_F(ProxyHubTest, PopulateIsAllOrNothing) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  auto c = client("mem://a");
  // A bad field: nothing is touched.
  auto bad = api_error([&] {
    hub.populate({route("a", "mem://a", "mem://car-b"), route("c", "mem://c", "mem://car-a"),
                  route("d", "mem://d", "rfc2217://127.0.0.1:4000")});
  });
  EXPECT_EQ(bad.first, 400);
  EXPECT_THAT(bad.second, HasSubstr("upstream: "));
  EXPECT_THROW(hub.get("c"), ApiError);
  EXPECT_EQ(hub.get("a").spec.upstream, "mem://car-a");
  EXPECT_FALSE(c->closed.has_value());

  // An address in use, found while starting: the routes made are undone
  // and the one replaced listens again.
  hub.create(route("x", "mem://taken", "mem://car-a"));
  auto in_use = api_error([&] {
    hub.populate({route("a", "mem://a", "mem://car-b"), route("c", "mem://c", "mem://car-a"),
                  route("d", "mem://taken", "mem://car-a")});
  });
  EXPECT_EQ(in_use, std::make_pair(409, std::string("listen: mem://taken is in use")));
  EXPECT_THROW(hub.get("c"), ApiError);
  EXPECT_THROW(hub.get("d"), ApiError);
  EXPECT_EQ(hub.get("a").spec.upstream, "mem://car-a");
  EXPECT_EQ(echo(*client("mem://a")), "LOGI:SP:050:D7#");
  EXPECT_EQ(client("mem://c")->connect_error, std::errc::connection_refused);
}

TEST_F(ProxyHubTest, ErrorsNameTheField) {
  hub.create(route("a", "mem://a", "mem://car-a"));
  EXPECT_EQ(api_error([&] { hub.get("nope"); }),
            std::make_pair(404, std::string("proxy not found: nope")));
  EXPECT_EQ(api_error([&] { hub.get_toxic("a", "t"); }),
            std::make_pair(404, std::string("toxic not found: t")));
  EXPECT_EQ(api_error([&] { hub.remove("nope"); }).first, 404);
  EXPECT_EQ(api_error([&] { hub.create(route("a", "mem://a2", "mem://car-a")); }),
            std::make_pair(409, std::string("name: a proxy named a already exists")));
  EXPECT_EQ(api_error([&] { hub.create(route("z", "mem://a", "mem://car-a")); }),
            std::make_pair(409, std::string("listen: mem://a is in use")));
  hub.add_toxic("a", {{"type", "latency"}});
  EXPECT_EQ(api_error([&] { hub.add_toxic("a", {{"type", "latency"}}); }).first, 409);

  const auto status_and = [&](RouteSpec spec) { return api_error([&] { hub.create(spec); }); };
  auto e = status_and(route("z", "mem://z", "pty://"));
  EXPECT_EQ(e.first, 400);
  EXPECT_THAT(e.second, testing::StartsWith("upstream: "));
  e = status_and(route("z", "nope://z", "mem://car-a"));
  EXPECT_EQ(e.first, 400);
  EXPECT_THAT(e.second, testing::StartsWith("listen: "));
  e = status_and(route("z", "mem://z", "mem://car-a", "logo"));
  EXPECT_EQ(e.first, 400);
  EXPECT_THAT(e.second, HasSubstr("protocol: unknown protocol 'logo'"));
  EXPECT_THAT(e.second, HasSubstr("logi, wr8, arduino, leka, raw"));
  auto with_profile = route("z", "mem://z", "mem://car-a");
  with_profile.profile = "nightly";
  e = status_and(with_profile);
  EXPECT_EQ(e.first, 400);
  EXPECT_THAT(e.second, testing::StartsWith("profile: "));
  EXPECT_THAT(e.second, HasSubstr("nightly"));
  e = status_and(route("z", "mem://z", "127.0.0.1:4000?x", "raw"));
  EXPECT_EQ(e.first, 400);
  e = status_and(route("z", "mem://z", "rfc2217://127.0.0.1:4000"));
  EXPECT_EQ(e.first, 400);
  EXPECT_THAT(e.second, HasSubstr("cannot connect to an RFC 2217 server"));
  e = status_and(route("bad name", "mem://z", "mem://car-a"));
  EXPECT_EQ(e.first, 400);
  EXPECT_THAT(e.second, testing::StartsWith("name: "));
  EXPECT_EQ(hub.routes().size(), 1u);
}

TEST(ParseRouteSpec, ReadsTheToxiproxyShapeAndNamesBadFields) {
  const auto spec = parse_route_spec({{"name", "car"},
                                      {"listen", "127.0.0.1:0"},
                                      {"upstream", "127.0.0.1:9000"},
                                      {"enabled", false},
                                      {"protocol", "arduino"},
                                      {"profile", "readme"},
                                      {"extra", 1}});
  EXPECT_EQ(spec.name, "car");
  EXPECT_EQ(spec.listen, "127.0.0.1:0");
  EXPECT_EQ(spec.upstream, "127.0.0.1:9000");
  EXPECT_FALSE(spec.enabled);
  EXPECT_EQ(spec.protocol, "arduino");
  EXPECT_EQ(spec.profile, "readme");
  const auto defaults = parse_route_spec({{"name", "car"}, {"upstream", "127.0.0.1:9000"}});
  EXPECT_EQ(defaults.listen, "");
  EXPECT_TRUE(defaults.enabled);
  EXPECT_EQ(defaults.protocol, "raw");

  const auto message = [](const nlohmann::json& body) {
    return api_error([&] { parse_route_spec(body); });
  };
  EXPECT_EQ(message({{"name", "car"}}).first, 400);
  EXPECT_THAT(message({{"name", "car"}}).second, testing::StartsWith("upstream: "));
  EXPECT_THAT(message({{"upstream", "x:1"}}).second, testing::StartsWith("name: "));
  EXPECT_THAT(message({{"name", 3}, {"upstream", "x:1"}}).second,
              testing::StartsWith("name: expected a string"));
  EXPECT_THAT(message({{"name", "car"}, {"upstream", "x:1"}, {"enabled", "yes"}}).second,
              testing::StartsWith("enabled: expected true or false"));
  EXPECT_THAT(message({{"name", "car"}, {"upstream", "x:1"}, {"listen", 8080}}).second,
              testing::StartsWith("listen: expected a string"));
  EXPECT_THAT(message(nlohmann::json::array()).second, testing::StartsWith("body: "));
}

// Over real TCP: listen addresses in Toxiproxy's form, the real port shown,
// a port taken answered with 409, and one wire log for every route.
TEST(ProxyHubTcp, ListensWhereToldAndSharesOneWireLog) {
  asio::io_context io;
  link::AsioExecutor executor(io);
  link::TransportContext ctx{executor, &io};
  const auto dir =
      std::filesystem::temp_directory_path() / ("hil-hub-test-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ProxyHubOptions options;
  options.wire_log_path = (dir / "wire.ndjson").string();
  options.pcap_dir = dir.string();
  ProxyHub hub(ctx, options);

  auto car = link::listen(ctx, link::parse_endpoint("tcp://127.0.0.1:0"));
  std::vector<link::BytePipePtr> car_pipes;
  car->start([&](link::BytePipePtr p) {
    car_pipes.push_back(p);
    std::weak_ptr<link::BytePipe> weak = p;
    p->start({[weak](link::ByteView b) {
                if (auto self = weak.lock()) self->write(b);
              },
              [](std::error_code) {}});
  });
  const std::string upstream = car->address().substr(6);  // "127.0.0.1:PORT"
  hub.create(route("a", "", upstream));
  hub.create(route("b", "127.0.0.1:0", "tcp://" + upstream));
  const std::string listen_a = to_json(hub.get("a"))["listen"];
  EXPECT_THAT(listen_a, testing::StartsWith("127.0.0.1:"));
  EXPECT_NE(listen_a, "127.0.0.1:0");
  EXPECT_EQ(api_error([&] { hub.create(route("c", listen_a, upstream)); }),
            std::make_pair(409, "listen: " + listen_a + " is in use"));

  std::string got_a, got_b;
  std::vector<link::BytePipePtr> pipes;
  const auto talk = [&](const std::string& listen, std::string& got) {
    link::connect(
        ctx, link::parse_endpoint("tcp://" + listen), [&](std::error_code ec, link::BytePipePtr p) {
          if (ec) return;
          pipes.push_back(p);
          p->start(
              {[&](link::ByteView b) { got.append(b.begin(), b.end()); }, [](std::error_code) {}});
          p->write(to_bytes("LOGI:SP:050:D7#"));
        });
  };
  talk(listen_a, got_a);
  talk(to_json(hub.get("b"))["listen"], got_b);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while ((got_a.size() < 15 || got_b.size() < 15) && std::chrono::steady_clock::now() < deadline) {
    io.run_for(std::chrono::milliseconds(5));
    io.restart();
  }
  EXPECT_EQ(got_a, "LOGI:SP:050:D7#");
  EXPECT_EQ(got_b, "LOGI:SP:050:D7#");
  hub.close();
  io.run_for(std::chrono::milliseconds(20));

  std::set<std::string> links;
  for (const auto& record : link::read_wire_log(dir / "wire.ndjson"))
    links.insert(record["link"].get<std::string>());
  EXPECT_EQ(links, (std::set<std::string>{"a/link1", "b/link1"}));
  EXPECT_TRUE(std::filesystem::exists(dir / "a-link1.pcap"));
  EXPECT_TRUE(std::filesystem::exists(dir / "b-link1.pcap"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hil::control
