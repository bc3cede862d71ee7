// The LOGI client session against the mock LOGI car on mem:// in virtual
// time: the auto transport flow, retries against a car that ignores SP, the
// switch to MAN, and the reconnect timeline after a reset connection.

#include "client/logi/session.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "link/executor.hpp"
#include "link/faults/profile.hpp"
#include "link/transport.hpp"
#include "mocks/logi.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::logi {
namespace {

using link::milliseconds;
using link::seconds;
using proto::Direction;
using proto::Mode;

/// The mock car on mem://car and a session pointed at it, in virtual time.
class VirtualBench : public test::SessionOnMem<LogiSession, mocks::LogiFirmware, Event> {
 public:
  explicit VirtualBench(mocks::ServerOptions options = {}, ClientConfig config = {})
      : SessionOnMem("logi", sim::logi_car(), std::move(options), std::move(config)) {}

  using SessionOnMem::run_until;
  /// Runs until `done()` holds, in 10 ms steps, for at most `limit`.
  template <class Pred>
  bool run_until(Pred done, link::Duration limit) {
    const Time end = now() + limit;
    while (!done()) {
      if (now() >= end) return false;
      run_for(milliseconds(10));
    }
    return true;
  }

  void connect() {
    session().connect();
    run_for(milliseconds(1));
    ASSERT_EQ(session().core().state(), ConnectionState::connected);
  }

  std::vector<std::pair<Time, CommandEvent>> commands(CommandState state) const {
    std::vector<std::pair<Time, CommandEvent>> out;
    for (auto& [t, e] : of<CommandEvent>()) {
      if (e.state == state) out.emplace_back(t, e);
    }
    return out;
  }
  /// (time, raw) of every frame the client sent.
  std::vector<std::pair<Time, std::string>> sent() const {
    std::vector<std::pair<Time, std::string>> out;
    for (const auto& e : session().log()->entries()) {
      if (e.kind == LogKind::tx) out.emplace_back(e.at, e.raw);
    }
    return out;
  }
};

TEST(LogiSession, AutoTransportFlowToStation002Completes) {
  VirtualBench b;
  b.connect();
  const auto sp = b.session().submit(proto::SetSpeed{50});
  const auto md = b.session().submit(proto::SetMode{Mode::automatic});
  const auto gs = b.session().submit(proto::SetStation{2});
  const auto run = b.session().submit(proto::SetRun{true});
  ASSERT_TRUE(sp && md && gs && run);
  b.run_for(milliseconds(100));
  std::vector<RequestId> accepted;
  for (auto& [t, e] : b.commands(CommandState::accepted))
    accepted.push_back(e.request);
  EXPECT_EQ(accepted, (std::vector<RequestId>{sp.request, md.request, gs.request, run.request}));
  EXPECT_TRUE(b.firmware().state().running);
  bool saw_running = false;
  ASSERT_TRUE(b.run_until(
      [&] {
        const auto& s = b.session().core().last_status();
        if (s && s->running) saw_running = true;
        return saw_running && s && !s->running;
      },
      seconds(60)));
  const auto& s = *b.session().core().last_status();
  EXPECT_EQ(s.station, 2);
  EXPECT_EQ(b.firmware().state().arrivals, 1u);
  EXPECT_EQ(b.firmware().state().last_run_end, mocks::LogiRunEnd::arrived);
  EXPECT_FALSE(b.session().core().stale());
  EXPECT_TRUE(b.of<ParseErrorEvent>().empty());
}

TEST(LogiSession, ACarThatIgnoresSpGetsTwoRetriesThenTheCommandIsUncertain) {
  VirtualBench b;
  b.firmware().arm(mocks::Behaviour{"deaf to SP", {}, mocks::Ignore{"SP", {}, {}}});
  b.connect();
  const Time t0 = b.now();
  const auto sp = b.session().submit(proto::SetSpeed{30});
  b.session().submit(proto::SetMode{Mode::manual});
  b.run_for(seconds(3));
  const auto tx = b.sent();
  ASSERT_GE(tx.size(), 4u);
  EXPECT_EQ(tx[0], (std::pair<Time, std::string>{t0, "LOGI:SP:030:D5#"}));
  EXPECT_EQ(tx[1], (std::pair<Time, std::string>{t0 + milliseconds(800), "LOGI:SP:030:D5#"}));
  EXPECT_EQ(tx[2], (std::pair<Time, std::string>{t0 + milliseconds(1600), "LOGI:SP:030:D5#"}));
  EXPECT_EQ(tx[3], (std::pair<Time, std::string>{t0 + milliseconds(2400), "LOGI:MD:MAN:0C#"}));
  const auto unc = b.commands(CommandState::uncertain);
  ASSERT_EQ(unc.size(), 1u);
  EXPECT_EQ(unc[0].first, t0 + milliseconds(2400));
  EXPECT_EQ(unc[0].second.request, sp.request);
  EXPECT_EQ(b.firmware().state().mode, Mode::manual) << "the queue went on after the SP";
}

TEST(LogiSession, AMoveInAutoSwitchesTheCarToManAndDrives) {
  VirtualBench b;
  b.connect();
  b.session().submit(proto::SetSpeed{50});
  b.session().submit(proto::SetMode{Mode::automatic});
  b.run_for(milliseconds(10));
  const auto mv = b.session().press(Direction::fwd);
  ASSERT_TRUE(mv);
  b.run_for(milliseconds(10));
  ASSERT_EQ(b.of<NoticeEvent>().size(), 1u);
  EXPECT_EQ(b.of<NoticeEvent>()[0].second.text, "Not in manual mode, switching to MAN");
  EXPECT_EQ(b.firmware().state().mode, Mode::manual);
  EXPECT_EQ(b.firmware().state().manual, Direction::fwd);
  const auto acc = b.commands(CommandState::accepted);
  ASSERT_FALSE(acc.empty());
  EXPECT_EQ(acc.back().second.request, mv.request);
  b.session().release();
  b.run_for(milliseconds(10));
  EXPECT_EQ(b.firmware().state().manual, Direction::stop);
}

TEST(LogiSession, EmergencyStopEndsAnAutoRun) {
  VirtualBench b;
  b.connect();
  b.session().submit(proto::SetSpeed{50});
  b.session().submit(proto::SetMode{Mode::automatic});
  b.session().submit(proto::SetStation{2});
  b.session().submit(proto::SetRun{true});
  b.run_for(seconds(2));
  ASSERT_TRUE(b.firmware().state().running);
  b.session().emergency_stop();
  b.run_for(milliseconds(10));
  EXPECT_FALSE(b.firmware().state().running);
  EXPECT_EQ(b.firmware().state().last_run_end, mocks::LogiRunEnd::stopped);
}

TEST(LogiSession, MutedTelemetryRaisesStaleAfter2sAndItClearsWhenStatReturns) {
  VirtualBench b;
  b.connect();
  b.run_until(seconds(1));  // STATs at 500 ms and 1000 ms
  b.firmware().arm(mocks::Behaviour{"mute", {}, mocks::MuteTelemetry{seconds(3)}});
  b.run_until(seconds(6));
  const auto stale = b.of<StaleEvent>();
  ASSERT_EQ(stale.size(), 2u);
  EXPECT_TRUE(stale[0].second.stale);
  EXPECT_EQ(stale[0].first, seconds(3) + LogiClientCore::kTick)
      << "the first instant more than 2 s after the STAT of 1000 ms";
  EXPECT_FALSE(stale[1].second.stale);
}

TEST(LogiSession, AResetConnectionIsFollowedByReconnectAttemptsAt1s3s6s9s) {
  VirtualBench b;
  b.firmware().arm(mocks::Behaviour{"hang up", mocks::When{seconds(2), {}, 1},
                                    mocks::CloseConnection{link::CloseMode::reset}});
  b.connect();
  b.session().submit(proto::SetSpeed{50});
  b.session().submit(proto::SetMode{Mode::manual});
  b.run_until(seconds(2));
  ASSERT_NE(b.session().core().state(), ConnectionState::connected);
  Time dropped{0};
  for (auto& [t, e] : b.of<ConnectionEvent>()) {
    if (e.state == ConnectionState::reconnecting) {
      dropped = t;
      break;
    }
  }
  EXPECT_EQ(dropped, seconds(2));
  EXPECT_FALSE(b.session().core().movement_enabled());
  b.server().close();  // the car is gone: every attempt is refused
  b.run_until(seconds(12));
  std::vector<Time> attempts;
  for (auto& [t, e] : b.of<ConnectionEvent>()) {
    if (e.state == ConnectionState::connecting && t > seconds(2)) attempts.push_back(t);
  }
  EXPECT_EQ(attempts, (std::vector<Time>{seconds(3), seconds(5), seconds(8), seconds(11)}));
  // The car comes back: the next attempt connects, and movement waits for MD and SP.
  b.server().start();
  b.run_until(seconds(14) + milliseconds(1));
  EXPECT_EQ(b.session().core().state(), ConnectionState::connected);
  EXPECT_EQ(b.session().press(Direction::fwd).refusal, Refusal::mode_speed_unconfirmed);
  b.session().submit(proto::SetMode{Mode::manual});
  b.session().submit(proto::SetSpeed{40});
  EXPECT_TRUE(b.session().press(Direction::fwd));
  b.run_for(milliseconds(10));
  EXPECT_EQ(b.firmware().state().manual, Direction::fwd);
}

TEST(LogiSession, DisconnectOnRequestStaysDisconnected) {
  VirtualBench b;
  b.connect();
  b.session().disconnect();
  b.run_for(seconds(10));
  EXPECT_EQ(b.session().core().state(), ConnectionState::disconnected);
  EXPECT_FALSE(b.server().client_connected());
  EXPECT_EQ(b.server().clients_served(), 1u);
}

TEST(LogiSession, FramesSplitIntoPiecesAndStuckTogetherAllArrive) {
  mocks::ServerOptions options;
  link::FaultRule split;
  split.name = "split";
  split.direction = link::DirectionFilter::to_client;
  split.trigger.match = "STAT";
  split.action = link::Fragment{{1, 3}, {milliseconds(1), milliseconds(2)}};
  options.faults.rules.push_back(split);
  link::FaultRule stick;
  stick.name = "stick";
  stick.direction = link::DirectionFilter::to_client;
  stick.trigger.match = "FB";
  stick.action = link::Coalesce{2, seconds(1)};
  options.faults.rules.push_back(stick);
  VirtualBench b(options);
  b.connect();
  b.session().submit(proto::SetSpeed{50});
  b.session().submit(proto::SetMode{Mode::manual});
  b.run_until(seconds(5) + milliseconds(100));  // the last STAT's pieces take a few ms
  EXPECT_GE(b.server().faults_injected(), 11u) << "ten STATs split, FBs stuck together";
  EXPECT_TRUE(b.of<ParseErrorEvent>().empty());
  EXPECT_EQ(b.of<StatusEvent>().size(), 10u) << "STAT at 500 ms ... 5000 ms";
  EXPECT_EQ(b.commands(CommandState::accepted).size(), 2u);
  EXPECT_FALSE(b.session().core().stale());
}

TEST(LogiSession, AFrameWithABadChecksumIsDroppedAndLoggedAndTheLinkStaysUp) {
  VirtualBench b;
  b.firmware().arm(
      mocks::Behaviour{"noise", mocks::When{seconds(1) + milliseconds(100), {}, 1},
                       mocks::SendBytes{protocol::Bytes{'L', 'O', 'G', 'I', ':', 'F', 'B', ':', 'S',
                                                        'P', ':', '1', ':', '0', '0', '#'}}});
  b.connect();
  b.run_until(seconds(2));
  const auto errors = b.of<ParseErrorEvent>();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].first, seconds(1) + milliseconds(100));
  EXPECT_EQ(errors[0].second.error.kind, protocol::ErrorKind::bad_checksum);
  EXPECT_TRUE(b.of<FeedbackEvent>().empty());
  EXPECT_NE(b.session()
                .log()
                ->to_string(client::LogFormat::txt)
                .find("ERR  LOGI:FB:SP:1:00#  bad_checksum"),
            std::string::npos)
      << b.session().log()->to_string(client::LogFormat::txt);
  EXPECT_EQ(b.session().core().state(), ConnectionState::connected);
  EXPECT_EQ(b.of<StatusEvent>().size(), 4u);
}

TEST(LogiSession, KeepaliveRepeatsTheHeldMoveToTheCarEvery300ms) {
  ClientConfig config;
  config.keepalive = true;
  VirtualBench b({}, config);
  b.connect();
  b.session().submit(proto::SetSpeed{50});
  b.session().submit(proto::SetMode{Mode::manual});
  b.run_until(milliseconds(100));
  b.session().press(Direction::cw);
  b.run_until(milliseconds(950));
  b.session().release();
  b.run_until(milliseconds(2000));
  std::vector<Time> moves;
  for (const auto& [t, raw] : b.sent()) {
    if (raw == "LOGI:MV:CW:DC#") moves.push_back(t);
  }
  EXPECT_EQ(moves, (std::vector<Time>{milliseconds(100), milliseconds(400), milliseconds(700)}));
  EXPECT_EQ(b.sent().back(), (std::pair<Time, std::string>{milliseconds(950), "LOGI:MV:STOP:88#"}));
  EXPECT_EQ(b.firmware().state().manual, Direction::stop);
}

}  // namespace
}  // namespace hil::client::logi
