// The proxy over real transports: TCP to TCP and pty to TCP, with faults and
// capture. Each test runs the io_context with a deadline, so none can hang.

#include <gtest/gtest.h>
#include <unistd.h>

#include <asio/io_context.hpp>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "link/asio_executor.hpp"
#include "link/capture/wire_log.hpp"
#include "link/faults/profile_yaml.hpp"
#include "link/proxy.hpp"
#include "link/transport.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;

// An upstream "car" that answers every byte it gets by echoing it.
struct EchoCar {
  std::unique_ptr<Listener> listener;
  std::vector<BytePipePtr> pipes;
  std::string received;

  explicit EchoCar(TransportContext& ctx) {
    listener = listen(ctx, parse_endpoint("tcp://127.0.0.1:0"));
    listener->start([this](BytePipePtr p) {
      pipes.push_back(p);
      std::weak_ptr<BytePipe> weak = p;
      p->start({[this, weak](ByteView b) {
                  received.append(b.begin(), b.end());
                  if (auto self = weak.lock()) self->write(b);
                },
                [](std::error_code) {}});
    });
  }
};

// A client of the proxy, collecting what comes back.
struct Client {
  BytePipePtr pipe;
  std::string received;
  std::optional<std::error_code> closed;
  bool connected = false;
  std::error_code connect_error;

  void connect_to(TransportContext& ctx, const std::string& uri,
                  const std::string& first_write = {}) {
    connect(ctx, parse_endpoint(uri), [this, first_write](std::error_code ec, BytePipePtr p) {
      connect_error = ec;
      if (ec) return;
      connected = true;
      pipe = p;
      p->start({[this](ByteView b) { received.append(b.begin(), b.end()); },
                [this](std::error_code e) { closed = e; }});
      if (!first_write.empty()) p->write(to_bytes(first_write));
    });
  }
};

class ProxyTest : public ::testing::Test {
 protected:
  asio::io_context io;
  AsioExecutor executor{io};
  TransportContext ctx{executor, &io};

  // Runs the io_context until `done` holds or 5 s pass.
  bool run_until(const std::function<bool()>& done) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (!done() && std::chrono::steady_clock::now() < deadline) {
      io.run_for(std::chrono::milliseconds(5));
      io.restart();
    }
    return done();
  }
  // For bulk transfers, whose time depends on the build (a sanitizer tree
  // moves bytes several times slower): waits while `count` keeps growing
  // and gives up only after five seconds without progress.
  bool run_while_progressing(const std::function<std::size_t()>& count, std::size_t target) {
    std::size_t seen = count();
    auto stalled_since = std::chrono::steady_clock::now();
    while (count() < target &&
           std::chrono::steady_clock::now() - stalled_since < std::chrono::seconds(5)) {
      io.run_for(std::chrono::milliseconds(5));
      io.restart();
      if (count() != seen) {
        seen = count();
        stalled_since = std::chrono::steady_clock::now();
      }
    }
    return count() >= target;
  }
  void settle(std::chrono::milliseconds d) {
    const auto until = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < until) {
      io.run_for(std::chrono::milliseconds(5));
      io.restart();
    }
  }

  ProxyOptions options(const EchoCar& car, const std::string& faults_yaml = "rules: []") {
    ProxyOptions o;
    o.listen = parse_endpoint("tcp://127.0.0.1:0");
    o.upstream = parse_endpoint(car.listener->address());
    o.protocol = protocol_adapter("logi");
    o.faults = parse_fault_profile_text(faults_yaml, "test");
    o.seed = 7;
    return o;
  }
};

TEST_F(ProxyTest, TcpToTcpCarriesBothDirections) {
  EchoCar car(ctx);
  Proxy proxy(ctx, options(car));
  proxy.start();
  Client client;
  client.connect_to(ctx, proxy.address(), "LOGI:SP:050:D7#LOGI:MV:FWD:23#");
  ASSERT_TRUE(run_until([&] { return client.received.size() == 30; })) << client.received;
  EXPECT_EQ(car.received, "LOGI:SP:050:D7#LOGI:MV:FWD:23#");
  EXPECT_EQ(client.received, "LOGI:SP:050:D7#LOGI:MV:FWD:23#");
  EXPECT_EQ(proxy.links_opened(), 1u);
  EXPECT_EQ(proxy.open_links(), 1u);
}

// A client that writes far faster than the car reads: the proxy holds the
// client back (it stops reading it) instead of queueing for the car until
// the send limit drops the car, and every byte arrives, in order.
TEST_F(ProxyTest, AFastClientIsHeldBackForASlowCarAndNothingIsLostOrDropped) {
  // The car reads nothing for half a second, then everything.
  std::unique_ptr<Listener> car = listen(ctx, parse_endpoint("tcp://127.0.0.1:0"));
  BytePipePtr car_pipe;
  std::string at_car;
  car->start([&](BytePipePtr p) {
    car_pipe = p;
    p->pause_reading();
    p->start({[&](ByteView b) { at_car.append(b.begin(), b.end()); }, [](std::error_code) {}});
  });
  ProxyOptions o;
  o.listen = parse_endpoint("tcp://127.0.0.1:0");
  o.upstream = parse_endpoint(car->address());
  o.protocol = protocol_adapter("raw");
  std::vector<std::string> log;
  o.log = [&](const std::string& line) { log.push_back(line); };
  Proxy proxy(ctx, o);
  proxy.start();

  // 64 MiB: more than the kernel's socket buffers on both sides of the
  // proxy take, and 64 times the send limit that would drop the car.
  std::string sent(64 << 20, '\0');
  for (std::size_t i = 0; i < sent.size(); ++i)
    sent[i] = static_cast<char>(i % 251);
  Client client;
  client.connect_to(ctx, proxy.address());
  ASSERT_TRUE(run_until([&] { return client.connected && car_pipe != nullptr; }));
  client.pipe->write(to_bytes(sent));
  settle(std::chrono::milliseconds(500));
  EXPECT_TRUE(at_car.empty());
  EXPECT_EQ(proxy.open_links(), 1u);
  EXPECT_FALSE(client.closed.has_value());

  car_pipe->resume_reading();
  ASSERT_TRUE(run_while_progressing([&] { return at_car.size(); }, sent.size()))
      << at_car.size() << " of " << sent.size()
      << " bytes reached the car, then five seconds of nothing";
  EXPECT_TRUE(at_car == sent) << "the bytes arrived changed or out of order";
  EXPECT_EQ(proxy.open_links(), 1u);
  EXPECT_FALSE(client.closed.has_value());
  for (const auto& line : log)
    EXPECT_EQ(line.find("dropped"), std::string::npos) << line;
}

TEST_F(ProxyTest, FaultRulesActOnFramesOfTheNamedKind) {
  EchoCar car(ctx);
  Proxy proxy(ctx, options(car, R"(
rules:
  - kind: drop
    direction: to_car
    match: "SP"
    first: 1
)"));
  proxy.start();
  Client client;
  client.connect_to(ctx, proxy.address(), "LOGI:SP:050:D7#LOGI:MV:FWD:23#");
  ASSERT_TRUE(run_until([&] { return client.received.size() >= 15; }));
  settle(std::chrono::milliseconds(50));
  EXPECT_EQ(car.received, "LOGI:MV:FWD:23#");
  EXPECT_EQ(client.received, "LOGI:MV:FWD:23#");
}

TEST_F(ProxyTest, RefuseRuleTurnsClientsAway) {
  EchoCar car(ctx);
  Proxy proxy(ctx, options(car, R"(
rules:
  - kind: refuse
    at: 0s
    for: 60s
)"));
  proxy.start();
  Client client;
  client.connect_to(ctx, proxy.address());
  ASSERT_TRUE(
      run_until([&] { return client.closed.has_value() || (client.connect_error && true); }));
  EXPECT_EQ(proxy.connections_refused(), 1u);
  EXPECT_EQ(proxy.links_opened(), 0u);
  EXPECT_TRUE(car.pipes.empty());
}

TEST_F(ProxyTest, UnreachableCarClosesTheClient) {
  ProxyOptions o;
  o.listen = parse_endpoint("tcp://127.0.0.1:0");
  {
    // A port that was free a moment ago: nothing listens there now.
    auto probe = listen(ctx, parse_endpoint("tcp://127.0.0.1:0"));
    o.upstream = parse_endpoint(probe->address());
    probe->close();
  }
  std::vector<std::string> lines;
  o.log = [&](const std::string& line) { lines.push_back(line); };
  Proxy proxy(ctx, o);
  proxy.start();
  Client client;
  client.connect_to(ctx, proxy.address());
  ASSERT_TRUE(run_until([&] { return client.closed.has_value(); }));
  bool said = false;
  for (const auto& l : lines)
    said = said || l.find("cannot reach the car") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST_F(ProxyTest, WireLogRecordsEveryLink) {
  EchoCar car(ctx);
  auto o = options(car);
  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-proxy-test-" + std::to_string(::getpid()) + ".ndjson");
  std::filesystem::remove(path);
  o.wire_log_path = path.string();
  {
    Proxy proxy(ctx, o);
    proxy.start();
    Client a, b;
    a.connect_to(ctx, proxy.address(), "LOGI:SP:050:D7#");
    b.connect_to(ctx, proxy.address(), "LOGI:MV:CW:DC#");
    ASSERT_TRUE(run_until([&] { return a.received.size() == 15 && b.received.size() == 14; }));
    proxy.close();
    settle(std::chrono::milliseconds(20));
  }
  const auto records = read_wire_log(path);
  std::set<std::string> links;
  std::size_t delivered = 0;
  for (const auto& r : records) {
    links.insert(r["link"].get<std::string>());
    if (r["event"] == "delivered") delivered += r["bytes"].get<std::size_t>();
  }
  EXPECT_EQ(links, (std::set<std::string>{"link1", "link2"}));
  EXPECT_EQ(delivered, 2u * (15 + 14));  // each frame there and back
  std::filesystem::remove(path);
}

// Toxiproxy's enabled flag over TCP: a proxy asked for port 0 listens on
// the port it first got when enabled again, so clients find it there.
TEST_F(ProxyTest, EnablingAgainListensOnTheSamePort) {
  EchoCar car(ctx);
  Proxy proxy(ctx, options(car));
  proxy.start();
  const std::string address = proxy.address();
  Client first;
  first.connect_to(ctx, address, "LOGI:SP:050:D7#");
  ASSERT_TRUE(run_until([&] { return first.received.size() == 15; }));

  proxy.set_enabled(false);
  ASSERT_TRUE(run_until([&] { return first.closed.has_value(); }));
  Client refused;
  refused.connect_to(ctx, address);
  ASSERT_TRUE(run_until([&] { return refused.connect_error || refused.closed.has_value(); }));
  EXPECT_FALSE(refused.connected) << "a disabled proxy accepted a client";

  proxy.set_enabled(true);
  EXPECT_EQ(proxy.address(), address);
  Client again;
  again.connect_to(ctx, address, "LOGI:MV:CW:DC#");
  ASSERT_TRUE(run_until([&] { return again.received.size() == 14; })) << again.received;
  EXPECT_EQ(proxy.links_opened(), 2u);
}

// Several proxies sharing one wire log tell their links apart by prefix,
// and a pcap folder gets one file per link, named after the proxy.
TEST_F(ProxyTest, LinkIdPrefixAndPcapFolder) {
  EchoCar car(ctx);
  auto o = options(car);
  const auto dir = std::filesystem::temp_directory_path() /
                   ("hil-proxy-test-pcaps-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  o.name = "car";
  o.link_id_prefix = "car/";
  o.wire_log_path = (dir / "wire.ndjson").string();
  o.pcap_dir = dir.string();
  {
    Proxy proxy(ctx, o);
    proxy.start();
    Client a, b;
    a.connect_to(ctx, proxy.address(), "LOGI:SP:050:D7#");
    ASSERT_TRUE(run_until([&] { return a.received.size() == 15; }));
    b.connect_to(ctx, proxy.address(), "LOGI:SP:050:D7#");
    ASSERT_TRUE(run_until([&] { return b.received.size() == 15; }));
    proxy.close();
    settle(std::chrono::milliseconds(20));
  }
  std::set<std::string> links;
  for (const auto& r : read_wire_log(dir / "wire.ndjson"))
    links.insert(r["link"].get<std::string>());
  EXPECT_EQ(links, (std::set<std::string>{"car/link1", "car/link2"}));
  EXPECT_GT(std::filesystem::file_size(dir / "car-link1.pcap"), 24u);
  EXPECT_GT(std::filesystem::file_size(dir / "car-link2.pcap"), 24u);
  std::filesystem::remove_all(dir);
}

TEST_F(ProxyTest, PtyClientReachesATcpCar) {
  EchoCar car(ctx);
  auto o = options(car);
  const std::string path = "/tmp/hil-proxy-test-pty-" + std::to_string(::getpid());
  o.listen = parse_endpoint("pty://" + path);
  Proxy proxy(ctx, o);
  proxy.start();
  Client client;
  client.connect_to(ctx, "pty://" + path, "LOGI:GS:002:CB#");
  ASSERT_TRUE(run_until([&] { return client.received.size() == 15; })) << client.received;
  EXPECT_EQ(car.received, "LOGI:GS:002:CB#");
  proxy.close();
  settle(std::chrono::milliseconds(20));
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace hil::link
