// The RFC 2217 listener: in virtual time over mem:// connections (exact
// timings), and once over real TCP by URI.

#include "link/rfc2217_listener.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>

#include <asio/io_context.hpp>

#include "link/asio_executor.hpp"
#include "link/mem_pipe.hpp"
#include "link/transport.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace rfc2217_listener_test {
namespace {

using ::testing::HasSubstr;

constexpr std::uint8_t IAC = 255, SB = 250, SE = 240, WILL = 251;

/// IAC SB 44 <command> <value> IAC SE (no 0xFF in the values used here).
Bytes command(std::uint8_t code, Bytes value = {}) {
  Bytes out = {IAC, SB, 44, code};
  out.insert(out.end(), value.begin(), value.end());
  out.push_back(IAC);
  out.push_back(SE);
  return out;
}

Bytes set_baud(std::uint32_t baud) {
  return command(1, {static_cast<std::uint8_t>(baud >> 24), static_cast<std::uint8_t>(baud >> 16),
                     static_cast<std::uint8_t>(baud >> 8), static_cast<std::uint8_t>(baud)});
}

bool contains(const Bytes& haystack, const Bytes& needle) {
  return std::search(haystack.begin(), haystack.end(), needle.begin(), needle.end()) !=
         haystack.end();
}

/// What one end of a pipe got, and when its last byte came.
struct Recorder {
  Executor* ex = nullptr;
  Bytes got;
  Time last{0};
  std::optional<std::error_code> closed;
  BytePipe::Handlers handlers() {
    return {[this](ByteView b) {
              got.insert(got.end(), b.begin(), b.end());
              last = ex->now();
            },
            [this](std::error_code ec) { closed = ec; }};
  }
};

/// A car behind an rfc2217 listener on mem://car, and its clients.
struct Bench {
  explicit Bench(unsigned baud = 9600, Duration reset = Duration{0}) {
    listener = std::make_unique<Rfc2217Listener>(
        ex, net.listen("car"),
        Rfc2217Options{baud, reset, [this](const std::string& line) { log += line + "\n"; }});
    listener->start([this](BytePipePtr p) {
      sessions.push_back(p);
      cars.push_back(std::make_unique<Recorder>());
      cars.back()->ex = &ex;
      p->start(cars.back()->handlers());
    });
  }

  /// A new client connection, started; its recorder.
  Recorder& connect() {
    clients_seen.push_back(std::make_unique<Recorder>());
    Recorder& r = *clients_seen.back();
    r.ex = &ex;
    net.connect("car", [this, &r](std::error_code ec, BytePipePtr p) {
      ASSERT_FALSE(ec);
      clients.push_back(p);
      p->start(r.handlers());
    });
    ex.run_until_idle();
    return r;
  }

  Recorder& car(std::size_t i = 0) { return *cars.at(i); }

  VirtualExecutor ex;
  MemNetwork net{ex};
  std::string log;
  std::unique_ptr<Rfc2217Listener> listener;
  std::vector<BytePipePtr> sessions;
  std::vector<std::unique_ptr<Recorder>> cars;
  std::vector<BytePipePtr> clients;
  std::vector<std::unique_ptr<Recorder>> clients_seen;
};

TEST(Rfc2217Listener, TheCarGetsOnlyDataPacedAtTheCarsRate) {
  Bench bench(9600);
  bench.connect();
  const Time start = bench.ex.now();
  Bytes data(1000, 'x');
  data[500] = IAC;
  Bytes wire = command(5, {8});  // DTR on: a command, not data
  for (const auto byte : data) {
    wire.push_back(byte);
    if (byte == IAC) wire.push_back(IAC);
  }
  bench.clients[0]->write(wire);
  bench.ex.run_until_idle();
  EXPECT_EQ(bench.car().got, data);
  // 1,000 bytes of 10 bits at 9600 baud: the last one's stop bit ends at
  // 1.041666667 s.
  EXPECT_EQ(bench.car().last - start, Duration(1'041'666'667));
  EXPECT_EQ(bench.log, "");
}

TEST(Rfc2217Listener, TheClientsRateAndFramingPaceTheLineAndAMismatchIsLogged) {
  Bench bench(9600);
  bench.connect();
  bench.clients[0]->write(set_baud(19200));
  bench.ex.run_until_idle();
  const Time start = bench.ex.now();
  bench.clients[0]->write(Bytes(1000, 'y'));
  bench.ex.run_until_idle();
  EXPECT_EQ(bench.car().got.size(), 1000u);
  // 10 bits at 19200 baud: 520.83 ms, released on the pacer's 1 ms ticks.
  EXPECT_GE(bench.car().last - start, Duration(520'833'334));
  EXPECT_LE(bench.car().last - start, Duration(521'833'334));
  EXPECT_THAT(bench.log, HasSubstr("the client set 19200 baud 8N1 but the car's line runs at "
                                   "9600 baud 8N1 (a real board would garble every byte)"));
  // Back to 9600 but with even parity: 11 bits a character.
  bench.clients[0]->write(set_baud(9600));
  bench.clients[0]->write(command(3, {3}));
  bench.ex.run_until_idle();
  EXPECT_THAT(bench.log, HasSubstr("the client set 9600 baud 8E1"));
  const Time again = bench.ex.now();
  bench.clients[0]->write(Bytes(1000, 'z'));
  bench.ex.run_until_idle();
  const double seconds = std::chrono::duration<double>(bench.car().last - again).count();
  EXPECT_NEAR(seconds, 1000 * 11 / 9600.0, 0.0002);
  bench.clients[0]->write(command(3, {1}));
  bench.ex.run_until_idle();
  EXPECT_THAT(bench.log, HasSubstr("matches the car's again (9600 baud 8N1)"));
}

TEST(Rfc2217Listener, TheCarsBytesArePacedToTheClientWithIacDoubled) {
  Bench bench(9600);
  Recorder& client = bench.connect();
  bench.ex.run_until_idle();
  client.got.clear();
  const Time start = bench.ex.now();
  Bytes frame(96, 'a');
  frame[10] = 0xFF;
  bench.sessions[0]->write(frame);
  bench.ex.run_for(milliseconds(50));
  EXPECT_LT(client.got.size(), 60u);  // half of it after half the time
  bench.ex.run_until_idle();
  Bytes expected = frame;
  expected.insert(expected.begin() + 10, 0xFF);
  EXPECT_EQ(client.got, expected);
  EXPECT_EQ(client.last - start, Duration(100'000'000));  // 96 bytes at 9600 baud
}

TEST(Rfc2217Listener, BytesQueuedBeforeARateChangeFinishAtTheOldRate) {
  Bench bench(9600);
  Recorder& client = bench.connect();
  client.got.clear();
  const Time start = bench.ex.now();
  bench.sessions[0]->write(Bytes(48, 'a'));  // 50 ms at 9600 baud
  bench.ex.run_for(milliseconds(10));
  bench.clients[0]->write(set_baud(19200));
  bench.ex.run_for(milliseconds(10));
  bench.sessions[0]->write(Bytes(48, 'b'));          // 25 ms at 19200 baud, after the a's
  bench.ex.run_until(start + microseconds(50'400));  // a b takes 521 us
  EXPECT_EQ(std::count(client.got.begin(), client.got.end(), 'a'), 48);
  EXPECT_EQ(std::count(client.got.begin(), client.got.end(), 'b'), 0);
  bench.ex.run_until_idle();
  EXPECT_EQ(std::count(client.got.begin(), client.got.end(), 'b'), 48);
  EXPECT_GE(client.last - start, milliseconds(75));
  EXPECT_LE(client.last - start, milliseconds(77));
  // The SET-BAUDRATE answer went at once, ahead of the paced bytes.
  const Bytes answer = command(101, {0x00, 0x00, 0x4B, 0x00});
  const auto at = std::search(client.got.begin(), client.got.end(), answer.begin(), answer.end());
  ASSERT_NE(at, client.got.end());
  EXPECT_LT(std::count(client.got.begin(), at, 'a'), 48);
}

TEST(Rfc2217Listener, AReopenIsANewSessionAndTheResetWindowCountsFromIt) {
  Bench bench(9600, milliseconds(200));
  bench.connect();
  bench.clients[0]->write(protocol::to_bytes("lost"));
  bench.ex.run_for(milliseconds(250));
  bench.clients[0]->write(protocol::to_bytes("kept"));
  bench.ex.run_until_idle();
  EXPECT_EQ(protocol::to_string(bench.car(0).got), "kept");
  EXPECT_EQ(bench.listener->bytes_lost_to_reset(), 4u);
  EXPECT_THAT(bench.log, HasSubstr("4 byte(s) lost to reset_on_open"));

  bench.clients[0]->close();
  bench.ex.run_until_idle();
  ASSERT_TRUE(bench.car(0).closed.has_value());
  EXPECT_EQ(*bench.car(0).closed, end_of_stream());

  // The port opens again: a new pipe for the car (the board's reset) and a
  // new window.
  bench.connect();
  ASSERT_EQ(bench.sessions.size(), 2u);
  bench.clients[1]->write(protocol::to_bytes("early"));
  bench.ex.run_for(milliseconds(300));
  bench.clients[1]->write(protocol::to_bytes("late"));
  bench.ex.run_until_idle();
  EXPECT_EQ(protocol::to_string(bench.car(1).got), "late");
  EXPECT_EQ(bench.listener->bytes_lost_to_reset(), 9u);
}

TEST(Rfc2217Listener, AReopenCutsShortWhatTheLastClientLeftOnTheLine) {
  Bench bench(9600);
  bench.connect();
  bench.clients[0]->write(Bytes(1000, 'w'));  // 1.04 s on the line
  bench.clients[0]->close();
  bench.ex.run_for(milliseconds(100));
  EXPECT_FALSE(bench.car(0).closed.has_value());  // still arriving
  bench.connect();
  ASSERT_EQ(bench.sessions.size(), 2u);
  ASSERT_TRUE(bench.car(0).closed.has_value());
  EXPECT_EQ(*bench.car(0).closed, end_of_stream());
  const auto arrived = bench.car(0).got.size();
  EXPECT_GE(arrived, 90u);
  EXPECT_LE(arrived, 100u);
  EXPECT_THAT(bench.log, HasSubstr("the port opened again with"));
  bench.ex.run_until_idle();
  EXPECT_EQ(bench.car(0).got.size(), arrived);
  EXPECT_TRUE(bench.car(1).got.empty());
}

TEST(Rfc2217Listener, ASecondClientIsRefusedWhileTheFirstIsConnected) {
  Bench bench(0);
  bench.connect();
  Recorder& second = bench.connect();
  EXPECT_EQ(bench.sessions.size(), 1u);
  ASSERT_TRUE(second.closed.has_value());
  EXPECT_EQ(bench.listener->connections_refused(), 1u);
  EXPECT_THAT(bench.log, HasSubstr("rfc2217 mem car (server end): refused: the port is in use by "
                                   "rfc2217 mem car (server end) (one client at a time"));
  // The first still talks to the car.
  bench.clients[0]->write(protocol::to_bytes("still here"));
  bench.ex.run_until_idle();
  EXPECT_EQ(protocol::to_string(bench.car().got), "still here");
  // Once it has gone, the next one gets the port.
  bench.clients[0]->close();
  bench.ex.run_until_idle();
  bench.connect();
  EXPECT_EQ(bench.sessions.size(), 2u);
}

TEST(Rfc2217Listener, PurgeDropsWhatTheCarSentAndTheClientHasNotGot) {
  Bench bench(9600);
  Recorder& client = bench.connect();
  client.got.clear();
  bench.sessions[0]->write(Bytes(1000, 'q'));
  bench.ex.run_for(milliseconds(100));
  bench.clients[0]->write(command(12, {1}));
  bench.ex.run_until_idle();
  const auto data_bytes = std::count(client.got.begin(), client.got.end(), 'q');
  EXPECT_GE(data_bytes, 90);
  EXPECT_LE(data_bytes, 100);
  EXPECT_TRUE(contains(client.got, command(112, {1})));
  EXPECT_EQ(bench.sessions[0]->queued_bytes(), 0u);
}

TEST(Rfc2217Listener, FlowControlSuspendHoldsTheCarsBytesUntilResume) {
  Bench bench(0);
  Recorder& client = bench.connect();
  client.got.clear();
  bench.clients[0]->write(command(8));
  bench.ex.run_until_idle();
  bench.sessions[0]->write(protocol::to_bytes("held"));
  bench.ex.run_until_idle();
  EXPECT_TRUE(client.got.empty());
  EXPECT_EQ(bench.sessions[0]->queued_bytes(), 4u);
  bench.clients[0]->write(command(9));
  bench.ex.run_until_idle();
  EXPECT_EQ(protocol::to_string(client.got), "held");
}

TEST(Rfc2217Listener, BadInputIsLoggedWithTheConnectionAndNeverReachesTheCar) {
  Bench bench(0);
  bench.connect();
  bench.clients[0]->write(Bytes{IAC, SB, 44, 1, 0, 0, IAC, WILL, 44});  // truncated
  bench.clients[0]->write(command(1, {0, 0, 0, 0}));                    // a query, not an error
  bench.clients[0]->write(set_baud(5'000'000));
  bench.clients[0]->write(command(77));
  bench.ex.run_until_idle();
  EXPECT_TRUE(bench.car().got.empty());
  EXPECT_THAT(bench.log,
              HasSubstr("rfc2217 mem car (server end): SET-BAUDRATE with 2 value byte(s)"));
  EXPECT_THAT(bench.log, HasSubstr("SET-BAUDRATE 5000000 refused"));
  EXPECT_THAT(bench.log, HasSubstr("unknown COM-PORT-OPTION command 77"));
}

TEST(Rfc2217Listener, TheCarClosingFlushesItsBytesFirst) {
  Bench bench(9600);
  Recorder& client = bench.connect();
  client.got.clear();
  bench.sessions[0]->write(protocol::to_bytes("bye"));
  bench.sessions[0]->close(CloseMode::graceful);
  bench.ex.run_until_idle();
  EXPECT_EQ(protocol::to_string(client.got), "bye");
  ASSERT_TRUE(client.closed.has_value());
  EXPECT_EQ(*client.closed, end_of_stream());
  ASSERT_TRUE(bench.car().closed.has_value());
  EXPECT_EQ(*bench.car().closed, closed_here());
}

TEST(Rfc2217Listener, ByUriOverRealTcp) {
  asio::io_context io;
  AsioExecutor ex(io);
  std::string log;
  TransportContext context{ex, &io};
  context.log = [&](const std::string& line) { log += line + "\n"; };
  auto listener = listen(context, parse_endpoint("rfc2217://127.0.0.1:0?baud=115200"));
  const auto address = std::get<Rfc2217Endpoint>(parse_endpoint(listener->address()));
  EXPECT_EQ(address.host, "127.0.0.1");
  EXPECT_NE(address.port, 0);
  EXPECT_EQ(address.baud, 115200u);
  Bytes car_got;
  BytePipePtr car;
  listener->start([&](BytePipePtr p) {
    car = p;
    p->start({[&](ByteView b) { car_got.insert(car_got.end(), b.begin(), b.end()); }, {}});
  });
  BytePipePtr client;
  Bytes client_got;
  connect(context, TcpEndpoint{"127.0.0.1", address.port}, [&](std::error_code ec, BytePipePtr p) {
    ASSERT_FALSE(ec) << ec.message();
    client = p;
    p->start({[&](ByteView b) { client_got.insert(client_got.end(), b.begin(), b.end()); }, {}});
    Bytes wire = command(0);
    const Bytes data = protocol::to_bytes("over tcp");
    wire.insert(wire.end(), data.begin(), data.end());
    p->write(wire);
  });
  ASSERT_TRUE(test::run_until(io, [&] { return car_got.size() == 8; }));
  EXPECT_EQ(protocol::to_string(car_got), "over tcp");
  ASSERT_TRUE(test::run_until(io, [&] {
    return contains(client_got, command(100, {'h', 'i', 'l'}));
  }));
  // hil has no RFC 2217 client: a connect is refused, as a task.
  std::optional<std::error_code> refused;
  connect(context, parse_endpoint("rfc2217://127.0.0.1:1"), [&](std::error_code ec, BytePipePtr p) {
    refused = ec;
    EXPECT_EQ(p, nullptr);
  });
  EXPECT_FALSE(refused.has_value());
  ASSERT_TRUE(test::run_until(io, [&] { return refused.has_value(); }));
  EXPECT_EQ(*refused, std::errc::protocol_not_supported);
  EXPECT_EQ(log, "");
}

}  // namespace
}  // namespace rfc2217_listener_test
}  // namespace hil::link
