// The proxy as the control API drives it, in virtual time over mem://
// pipes: per-link rules, stalling and resetting one link, disabling and
// enabling, and what is counted on each link and in total.

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "link/executor.hpp"
#include "link/faults/profile_yaml.hpp"
#include "link/proxy.hpp"
#include "link/transport.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;
using std::chrono::milliseconds;

// A car on mem://car that echoes every byte at once.
struct MemEchoCar {
  std::unique_ptr<Listener> listener;
  std::vector<BytePipePtr> pipes;

  explicit MemEchoCar(TransportContext& ctx) {
    listener = listen(ctx, parse_endpoint("mem://car"));
    listener->start([this](BytePipePtr p) {
      pipes.push_back(p);
      std::weak_ptr<BytePipe> weak = p;
      p->start({[weak](ByteView b) {
                  if (auto self = weak.lock()) self->write(b);
                },
                [](std::error_code) {}});
    });
  }
};

// A client of the proxy: what came back, and when.
struct MemClient {
  Executor* executor = nullptr;
  BytePipePtr pipe;
  std::string received;
  std::vector<Time> arrivals;
  std::optional<std::error_code> closed;
  std::error_code connect_error;

  void connect_to(TransportContext& ctx, const std::string& uri) {
    executor = &ctx.executor;
    connect(ctx, parse_endpoint(uri), [this](std::error_code ec, BytePipePtr p) {
      connect_error = ec;
      if (ec) return;
      pipe = p;
      p->start({[this](ByteView b) {
                  received.append(b.begin(), b.end());
                  arrivals.push_back(executor->now());
                },
                [this](std::error_code e) { closed = e; }});
    });
  }
  void send(const std::string& text) { pipe->write(to_bytes(text)); }
};

class ProxyRoutesTest : public ::testing::Test {
 protected:
  VirtualExecutor ex;
  TransportContext ctx{ex};
  MemEchoCar car{ctx};

  ProxyOptions options(const std::string& protocol = "logi") {
    ProxyOptions o;
    o.name = "car";
    o.listen = parse_endpoint("mem://proxy");
    o.upstream = parse_endpoint("mem://car");
    o.protocol = protocol_adapter(protocol);
    o.seed = 11;
    return o;
  }
  // A connected client; runs the executor until the link is joined.
  std::unique_ptr<MemClient> client() {
    auto c = std::make_unique<MemClient>();
    c->connect_to(ctx, "mem://proxy");
    ex.run_for(milliseconds(1));
    return c;
  }
};

TEST_F(ProxyRoutesTest, CountsFramesAndBadFramesPerLinkAndInTotal) {
  Proxy proxy(ctx, options());
  proxy.start();
  auto a = client();
  a->send("LOGI:SP:050:D7#LOGI:SP:050:00#");  // the second's checksum is wrong
  ex.run_for(milliseconds(10));
  ASSERT_EQ(a->received, "LOGI:SP:050:D7#LOGI:SP:050:00#");

  const auto links = proxy.links();
  ASSERT_EQ(links.size(), 1u);
  const auto& link = links[0];
  EXPECT_EQ(link.number, 1u);
  EXPECT_TRUE(link.open);
  EXPECT_EQ(link.seed, 11u);
  for (const auto d : {Direction::to_car, Direction::to_client}) {
    const auto i = static_cast<std::size_t>(d);
    EXPECT_EQ(link.frames[i], 1u) << to_string(d);
    EXPECT_EQ(link.bad_frames[i], 1u) << to_string(d);
    EXPECT_EQ(link.stats.bytes_delivered[i], 30u) << to_string(d);
  }

  const auto recent = proxy.recent_frames(10);
  ASSERT_EQ(recent.size(), 4u);
  EXPECT_EQ(recent[0].direction, Direction::to_car);
  EXPECT_EQ(recent[0].link, 1u);
  EXPECT_TRUE(recent[0].frame.valid);
  EXPECT_EQ(recent[0].frame.kind, "SP");
  EXPECT_FALSE(recent[1].frame.valid);
  EXPECT_EQ(recent[2].direction, Direction::to_client);
  EXPECT_EQ(proxy.recent_frames(1).size(), 1u);
  EXPECT_FALSE(proxy.recent_frames(1)[0].frame.valid);

  // Totals keep counting after the link has closed.
  a->pipe->close();
  ex.run_for(milliseconds(10));
  auto b = client();
  b->send("LOGI:SP:050:D7#");
  ex.run_for(milliseconds(10));
  const auto totals = proxy.counters();
  EXPECT_EQ(totals.connections, 2u);
  EXPECT_EQ(totals.links_opened, 2u);
  EXPECT_EQ(totals.open_links, 1u);
  EXPECT_EQ(totals.frames[0], 2u);
  EXPECT_EQ(totals.frames[1], 2u);
  EXPECT_EQ(totals.bad_frames[0], 1u);
  EXPECT_EQ(totals.bytes[0], 45u);
  const auto both = proxy.links();
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].number, 2u);  // the open one first
  EXPECT_EQ(both[1].number, 1u);
  EXPECT_FALSE(both[1].open);
  EXPECT_EQ(both[1].close_reason, "client closed");
}

TEST_F(ProxyRoutesTest, FaultsAreCountedByKind) {
  auto o = options();
  o.faults = parse_fault_profile_text("rules: [{kind: drop, direction: to_car, match: SP}]", "t");
  Proxy proxy(ctx, o);
  proxy.start();
  auto a = client();
  a->send("LOGI:SP:050:D7#LOGI:SP:050:D7#");
  ex.run_for(milliseconds(10));
  EXPECT_EQ(a->received, "");
  const auto drop = static_cast<std::size_t>(FaultKind::drop);
  EXPECT_EQ(proxy.links()[0].faults[drop], 2u);
  EXPECT_EQ(proxy.counters().faults[drop], 2u);
}

TEST_F(ProxyRoutesTest, LinkFaultsAreAskedPerLinkAndAgainOnRefresh) {
  bool drop_on_every_link = false;
  std::vector<std::size_t> asked;
  auto o = options();
  o.link_faults = [&](const ProxyLinkInfo& info) {
    asked.push_back(info.number);
    if (info.number != 2 && !drop_on_every_link) return FaultProfile{};
    return parse_fault_profile_text("rules: [{kind: drop, direction: to_car}]", "t");
  };
  Proxy proxy(ctx, o);
  proxy.start();
  auto a = client();
  auto b = client();
  a->send("LOGI:SP:050:D7#");
  b->send("LOGI:SP:050:D7#");
  ex.run_for(milliseconds(10));
  EXPECT_EQ(a->received, "LOGI:SP:050:D7#");
  EXPECT_EQ(b->received, "");
  EXPECT_EQ(asked, (std::vector<std::size_t>{1, 2}));

  drop_on_every_link = true;
  proxy.refresh_faults();
  a->send("LOGI:SP:050:D7#");
  ex.run_for(milliseconds(10));
  EXPECT_EQ(a->received, "LOGI:SP:050:D7#");  // nothing more
  EXPECT_EQ(asked.size(), 4u);
}

TEST_F(ProxyRoutesTest, StallLinkHoldsThatLinkForExactlyItsDuration) {
  Proxy proxy(ctx, options());
  proxy.start();
  auto a = client();
  auto b = client();
  ex.run_until(Time{seconds(1)});
  ASSERT_TRUE(proxy.stall_link(1, seconds(2), DirectionFilter::to_client));
  EXPECT_FALSE(proxy.stall_link(3, seconds(2), DirectionFilter::both));
  ex.run_until(Time{milliseconds(1500)});
  a->send("LOGI:SP:050:D7#");
  b->send("LOGI:SP:050:D7#");
  ex.run_until(Time{milliseconds(2999)});
  EXPECT_EQ(a->received, "");
  EXPECT_EQ(b->received, "LOGI:SP:050:D7#");
  EXPECT_EQ(b->arrivals, (std::vector<Time>{milliseconds(1500)}));
  ex.run_until(Time{seconds(4)});
  EXPECT_EQ(a->received, "LOGI:SP:050:D7#");
  EXPECT_EQ(a->arrivals, (std::vector<Time>{seconds(3)}));
  // The car's side was not stalled: it had the bytes at 1.5 s.
  EXPECT_EQ(proxy.links()[0].stats.bytes_delivered[0], 15u);
  EXPECT_EQ(proxy.links()[0].faults[static_cast<std::size_t>(FaultKind::stall)], 1u);

  // A second stall later on the same link holds it again.
  ASSERT_TRUE(proxy.stall_link(1, milliseconds(500), DirectionFilter::both));
  a->send("LOGI:SP:050:D7#");
  ex.run_until(Time{seconds(5)});
  ASSERT_EQ(a->arrivals.size(), 2u);
  EXPECT_EQ(a->arrivals[1], milliseconds(4500));
}

TEST_F(ProxyRoutesTest, ResetLinkResetsOnlyThatLink) {
  Proxy proxy(ctx, options());
  proxy.start();
  auto a = client();
  auto b = client();
  ASSERT_TRUE(proxy.reset_link(1));
  ex.run_for(milliseconds(10));
  ASSERT_TRUE(a->closed.has_value());
  EXPECT_EQ(*a->closed, std::errc::connection_reset);
  EXPECT_FALSE(b->closed.has_value());
  b->send("LOGI:SP:050:D7#");
  ex.run_for(milliseconds(10));
  EXPECT_EQ(b->received, "LOGI:SP:050:D7#");
  EXPECT_FALSE(proxy.reset_link(1));  // closed now
  EXPECT_EQ(proxy.open_links(), 1u);
}

TEST_F(ProxyRoutesTest, DisablingClosesEveryLinkAndRefusesClientsUntilEnabled) {
  Proxy proxy(ctx, options());
  proxy.start();
  auto a = client();
  auto b = client();
  proxy.set_enabled(false);
  EXPECT_FALSE(proxy.enabled());
  ex.run_for(milliseconds(10));
  EXPECT_EQ(a->closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_EQ(b->closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_EQ(proxy.open_links(), 0u);

  auto refused = client();
  EXPECT_EQ(refused->connect_error, std::errc::connection_refused);
  EXPECT_EQ(proxy.address(), "mem://proxy");

  proxy.set_enabled(true);
  EXPECT_TRUE(proxy.enabled());
  auto c = client();
  ASSERT_FALSE(c->connect_error);
  c->send("LOGI:SP:050:D7#");
  ex.run_for(milliseconds(10));
  EXPECT_EQ(c->received, "LOGI:SP:050:D7#");
  EXPECT_EQ(proxy.links().front().number, 3u);  // numbering carries on
  EXPECT_EQ(proxy.counters().connections, 3u);
}

TEST_F(ProxyRoutesTest, ADisabledProxyStartsWithoutListening) {
  Proxy proxy(ctx, options());
  proxy.set_enabled(false);
  proxy.start();
  auto a = client();
  EXPECT_EQ(a->connect_error, std::errc::connection_refused);
  proxy.set_enabled(true);
  auto b = client();
  EXPECT_FALSE(b->connect_error);
  EXPECT_EQ(proxy.open_links(), 1u);
}

TEST_F(ProxyRoutesTest, KeepsOnlyTheNewestClosedLinks) {
  auto o = options();
  o.closed_links_kept = 2;
  o.recent_frames = 3;
  Proxy proxy(ctx, o);
  proxy.start();
  for (int i = 0; i < 5; ++i) {
    auto c = client();
    c->send("LOGI:SP:050:D7#");
    ex.run_for(milliseconds(1));
    c->pipe->close();
    ex.run_for(milliseconds(1));
  }
  const auto links = proxy.links();
  ASSERT_EQ(links.size(), 2u);
  EXPECT_EQ(links[0].number, 4u);
  EXPECT_EQ(links[1].number, 5u);
  EXPECT_EQ(proxy.recent_frames(100).size(), 3u);
  EXPECT_EQ(proxy.recent_frames(100).back().link, 5u);
  EXPECT_EQ(proxy.counters().frames[0], 5u);
}

}  // namespace
}  // namespace hil::link
