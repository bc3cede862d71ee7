// The Arduino client session against the Arduino robot on mem:// in
// virtual time, on both boards (the behavioural mock and hil's test sketch
// on the emulated ATmega328P, tests/client/arduino_board.hpp): every
// helper, and each timing rule seen on the wire through the session's
// frame log (stamped with the virtual clock).

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "client/arduino/session.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/arduino.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/codec.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/arduino_board.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::arduino {
namespace {

namespace proto = protocol::arduino;
using link::milliseconds;
using link::seconds;

using test::Board;

/// The robot (the board of the test's parameter) behind mem://arduino and a
/// session to it, in virtual time.
struct ArduinoSessionOnMem : ::testing::TestWithParam<Board>, test::BoardCar {
  /// Opens the port and waits until the board listens (the emulated board
  /// resets as the port opens, test::BoardCar::wait_until_listening()).
  void start(ClientConfig config = {}, mocks::ServerOptions options = {}) {
    open(config, std::move(options));
    ASSERT_TRUE(wait_until_listening()) << "the sketch never turned its UART on";
  }

  /// Opens the port and leaves the board to itself.
  void open(ClientConfig config = {}, mocks::ServerOptions options = {}) {
    start_board(GetParam(), test::on_mem("arduino", std::move(options)));
    session = std::make_unique<ArduinoSession>(context, link::MemEndpoint{"arduino"}, config);
    // Log times are the virtual clock in microseconds, so the log shows
    // exactly when each frame went out.
    session->set_wall_clock([this] { return executor.now().count() / 1000; });
    session->set_event_handler([this](const Event& e) {
      if (auto* l = std::get_if<LinkChanged>(&e)) changes.push_back(*l);
    });
    session->open();
    executor.run_for(Duration::zero());
    ASSERT_EQ(session->state(), ConnectionState::connected);
  }

  /// Runs a request to its end; the result and when it came.
  std::optional<Result> run(
      const std::function<RequestId(ArduinoSession&, ArduinoSession::Callback)>& f,
      Duration limit = seconds(30)) {
    std::optional<Result> result;
    f(*session, [&](const Result& r) {
      result = r;
      done_at = executor.now();
    });
    test::run_until_done(
        executor, [&] { return result.has_value(); }, limit);
    return result;
  }

  std::vector<Time> tx_times() const {
    std::vector<Time> out;
    for (auto& e : session->log().entries()) {
      if (e.kind == LogKind::tx) out.push_back(link::microseconds(e.utc_us));
    }
    return out;
  }

  /// The frame log, one line per frame with its time in microseconds, for
  /// a failure's message.
  std::string wire() const {
    std::string out;
    for (const auto& e : session->log().entries())
      out += std::to_string(e.utc_us) + (e.kind == LogKind::tx ? " TX " : " RX ") + e.raw + "\n";
    return out;
  }

  std::unique_ptr<ArduinoSession> session;
  std::vector<LinkChanged> changes;
  Time done_at{0};
};

/// The same, for the tests that need a behaviour only the mock honours.
struct ArduinoMockSessionOnMem : ArduinoSessionOnMem {};

/// Server options whose link corrupts the checksum of each of the first
/// `count` frames going `direction`.
mocks::ServerOptions checksum_corrupted(link::DirectionFilter direction, std::uint64_t count) {
  mocks::ServerOptions options;
  link::FaultRule rule;
  rule.direction = direction;
  rule.trigger.first = count;
  rule.action = link::Corrupt{.target = link::CorruptTarget::checksum, .field = "", .bits = 1};
  options.faults.rules.push_back(rule);
  return options;
}

/// Server options whose link loses every frame to the robot until `until`
/// (for ever when not given): a deaf robot on either board.
mocks::ServerOptions requests_lost(std::optional<Time> until = std::nullopt) {
  mocks::ServerOptions options;
  link::FaultRule rule;
  rule.direction = link::DirectionFilter::to_car;
  rule.window.to = until;
  rule.action = link::Drop{};
  options.faults.rules.push_back(rule);
  return options;
}

ClientConfig quiet() {
  ClientConfig c;
  c.health_check_interval = Duration::zero();
  return c;
}

TEST_P(ArduinoSessionOnMem, EveryHelperGetsTheRobotsAnswer) {
  start(quiet());
  auto ok = [](const std::optional<Result>& r) {
    EXPECT_TRUE(r.has_value());
    if (!r) return std::string();
    EXPECT_EQ(r->code, ResultCode::ok) << r->detail;
    return r->info;
  };
  // The real sketch's answers (the default profile).
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.ping(cb); })), "PONG");
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.set_v(160, cb); })), "OK");
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.move_cm(10, cb); })), "ACCEPTED");
  EXPECT_EQ(ok(run([](auto& s, auto cb) {
              return s.status(cb);
            })).rfind("STATUS:V=160,DIR=fwd,MOT:MOVE,tleft:", 0),
            0u);
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.stop(cb); })), "STOPPED");
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.raw("R:-90", cb); })), "ACCEPTED");
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.rotate_deg(30, cb); })), "ACCEPTED");
  const std::string sonar = ok(run([](auto& s, auto cb) { return s.sonar(cb); }));
  ASSERT_EQ(sonar.rfind("B:", 0), 0u) << sonar;
  EXPECT_EQ(sonar.find_first_not_of("0123456789", 2), std::string::npos) << sonar;
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.ir(cb); })).rfind("I:AL=", 0), 0u);
  EXPECT_EQ(ok(run([](auto& s, auto cb) { return s.help(cb); })),
            mocks::ArduinoFirmware::help_text(proto::Dialect::firmware));
  // The mock also keeps the last SEQ it took (the sketch keeps none).
  if (auto* m = mock()) EXPECT_EQ(m->state().last_seq, std::optional<std::uint8_t>(0x09));
  // Every frame in the log, both ways, with its SEQ.
  const auto entries = session->log().entries();
  ASSERT_EQ(entries.size(), 20u) << wire();
  EXPECT_EQ(entries[0].raw, "^00|PING| *30$");
  EXPECT_EQ(entries[1].raw, "^00|ACK|PONG*5F$");
  EXPECT_EQ(entries[1].kind, LogKind::rx);
  EXPECT_EQ(entries[1].seq, std::optional<std::uint8_t>(0x00));
}

// Mock only: the sketch never refuses a move (a scripted Reject does not
// act on the emulated board).
TEST_P(ArduinoMockSessionOnMem, ARejectedMoveComesBackAsItsNack) {
  start(quiet());
  firmware->arm(test::reject_next("M"));
  auto r = run([](auto& s, auto cb) { return s.move_cm(20, cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::nack);
  EXPECT_EQ(r->nack, (proto::Nack{std::string("BUSY")}));
  EXPECT_EQ(r->attempts, 1);
}

TEST_P(ArduinoSessionOnMem, CorruptedAnswersAreRetriedAfterExactly600Then1200Ms) {
  start(quiet(), checksum_corrupted(link::DirectionFilter::to_client, 2));
  const Time t0 = executor.now();
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
  EXPECT_EQ(r->attempts, 3) << wire();
  EXPECT_EQ(session->core().parse_errors(), 2u);
  const auto tx = tx_times();
  ASSERT_EQ(tx.size(), 3u);
  EXPECT_EQ(tx[0], t0);
  EXPECT_EQ(tx[1] - tx[0], milliseconds(600));
  EXPECT_EQ(tx[2] - tx[1], milliseconds(1200));
}

TEST_P(ArduinoSessionOnMem, ANackBadCsIsResentAtOnce) {
  start(quiet(), checksum_corrupted(link::DirectionFilter::to_car, 1));
  auto r = run([](auto& s, auto cb) { return s.set_v(200, cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
  EXPECT_EQ(r->info, "OK");
  EXPECT_EQ(r->attempts, 1) << wire();
  EXPECT_EQ(r->bad_cs_resends, 1);
  const auto entries = session->log().entries();
  ASSERT_EQ(entries.size(), 4u);
  EXPECT_EQ(entries[1].raw, "^00|NACK|BAD_CS*0F$");
  EXPECT_EQ(entries[2].kind, LogKind::tx);
  EXPECT_EQ(entries[2].raw, entries[0].raw);
  EXPECT_EQ(entries[2].utc_us, entries[1].utc_us) << "resent the moment the NACK arrived";
  // The resent V took effect.
  auto status = run([](auto& s, auto cb) { return s.status(cb); });
  ASSERT_TRUE(status);
  EXPECT_EQ(status->info, "STATUS:V=200,DIR=stop,MOT:IDLE");
}

// Mock only: the sketch answers every frame it hears (a scripted Ignore
// does not act on the emulated board).
TEST_P(ArduinoMockSessionOnMem, ARobotThatIgnoresEverythingGivesTimeoutAfter9s) {
  start(quiet());
  firmware->arm({.name = "", .when = {}, .action = mocks::Ignore{}});
  const Time t0 = executor.now();
  auto r = run([](auto& s, auto cb) { return s.sonar(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::timeout);
  EXPECT_EQ(r->attempts, 4);
  EXPECT_EQ(done_at - t0, milliseconds(9000));
  const auto tx = tx_times();
  ASSERT_EQ(tx.size(), 4u);
  EXPECT_EQ(tx[1] - t0, milliseconds(600));
  EXPECT_EQ(tx[2] - t0, milliseconds(1800));
  EXPECT_EQ(tx[3] - t0, milliseconds(4200));
}

// Mock only: it needs the board to ignore a request (Ignore does not act on
// the emulated board).
TEST_P(ArduinoMockSessionOnMem, AStaleAnswerWithAnotherSeqIsIgnored) {
  start(quiet());
  firmware->arm(
      {.name = "", .when = {}, .action = mocks::Ignore{.match = "B", .count = 1, .duration = {}}});
  mocks::When at_100ms;
  at_100ms.at = milliseconds(100);
  firmware->arm({.name = "",
                 .when = at_100ms,
                 .action = mocks::SendBytes{proto::encode({0x7F, proto::Ack{"999"}})}});
  const Time t0 = executor.now();
  auto r = run([](auto& s, auto cb) { return s.sonar(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
  EXPECT_NE(r->info, "999");
  EXPECT_EQ(r->attempts, 2);
  EXPECT_EQ(done_at - t0, milliseconds(600));
  EXPECT_EQ(session->core().stale_frames(), 1u);
}

// Mock only: the robot goes deaf by a scripted Ignore, which does not act on
// the emulated board.
TEST_P(ArduinoMockSessionOnMem, TheLinkGoesDegradedThenReconnectingThenOpenWhenTheRobotComesBack) {
  start();  // health check after 5 s of quiet
  // The robot hears nothing for 10 s, then recovers.
  firmware->arm({.name = "",
                 .when = {},
                 .action = mocks::Ignore{.match = "", .count = {}, .duration = seconds(10)}});
  executor.run_until(seconds(20));
  ASSERT_EQ(changes.size(), 5u);
  const std::vector<std::pair<ConnectionState, Time>> expected = {
      {ConnectionState::connecting, seconds(0)},
      {ConnectionState::connected, seconds(0)},
      {ConnectionState::degraded, seconds(14)},  // PING at 5 s, 9 s of attempts
      {ConnectionState::reconnecting, milliseconds(14500)},
      {ConnectionState::connected, milliseconds(14500)}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(changes[i].to, expected[i].first) << i;
    EXPECT_EQ(changes[i].at, expected[i].second) << i;
  }
  EXPECT_EQ(server->clients_served(), 2u);
  EXPECT_EQ(boots(), 3u) << "power-on and a reset per port opening";
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
}

// Mock only: silence by a scripted Ignore, which does not act on the
// emulated board.
TEST_P(ArduinoMockSessionOnMem, ARobotThatStaysSilentTakesTheLinkDown) {
  ClientConfig config = quiet();
  config.max_reconnect_attempts = 2;
  start(config);
  firmware->arm({.name = "", .when = {}, .action = mocks::Ignore{}});
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::timeout);
  executor.run_until(seconds(60));
  ASSERT_FALSE(changes.empty());
  EXPECT_EQ(changes.back().to, ConnectionState::down);
  // 9 s, +0.5 s, +4.2 s of reconnect PING, +1 s, +4.2 s.
  EXPECT_EQ(changes.back().at, milliseconds(9000 + 500 + 4200 + 1000 + 4200));
}

TEST_P(ArduinoSessionOnMem, ARobotThatHangsUpIsReopenedHalfASecondLaterAndQueuedRequestsGoOut) {
  start(quiet());
  mocks::When at_1s;
  at_1s.at = seconds(1);
  firmware->arm({.name = "", .when = at_1s, .action = mocks::CloseConnection{}});
  executor.run_until(seconds(1));
  ASSERT_EQ(session->state(), ConnectionState::degraded);
  EXPECT_EQ(changes.back().at, seconds(1));
  std::optional<Result> queued;
  session->sonar([&](const Result& r) {
    queued = r;
    done_at = executor.now();
  });
  executor.run_until(seconds(3));
  EXPECT_EQ(session->state(), ConnectionState::connected);
  ASSERT_TRUE(queued.has_value());
  EXPECT_EQ(queued->code, ResultCode::ok);
  // The reconnect PING took the next SEQ, the queued request the one after.
  EXPECT_EQ(queued->seq, std::optional<std::uint8_t>(0x01));
  // After the hang-up: the reconnect PING (SEQ 00), OPEN the instant its
  // ACK came in, and the queued sonar (SEQ 01) sent in that same instant.
  const auto entries = session->log().entries();
  ASSERT_GE(entries.size(), 4u);
  const auto us = [](Time t) { return t.count() / 1000; };
  std::vector<std::int64_t> ping_tx;
  std::optional<std::int64_t> ping_ack, sonar_tx, sonar_rx;
  for (const auto& e : entries) {
    if (e.kind == LogKind::tx && e.raw == "^00|PING| *30$") ping_tx.push_back(e.utc_us);
    if (e.kind == LogKind::rx && e.raw == "^00|ACK|PONG*5F$") ping_ack = e.utc_us;
    if (e.kind == LogKind::tx && e.seq == std::optional<std::uint8_t>(0x01)) sonar_tx = e.utc_us;
    if (e.kind == LogKind::rx && e.seq == std::optional<std::uint8_t>(0x01)) sonar_rx = e.utc_us;
  }
  ASSERT_TRUE(ping_ack && sonar_tx && sonar_rx);
  EXPECT_EQ(us(changes.back().at), *ping_ack);
  EXPECT_EQ(*sonar_tx, *ping_ack) << "sent right after the reconnect PING's ACK";
  EXPECT_EQ(us(done_at), *sonar_rx);
  if (GetParam() == Board::mock) {
    // The mock hears the PING sent as the port opens: OPEN at 1.5 s.
    EXPECT_EQ(ping_tx, (std::vector<std::int64_t>{1'500'000}));
    EXPECT_EQ(changes.back().at, milliseconds(1500));
    EXPECT_EQ(done_at, milliseconds(1500));
  } else {
    // The emulated board resets as the port opens and is deaf while it
    // does (about 66 ms): the PING sent at once is lost, and its first
    // retry, 600 ms later, proves the port.
    EXPECT_EQ(ping_tx, (std::vector<std::int64_t>{1'500'000, 2'100'000}));
    EXPECT_GT(changes.back().at, milliseconds(2100));
    EXPECT_LT(changes.back().at, milliseconds(2200));
  }
}

// The robot's deafness comes from the link here (every request lost for
// 10 s), so both boards take part; the mock's scripted Ignore does the same
// in TheLinkGoesDegradedThenReconnectingThenOpenWhenTheRobotComesBack.
TEST_P(ArduinoSessionOnMem, ALinkThatLosesEveryRequestFor10sDegradesAndReconnects) {
  start({}, requests_lost(seconds(10)));  // health check after 5 s of quiet
  executor.run_until(seconds(20));
  ASSERT_EQ(changes.size(), 5u) << wire();
  const std::vector<std::pair<ConnectionState, Time>> expected = {
      {ConnectionState::connecting, seconds(0)},
      {ConnectionState::connected, seconds(0)},
      {ConnectionState::degraded, seconds(14)},  // PING at 5 s, 9 s of attempts
      {ConnectionState::reconnecting, milliseconds(14500)}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(changes[i].to, expected[i].first) << i;
    EXPECT_EQ(changes[i].at, expected[i].second) << i;
  }
  EXPECT_EQ(changes[4].to, ConnectionState::connected);
  if (GetParam() == Board::mock) {
    EXPECT_EQ(changes[4].at, milliseconds(14500));
  } else {
    // The reopened port resets the emulated board: the proving PING sent
    // at 14.5 s is lost in the reset, its retry at 15.1 s is answered.
    const Duration exchange = test::sketch_frames_time(14, 16);
    EXPECT_GE(changes[4].at, milliseconds(15100) + exchange) << wire();
    EXPECT_LE(changes[4].at, milliseconds(15100) + exchange + test::kSketchSlack) << wire();
  }
  EXPECT_EQ(server->clients_served(), 2u);
  EXPECT_EQ(boots(), 3u) << "power-on and a reset per port opening";
}

// A link that loses every request: the same timeline on both boards, since
// neither hears anything.
TEST_P(ArduinoSessionOnMem, ALinkThatLosesEveryRequestTakesTheLinkDown) {
  ClientConfig config = quiet();
  config.max_reconnect_attempts = 2;
  start(config, requests_lost());
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::timeout);
  // Sent once the board listens (at once on the mock).
  const auto entries = session->log().entries();
  ASSERT_FALSE(entries.empty());
  const Time sent = link::microseconds(entries[0].utc_us);
  executor.run_until(sent + seconds(20));
  ASSERT_FALSE(changes.empty());
  EXPECT_EQ(changes.back().to, ConnectionState::down);
  // 9 s, +0.5 s, +4.2 s of reconnect PING, +1 s, +4.2 s.
  EXPECT_EQ(changes.back().at - sent, milliseconds(9000 + 500 + 4200 + 1000 + 4200));
}

// The client sends its first request the instant the port is open; it
// does not wait for the board. The mock answers it; the emulated board,
// like a real Uno, is resetting then (AvrConfig::startup_delay, about 66
// ms) and hears nothing, so the request is answered at its first retry.
TEST_P(ArduinoSessionOnMem, ARequestSentAsThePortOpensMeetsTheBoardsReset) {
  open(quiet());
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
  EXPECT_EQ(r->info, "PONG");
  const auto tx = tx_times();
  if (GetParam() == Board::mock) {
    EXPECT_EQ(r->attempts, 1);
    EXPECT_EQ(tx, (std::vector<Time>{milliseconds(0)}));
    EXPECT_EQ(done_at, milliseconds(0));
  } else {
    EXPECT_EQ(r->attempts, 2);
    EXPECT_EQ(tx, (std::vector<Time>{milliseconds(0), milliseconds(600)}));
    // 14 bytes in and 16 out at 9,600 baud: about 31 ms after the retry.
    EXPECT_GT(done_at, milliseconds(600 + 25));
    EXPECT_LT(done_at, milliseconds(600 + 50));
  }
}

INSTANTIATE_TEST_SUITE_P(Boards, ArduinoSessionOnMem, test::both_boards(), test::board_param_name);
INSTANTIATE_TEST_SUITE_P(Boards, ArduinoMockSessionOnMem, ::testing::Values(Board::mock),
                         test::board_param_name);

}  // namespace
}  // namespace hil::client::arduino
