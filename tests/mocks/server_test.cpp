// The firmware base, scripted behaviours and the server, with a tiny echo
// firmware under the virtual-time driver.

#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "mocks/firmware.hpp"
#include "mocks/server.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks {
namespace {

using link::milliseconds;

// Echoes every byte as "E<byte>" and sends "T" every 100 ms while connected.
class EchoFirmware final : public Firmware {
 public:
  EchoFirmware(sim::World& world, sim::Vehicle& vehicle) : Firmware(world, vehicle, "raw") {}
  std::string summary() const override { return "echo"; }
  int connects = 0;
  int disconnects = 0;
  int faults = 0;

 protected:
  void on_connect(Time now) override {
    ++connects;
    next_t_ = now + milliseconds(100);
  }
  void on_disconnect(Time) override { ++disconnects; }
  void on_bytes(Time now, ByteView bytes) override {
    for (const auto b : bytes) {
      count_frame_in();
      const std::string kind(1, static_cast<char>(b));
      switch (dispose(now, kind)) {
        case Disposition::handle:
          send(std::string("E") + static_cast<char>(b));
          break;
        case Disposition::reject:
          send(std::string("R") + static_cast<char>(b));
          break;
        case Disposition::ignore:
          break;
      }
      frame_handled(now, kind);
    }
  }
  void on_tick(Time now) override {
    while (connected() && now >= next_t_) {
      if (!telemetry_muted(next_t_)) send(std::string_view("T"));
      next_t_ += milliseconds(100);
    }
  }
  std::optional<Time> next_tick() const override {
    return connected() ? std::optional<Time>(next_t_) : std::nullopt;
  }
  void on_fault(Time, bool entered) override { faults += entered ? 1 : -1; }

 private:
  Time next_t_{0};
};

using Car = test::VirtualCar<EchoFirmware>;

Car make_car(ServerOptions options = {}) {
  return Car(
      sim::logi_car(),
      [](sim::World& w, sim::Vehicle& v) { return std::make_unique<EchoFirmware>(w, v); },
      std::move(options));
}

/// Writes `text` from `client`, runs 1 ms and returns what came back.
std::string exchange(Car& car, test::ClientEnd& client, std::string_view text) {
  client.write(text);
  car.run_for(milliseconds(1));
  return client.take_text();
}

TEST(MockServer, JoinsAClientToTheFirmwareAndBack) {
  auto car = make_car();
  auto client = car.connect();
  ASSERT_TRUE(car.server().client_connected());
  EXPECT_EQ(exchange(car, *client, "ab"), "EaEb");
  EXPECT_EQ(car.firmware().stats().frames_in, 2u);
  EXPECT_EQ(car.firmware().stats().bytes_in, 2u);
}

TEST(MockServer, TelemetryFollowsTheFirmwareClockExactly) {
  auto car = make_car();
  auto client = car.connect();  // connected at 0 ms
  car.run_until(link::Time(milliseconds(99)));
  EXPECT_EQ(client->take_text(), "");
  car.run_until(link::Time(milliseconds(100)));
  EXPECT_EQ(client->take_text(), "T");
  car.run_until(link::Time(milliseconds(1000)));
  EXPECT_EQ(client->take_text(), std::string(9, 'T'));
}

TEST(MockServer, TheWorldAdvancesWithTheExecutorWithoutAClient) {
  auto car = make_car();
  car.run_for(milliseconds(500));
  // Nothing to do without a client, so the world only catches up on the next event.
  auto client = car.connect();
  EXPECT_GE(car.world().time(), link::Duration(milliseconds(500)));
}

TEST(MockServer, ASecondClientIsClosedAndTheFirstKeepsItsSession) {
  auto car = make_car();
  auto first = car.connect();
  auto second = car.connect();
  car.run_for(milliseconds(5));
  ASSERT_TRUE(second->closed.has_value());
  EXPECT_EQ(*second->closed, link::end_of_stream());
  EXPECT_EQ(car.server().turned_away(), 1u);
  EXPECT_EQ(exchange(car, *first, "x"), "Ex");
  EXPECT_FALSE(first->closed.has_value());
}

TEST(MockServer, AClientThatLeavesDisconnectsTheFirmwareAndTheNextIsServed) {
  auto car = make_car();
  auto first = car.connect();
  first->pipe->close();
  car.run_for(milliseconds(5));
  EXPECT_FALSE(car.firmware().connected());
  EXPECT_EQ(car.firmware().disconnects, 1);
  auto second = car.connect();
  EXPECT_EQ(exchange(car, *second, "y"), "Ey");
  EXPECT_EQ(car.server().clients_served(), 2u);
  EXPECT_EQ(car.firmware().stats().connections, 2u);
}

TEST(MockServer, ARejectBehaviourAnswersTheNextNCommandsOfItsKindNegatively) {
  auto car = make_car();
  auto client = car.connect();
  car.firmware().arm(Behaviour{"", When{}, Reject{"a", 2}});
  EXPECT_EQ(exchange(car, *client, "abaa"), "RaEbRaEa");
  EXPECT_EQ(car.firmware().stats().rejected, 2u);
}

TEST(MockServer, AnIgnoreBehaviourSwallowsCommandsForItsDuration) {
  auto car = make_car();
  auto client = car.connect();
  car.firmware().arm(Behaviour{"", When{}, Ignore{"", std::nullopt, milliseconds(50)}});
  client->write("a");
  car.run_for(milliseconds(30));
  EXPECT_EQ(client->take_text(), "");
  car.run_for(milliseconds(30));
  EXPECT_EQ(exchange(car, *client, "b"), "Eb");
  EXPECT_EQ(car.firmware().stats().ignored, 1u);
}

TEST(MockServer, MutedTelemetryResumesOnTime) {
  auto car = make_car();
  auto client = car.connect();  // T at 100, 200, ...
  car.firmware().arm(Behaviour{"mute", When{link::Time(milliseconds(150)), "", 1},
                               MuteTelemetry{milliseconds(300)}});
  car.run_until(link::Time(milliseconds(1000)));
  // 100 sent; 200, 300, 400 muted (before 450); 500..1000 sent.
  EXPECT_EQ(client->take_text(), std::string(7, 'T'));
}

TEST(MockServer, AfterFrameBehavioursFireOnTheNthMatchingFrame) {
  auto car = make_car();
  auto client = car.connect();
  car.firmware().arm(Behaviour{"hello", When{std::nullopt, "z", 2}, SendBytes{{'!', '!'}}});
  EXPECT_EQ(exchange(car, *client, "zaz"), "EzEaEz!!");
}

TEST(MockServer, ACloseBehaviourHangsUpAndTheCarServesTheNextClient) {
  auto car = make_car();
  auto client = car.connect();
  car.firmware().arm(
      Behaviour{"", When{std::nullopt, "q", 1}, CloseConnection{link::CloseMode::graceful}});
  client->write("q");
  car.run_for(milliseconds(5));
  EXPECT_EQ(client->take_text(), "Eq");  // what was sent before the close still arrives
  ASSERT_TRUE(client->closed.has_value());
  EXPECT_EQ(*client->closed, link::end_of_stream());
  EXPECT_FALSE(car.firmware().connected());
  auto next = car.connect();
  EXPECT_EQ(exchange(car, *next, "r"), "Er");
}

TEST(MockServer, FaultAndClearFaultReachTheFirmwareOnce) {
  auto car = make_car();
  auto client = car.connect();
  car.firmware().arm(Behaviour{"", When{link::Time(milliseconds(10)), "", 1}, EnterFault{}});
  car.firmware().arm(Behaviour{"", When{link::Time(milliseconds(10)), "", 1}, EnterFault{}});
  car.run_for(milliseconds(20));
  EXPECT_TRUE(car.firmware().in_fault());
  EXPECT_EQ(car.firmware().faults, 1);
  car.firmware().arm(Behaviour{"", When{}, ClearFault{}});
  car.run_for(milliseconds(1));
  EXPECT_FALSE(car.firmware().in_fault());
  EXPECT_EQ(car.firmware().faults, 0);
}

TEST(MockServer, LinkFaultsApplyToTheCarsTraffic) {
  link::FaultProfile faults;
  link::FaultRule drop;
  drop.direction = link::DirectionFilter::to_client;
  drop.action = link::Drop{};
  drop.trigger.first = 1;
  faults.rules.push_back(drop);
  ServerOptions options;
  options.faults = faults;
  auto car = make_car(options);
  auto client = car.connect();
  client->write("a");
  car.run_for(milliseconds(1));
  EXPECT_EQ(exchange(car, *client, "b"), "Eb");
  EXPECT_EQ(car.server().faults_injected(), 1u);
}

TEST(MockServer, SetFaultsActsOnTheLinkAtOnceAndOnLaterLinksAndAnEmptyProfileEndsThem) {
  auto car = make_car();
  auto client = car.connect();
  EXPECT_EQ(exchange(car, *client, "a"), "Ea");

  link::FaultProfile drop_answers;
  link::FaultRule drop;
  drop.direction = link::DirectionFilter::to_client;
  drop.action = link::Drop{};  // raw frames: every write the car makes
  drop_answers.rules.push_back(drop);
  car.server().set_faults(drop_answers);
  EXPECT_EQ(exchange(car, *client, "b"), "") << "the running link drops the answer";
  EXPECT_EQ(car.server().faults_injected(), 1u);

  client->pipe->close();
  car.run_for(milliseconds(1));
  auto second = car.connect();
  EXPECT_EQ(exchange(car, *second, "c"), "") << "the next link starts with the new rules";

  car.server().set_faults({});
  EXPECT_EQ(exchange(car, *second, "d"), "Ed");
  EXPECT_EQ(car.server().faults_injected(), 2u);
}

TEST(MockServer, ARefusedConnectionIsAFaultTheObserversSee) {
  struct Faults final : link::LinkObserver {
    std::vector<link::FaultEvent> seen;
    void on_fault(const link::FaultEvent& e) override { seen.push_back(e); }
  };
  auto faults = std::make_shared<Faults>();
  ServerOptions options;
  options.observers.push_back(faults);
  link::FaultRule refuse;
  refuse.name = "closed";
  refuse.action = link::Refuse{milliseconds(500)};
  refuse.trigger.at = Time(0);
  options.faults.rules.push_back(refuse);
  auto car = make_car(options);
  auto client = car.connect();
  car.run_for(milliseconds(1));
  EXPECT_TRUE(client->closed.has_value());
  ASSERT_EQ(faults->seen.size(), 1u);
  EXPECT_EQ(faults->seen[0].kind, link::FaultKind::refuse);
  EXPECT_EQ(faults->seen[0].rule, "closed");
  EXPECT_EQ(car.server().turned_away(), 1u);
}

TEST(KindMatches, MatchesWholeParts) {
  EXPECT_TRUE(kind_matches("", "MV:FWD"));
  EXPECT_TRUE(kind_matches("MV", "MV:FWD"));
  EXPECT_TRUE(kind_matches("MV:FWD", "MV:FWD"));
  EXPECT_FALSE(kind_matches("MV:F", "MV:FWD"));
  EXPECT_FALSE(kind_matches("FB:ST", "FB:STAT"));
  EXPECT_TRUE(kind_matches("motor", "motor.all"));
  EXPECT_FALSE(kind_matches("MV:FWD", "MV"));
}

}  // namespace
}  // namespace hil::mocks
