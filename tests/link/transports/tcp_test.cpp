#include "link/tcp.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "link/asio_executor.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace {

const TcpEndpoint any_port{"127.0.0.1", 0};

/// Everything one end of a connection saw.
struct Seen {
  Bytes data;
  std::optional<std::error_code> closed;
  int close_calls = 0;
  int ends = 0;  // on_end calls
  std::size_t bytes_at_end = 0;

  /// With `half_close`, the peer's FIN is on_end (the pipe stays open).
  BytePipe::Handlers handlers(bool half_close = false) {
    BytePipe::Handlers h{[this](ByteView b) { data.insert(data.end(), b.begin(), b.end()); },
                         [this](std::error_code ec) {
                           closed = ec;
                           ++close_calls;
                         }};
    if (half_close) {
      h.on_end = [this] {
        ++ends;
        bytes_at_end = data.size();
      };
    }
    return h;
  }
  std::string text() const { return {data.begin(), data.end()}; }
};

/// A listener on 127.0.0.1 with a free port, and one connected client.
struct Connected {
  explicit Connected(bool echo = false, bool half_close = false) : listener(io, any_port) {
    listener.start([this, echo, half_close](BytePipePtr p) {
      servers.push_back(p);
      auto handlers = server_seen.handlers(half_close);
      if (echo) {
        auto keep = handlers.on_data;
        handlers.on_data = [keep, raw = p.get()](ByteView b) {
          keep(b);
          raw->write(b);
        };
      }
      p->start(std::move(handlers));
    });
    tcp_connect(io, TcpEndpoint{"127.0.0.1", listener.port()},
                [this, half_close](std::error_code ec, BytePipePtr p) {
                  connect_error = ec;
                  client = p;
                  if (p) p->start(client_seen.handlers(half_close));
                });
    EXPECT_TRUE(test::run_until(io, [&] { return client && !servers.empty(); }));
  }

  BytePipe& server() { return *servers.at(0); }

  asio::io_context io;
  TcpListener listener;
  std::vector<BytePipePtr> servers;
  BytePipePtr client;
  std::error_code connect_error;
  Seen server_seen;
  Seen client_seen;
};

TEST(Tcp, PortZeroPicksAFreePortThatAddressReports) {
  asio::io_context io;
  TcpListener listener(io, any_port);
  EXPECT_NE(listener.port(), 0);
  EXPECT_EQ(listener.address(), "tcp://127.0.0.1:" + std::to_string(listener.port()));
}

TEST(Tcp, EchoRoundTripOverLoopback) {
  Connected c(true);
  ASSERT_TRUE(c.client);
  c.client->write(protocol::to_bytes("LOGI:SP:050:D7#"));
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.client_seen.data.size() == 15; }));
  EXPECT_EQ(c.client_seen.text(), "LOGI:SP:050:D7#");
  EXPECT_EQ(c.server_seen.text(), "LOGI:SP:050:D7#");
  EXPECT_NE(c.client->describe().find("-> 127.0.0.1:" + std::to_string(c.listener.port())),
            std::string::npos);
  EXPECT_NE(
      c.server().describe().find("tcp 127.0.0.1:" + std::to_string(c.listener.port()) + " <- "),
      std::string::npos);
}

TEST(Tcp, ManySmallWritesArriveInOrder) {
  Connected c(true);
  std::string expected;
  for (int i = 0; i < 5000; ++i) {
    const std::string line = std::to_string(i) + "\n";
    expected += line;
    c.client->write(protocol::to_bytes(line));
  }
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.client_seen.data.size() >= expected.size(); }));
  EXPECT_EQ(c.server_seen.text(), expected);
  EXPECT_EQ(c.client_seen.text(), expected);
}

TEST(Tcp, EightMebibytesArriveIntact) {
  Connected c;
  const unsigned seed = std::random_device{}();
  std::printf("seed %u\n", seed);
  std::mt19937 rng(seed);
  Bytes sent(8u << 20);
  for (auto& b : sent)
    b = static_cast<std::uint8_t>(rng());
  for (std::size_t at = 0; at < sent.size(); at += 65536)
    c.client->write(ByteView(sent).subspan(at, 65536));
  // Nothing has run yet: all of it is queued, none of it lost.
  EXPECT_EQ(c.client->queued_bytes(), sent.size());
  ASSERT_TRUE(test::run_until(
      c.io, [&] { return c.server_seen.data.size() >= sent.size(); }, seconds(30)));
  EXPECT_TRUE(c.server_seen.data == sent) << "seed " << seed;
  EXPECT_EQ(c.client->queued_bytes(), 0u);
}

TEST(Tcp, PeerCloseGivesEofAfterTheLastBytes) {
  Connected c;
  c.server().write(protocol::to_bytes("bye"));
  c.server().close(CloseMode::graceful);
  EXPECT_FALSE(c.server().is_open());
  EXPECT_EQ(c.server_seen.close_calls, 0);  // never from inside close()
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.client_seen.closed && c.server_seen.closed; }));
  EXPECT_EQ(c.client_seen.text(), "bye");
  EXPECT_EQ(*c.client_seen.closed, end_of_stream());
  EXPECT_EQ(*c.server_seen.closed, std::errc::operation_canceled);
  EXPECT_FALSE(c.client->is_open());
  test::run_for(c.io, milliseconds(20));
  EXPECT_EQ(c.client_seen.close_calls, 1);
  EXPECT_EQ(c.server_seen.close_calls, 1);
}

TEST(Tcp, GracefulCloseFlushesEverythingQueued) {
  Connected c;
  Bytes big(4u << 20, 0x5A);
  c.server().write(big);
  c.server().close();
  c.server().write(protocol::to_bytes("ignored after close"));
  ASSERT_TRUE(test::run_until(
      c.io, [&] { return c.client_seen.closed.has_value(); }, seconds(30)));
  EXPECT_EQ(c.client_seen.data.size(), big.size());
  EXPECT_EQ(*c.client_seen.closed, end_of_stream());
}

TEST(Tcp, ResetCloseMakesThePeerSeeAConnectionReset) {
  Connected c;
  c.server().write(Bytes(1000, 1));
  c.server().close(CloseMode::reset);
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.client_seen.closed.has_value(); }));
  EXPECT_EQ(*c.client_seen.closed, std::errc::connection_reset);
  EXPECT_EQ(c.server().queued_bytes(), 0u);
}

TEST(Tcp, ClientCloseIsSeenByTheServerAsEof) {
  Connected c;
  c.client->write(protocol::to_bytes("last words"));
  c.client->close();
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.server_seen.closed.has_value(); }));
  EXPECT_EQ(c.server_seen.text(), "last words");
  EXPECT_EQ(*c.server_seen.closed, end_of_stream());
}

TEST(Tcp, AHalfCloseLetsThePeerAnswerThenBothEndsClose) {
  Connected c(false, true);
  c.client->write(protocol::to_bytes("request"));
  c.client->shutdown_send();
  c.client->write(protocol::to_bytes("ignored after shutdown_send"));
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.server_seen.ends == 1; }));
  EXPECT_EQ(c.server_seen.text(), "request");
  EXPECT_EQ(c.server_seen.bytes_at_end, 7u);
  EXPECT_TRUE(c.client->is_open()) << "the client still reads";
  EXPECT_TRUE(c.server().is_open()) << "the server still writes";

  // An answer larger than the socket buffers: it all arrives after the
  // client's FIN, and the server's FIN after it.
  Bytes answer(3u << 20);
  for (std::size_t i = 0; i < answer.size(); ++i)
    answer[i] = static_cast<std::uint8_t>(i * 13);
  c.server().write(answer);
  c.server().shutdown_send();
  ASSERT_TRUE(test::run_until(
      c.io, [&] { return c.client_seen.closed && c.server_seen.closed; }, seconds(30)));
  EXPECT_TRUE(c.client_seen.data == answer);
  EXPECT_EQ(c.client_seen.ends, 1);
  EXPECT_EQ(c.client_seen.bytes_at_end, answer.size());
  EXPECT_EQ(*c.client_seen.closed, end_of_stream());
  EXPECT_EQ(*c.server_seen.closed, end_of_stream());
  EXPECT_EQ(c.server_seen.text(), "request");
  EXPECT_FALSE(c.client->is_open());
  EXPECT_FALSE(c.server().is_open());
  test::run_for(c.io, milliseconds(20));
  EXPECT_EQ(c.client_seen.close_calls, 1);
  EXPECT_EQ(c.server_seen.close_calls, 1);
}

TEST(Tcp, AClosedPeerThatTakesNoHalfCloseSeesEofAsBefore) {
  Connected c(false, false);
  c.client->write(protocol::to_bytes("request"));
  c.client->shutdown_send();
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.server_seen.closed.has_value(); }));
  EXPECT_EQ(c.server_seen.text(), "request");
  EXPECT_EQ(*c.server_seen.closed, end_of_stream());
  EXPECT_EQ(c.server_seen.ends, 0);
  // The server pipe closed in turn (FIN): the client, which still read,
  // sees the end of the stream.
  ASSERT_TRUE(test::run_until(c.io, [&] { return c.client_seen.closed.has_value(); }));
  EXPECT_EQ(*c.client_seen.closed, end_of_stream());
}

TEST(Tcp, ConnectToAClosedPortIsRefused) {
  asio::io_context io;
  std::uint16_t port = 0;
  {
    TcpListener probe(io, any_port);
    port = probe.port();
  }
  std::optional<std::error_code> result;
  BytePipePtr pipe;
  tcp_connect(io, TcpEndpoint{"127.0.0.1", port}, [&](std::error_code ec, BytePipePtr p) {
    result = ec;
    pipe = p;
  });
  ASSERT_TRUE(test::run_until(io, [&] { return result.has_value(); }));
  EXPECT_EQ(*result, std::errc::connection_refused);
  EXPECT_EQ(pipe, nullptr);
}

TEST(Tcp, ListeningOnAPortInUseThrowsWithTheAddress) {
  asio::io_context io;
  TcpListener first(io, any_port);
  const std::string port = std::to_string(first.port());
  try {
    TcpListener second(io, TcpEndpoint{"127.0.0.1", first.port()});
    FAIL() << "a second listener on the same port was allowed";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code(), std::errc::address_in_use);
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + port), std::string::npos) << e.what();
  }
}

TEST(Tcp, ListenerAcceptsManyConnections) {
  asio::io_context io;
  TcpListener listener(io, any_port);
  std::vector<BytePipePtr> accepted;
  std::vector<BytePipePtr> clients;
  listener.start([&](BytePipePtr p) { accepted.push_back(p); });
  for (int i = 0; i < 5; ++i) {
    tcp_connect(io, TcpEndpoint{"127.0.0.1", listener.port()},
                [&](std::error_code, BytePipePtr p) { clients.push_back(p); });
  }
  ASSERT_TRUE(test::run_until(io, [&] { return accepted.size() == 5 && clients.size() == 5; }));
  for (const auto& p : clients)
    EXPECT_NE(p, nullptr);
}

TEST(Tcp, ClosedListenerStopsAcceptingButKeepsConnections) {
  Connected c(true);
  const std::uint16_t port = c.listener.port();
  c.listener.close();
  std::optional<std::error_code> second;
  tcp_connect(c.io, TcpEndpoint{"127.0.0.1", port},
              [&](std::error_code ec, BytePipePtr) { second = ec; });
  c.client->write(protocol::to_bytes("still here"));
  ASSERT_TRUE(
      test::run_until(c.io, [&] { return second.has_value() && c.client_seen.data.size() == 10; }));
  EXPECT_TRUE(*second);
  EXPECT_EQ(c.client_seen.text(), "still here");
}

}  // namespace
}  // namespace hil::link
