// The Arduino client session against the mock Arduino robot on mem:// in
// virtual time: every helper, and each timing rule seen on the wire through
// the session's frame log (stamped with the virtual clock).

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
#include "tests/client/client_test_support.hpp"

namespace hil::client::arduino {
namespace {

namespace proto = protocol::arduino;
using link::milliseconds;
using link::seconds;

/// The mock robot behind mem://arduino and a session to it, in virtual time.
struct ArduinoSessionOnMem : ::testing::Test, test::VirtualCar<mocks::ArduinoFirmware> {
  void start(ClientConfig config = {}, mocks::ServerOptions options = {}) {
    start_car(sim::arduino_robot(), test::on_mem("arduino", std::move(options)));
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
      if (e.kind == LogKind::tx) out.push_back(milliseconds(e.utc_us / 1000));
    }
    return out;
  }

  std::unique_ptr<ArduinoSession> session;
  std::vector<LinkChanged> changes;
  Time done_at{0};
};

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

ClientConfig quiet() {
  ClientConfig c;
  c.health_check_interval = Duration::zero();
  return c;
}

TEST_F(ArduinoSessionOnMem, EveryHelperGetsTheRobotsAnswer) {
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
  EXPECT_EQ(firmware->state().last_seq, std::optional<std::uint8_t>(0x09));
  // Every frame in the log, both ways, with its SEQ.
  const auto entries = session->log().entries();
  ASSERT_EQ(entries.size(), 20u);
  EXPECT_EQ(entries[0].raw, "^00|PING| *30$");
  EXPECT_EQ(entries[1].raw, "^00|ACK|PONG*5F$");
  EXPECT_EQ(entries[1].kind, LogKind::rx);
  EXPECT_EQ(entries[1].seq, std::optional<std::uint8_t>(0x00));
}

TEST_F(ArduinoSessionOnMem, ARejectedMoveComesBackAsItsNack) {
  start(quiet());
  firmware->arm(test::reject_next("M"));
  auto r = run([](auto& s, auto cb) { return s.move_cm(20, cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::nack);
  EXPECT_EQ(r->nack, (proto::Nack{std::string("BUSY")}));
  EXPECT_EQ(r->attempts, 1);
}

TEST_F(ArduinoSessionOnMem, CorruptedAnswersAreRetriedAfterExactly600Then1200Ms) {
  start(quiet(), checksum_corrupted(link::DirectionFilter::to_client, 2));
  const Time t0 = executor.now();
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
  EXPECT_EQ(r->attempts, 3);
  EXPECT_EQ(session->core().parse_errors(), 2u);
  const auto tx = tx_times();
  ASSERT_EQ(tx.size(), 3u);
  EXPECT_EQ(tx[0], t0);
  EXPECT_EQ(tx[1] - tx[0], milliseconds(600));
  EXPECT_EQ(tx[2] - tx[1], milliseconds(1200));
}

TEST_F(ArduinoSessionOnMem, ANackBadCsIsResentAtOnce) {
  start(quiet(), checksum_corrupted(link::DirectionFilter::to_car, 1));
  auto r = run([](auto& s, auto cb) { return s.set_v(200, cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
  EXPECT_EQ(r->info, "OK");
  EXPECT_EQ(r->attempts, 1);
  EXPECT_EQ(r->bad_cs_resends, 1);
  const auto entries = session->log().entries();
  ASSERT_EQ(entries.size(), 4u);
  EXPECT_EQ(entries[1].raw, "^00|NACK|BAD_CS*0F$");
  EXPECT_EQ(entries[2].kind, LogKind::tx);
  EXPECT_EQ(entries[2].raw, entries[0].raw);
  EXPECT_EQ(entries[2].utc_us, entries[1].utc_us) << "resent the moment the NACK arrived";
  EXPECT_EQ(firmware->state().pwm, 200);
}

TEST_F(ArduinoSessionOnMem, ARobotThatIgnoresEverythingGivesTimeoutAfter9s) {
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

TEST_F(ArduinoSessionOnMem, AStaleAnswerWithAnotherSeqIsIgnored) {
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

TEST_F(ArduinoSessionOnMem, TheLinkGoesDegradedThenReconnectingThenOpenWhenTheRobotComesBack) {
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
  EXPECT_EQ(firmware->state().boots, 3u) << "power-on and a reset per port opening";
  auto r = run([](auto& s, auto cb) { return s.ping(cb); });
  ASSERT_TRUE(r);
  EXPECT_EQ(r->code, ResultCode::ok);
}

TEST_F(ArduinoSessionOnMem, ARobotThatStaysSilentTakesTheLinkDown) {
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

TEST_F(ArduinoSessionOnMem, ARobotThatHangsUpIsReopenedHalfASecondLaterAndQueuedRequestsGoOut) {
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
  EXPECT_EQ(changes.back().at, milliseconds(1500));
  ASSERT_TRUE(queued.has_value());
  EXPECT_EQ(queued->code, ResultCode::ok);
  EXPECT_EQ(done_at, milliseconds(1500)) << "sent right after the reconnect PING's ACK";
  // The reconnect PING took the next SEQ, the queued request the one after.
  EXPECT_EQ(queued->seq, std::optional<std::uint8_t>(0x01));
}

}  // namespace
}  // namespace hil::client::arduino
