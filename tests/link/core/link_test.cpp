// A Link over mem pipes in virtual time: what each side receives, when, and
// how the link ends, with exact times.

#include <gtest/gtest.h>

#include <functional>

#include "link/faults/profile_yaml.hpp"
#include "link/link.hpp"
#include "link/mem_pipe.hpp"

namespace hil::link {
namespace {

using protocol::to_bytes;

struct End {
  std::string data;
  std::vector<std::pair<Time, std::string>> arrivals;
  std::optional<std::error_code> closed;
  Time closed_at{-1};
  Time ended_at{-1};             // on_end: the peer half-closed (only for ends that take it)
  std::function<void()> on_end;  // runs after ended_at is set
};

struct Recorder final : LinkObserver {
  std::vector<FaultEvent> faults;
  std::optional<LinkClose> close;
  Time closed_at{-1};
  std::optional<Time> opened_at;
  std::vector<std::pair<Time, Direction>> half_closes;
  void on_open(Time at, const std::string&, const std::string&) override { opened_at = at; }
  void on_fault(const FaultEvent& e) override { faults.push_back(e); }
  void on_half_close(Time at, Direction d) override { half_closes.emplace_back(at, d); }
  void on_close(Time at, const LinkClose& c) override {
    close = c;
    closed_at = at;
  }
};

class LinkTest : public ::testing::Test {
 protected:
  VirtualExecutor ex;
  BytePipePtr client_app, client_side, car_app, car_side;
  End at_client, at_car;
  std::shared_ptr<Recorder> recorder = std::make_shared<Recorder>();
  std::shared_ptr<Link> link;

  /// `half_close`: both apps take a half-close (on_end), as TCP peers do.
  void open(const std::string& to_car_yaml = "rules: []",
            const std::string& to_client_yaml = "rules: []", bool half_close = false) {
    std::tie(client_app, client_side) = make_mem_pipe(ex, "client");
    std::tie(car_side, car_app) = make_mem_pipe(ex, "car");
    watch(client_app, at_client, half_close);
    watch(car_app, at_car, half_close);
    LinkOptions o;
    o.protocol = protocol_adapter("logi");
    o.to_car = parse_fault_profile_text(to_car_yaml, "to_car");
    o.to_client = parse_fault_profile_text(to_client_yaml, "to_client");
    o.seed = 1;
    o.observers.push_back(recorder);
    link = Link::create(ex, client_side, car_side, o);
    link->start();
  }
  void watch(const BytePipePtr& pipe, End& end, bool half_close = false) {
    BytePipe::Handlers handlers{[this, &end](ByteView b) {
                                  end.data.append(b.begin(), b.end());
                                  end.arrivals.emplace_back(ex.now(),
                                                            std::string(b.begin(), b.end()));
                                },
                                [this, &end](std::error_code ec) {
                                  end.closed = ec;
                                  end.closed_at = ex.now();
                                }};
    if (half_close) {
      handlers.on_end = [this, &end] {
        end.ended_at = ex.now();
        if (end.on_end) end.on_end();
      };
    }
    pipe->start(std::move(handlers));
  }
};

TEST_F(LinkTest, OpensNowOrAtTheInstantItsConnectionWasAccepted) {
  open();
  EXPECT_EQ(recorder->opened_at, Time(0));
  // Accepted at 5 ms, set up and started at 12 ms (a loaded machine): the
  // observers see it open at 5 ms, the instant the car was connected.
  ex.run_until(Time(std::chrono::milliseconds(12)));
  auto [client_end, client_link_side] = make_mem_pipe(ex, "client2");
  auto [car_link_side, car_end] = make_mem_pipe(ex, "car2");
  LinkOptions o;
  auto late = std::make_shared<Recorder>();
  o.observers.push_back(late);
  auto second = Link::create(ex, client_link_side, car_link_side, o);
  second->start(Time(std::chrono::milliseconds(5)));
  EXPECT_EQ(late->opened_at, Time(std::chrono::milliseconds(5)));
}

TEST_F(LinkTest, CarriesBothDirectionsUntouchedWithoutFaults) {
  open();
  client_app->write(to_bytes("LOGI:SP:050:D7#"));
  car_app->write(to_bytes("LOGI:FB:SP:1:35#"));
  ex.run_until_idle();
  EXPECT_EQ(at_car.data, "LOGI:SP:050:D7#");
  EXPECT_EQ(at_client.data, "LOGI:FB:SP:1:35#");
  const auto stats = link->stats();
  EXPECT_EQ(stats.bytes_sent[0], 15u);
  EXPECT_EQ(stats.bytes_delivered[1], 16u);
  EXPECT_EQ(stats.faults, 0u);
}

TEST_F(LinkTest, UntouchedFramesOfOneWriteArriveAsOneWrite) {
  open();
  client_app->write(to_bytes("LOGI:SP:050:D7#LOGI:MD:MAN:0C#LOGI:MV:FWD:23#"));
  client_app->write(to_bytes("LOGI:MV:STOP:88#"));
  ex.run_until_idle();
  ASSERT_EQ(at_car.arrivals.size(), 2u);
  EXPECT_EQ(at_car.arrivals[0].second, "LOGI:SP:050:D7#LOGI:MD:MAN:0C#LOGI:MV:FWD:23#");
  EXPECT_EQ(at_car.arrivals[1].second, "LOGI:MV:STOP:88#");
}

TEST_F(LinkTest, AFrameARuleTouchedIsItsOwnWrite) {
  open("rules:\n  - kind: delay\n    delay: 10ms\n    at_frame: 2\n");
  client_app->write(to_bytes("LOGI:SP:050:D7#LOGI:MD:MAN:0C#LOGI:MV:FWD:23#"));
  ex.run_until_idle();
  ASSERT_EQ(at_car.arrivals.size(), 3u);
  EXPECT_EQ(at_car.arrivals[0], (std::pair<Time, std::string>{Time{0}, "LOGI:SP:050:D7#"}));
  EXPECT_EQ(at_car.arrivals[1],
            (std::pair<Time, std::string>{milliseconds(10), "LOGI:MD:MAN:0C#"}));
  EXPECT_EQ(at_car.arrivals[2],
            (std::pair<Time, std::string>{milliseconds(10), "LOGI:MV:FWD:23#"}));
}

TEST_F(LinkTest, DelayedBytesArriveAtTheExactTime) {
  open("rules:\n  - kind: delay\n    delay: 100ms\n");
  ex.run_until(milliseconds(250));
  client_app->write(to_bytes("LOGI:MV:FWD:23#"));
  ex.run_until_idle();
  ASSERT_EQ(at_car.arrivals.size(), 1u);
  EXPECT_EQ(at_car.arrivals[0].first, milliseconds(350));
}

TEST_F(LinkTest, FaultRulesChangeWhileTheLinkRuns) {
  open();
  client_app->write(to_bytes("LOGI:MV:FWD:23#"));
  ex.run_for(seconds(1));
  link->set_profile(Direction::to_car,
                    parse_fault_profile_text("rules:\n  - kind: drop\n", "live"));
  client_app->write(to_bytes("LOGI:MV:STOP:88#"));
  ex.run_for(seconds(1));
  link->set_profile(Direction::to_car, FaultProfile{});
  client_app->write(to_bytes("LOGI:MV:CW:DC#"));
  ex.run_until_idle();
  EXPECT_EQ(at_car.data, "LOGI:MV:FWD:23#LOGI:MV:CW:DC#");
  ASSERT_EQ(recorder->faults.size(), 1u);
  EXPECT_EQ(recorder->faults[0].kind, link::FaultKind::drop);
  EXPECT_EQ(recorder->faults[0].at, seconds(1));
}

TEST_F(LinkTest, ClientCloseDeliversWhatIsInFlightThenClosesTheCar) {
  open("rules:\n  - kind: delay\n    delay: 100ms\n");
  client_app->write(to_bytes("LOGI:MV:STOP:88#"));
  client_app->close();
  ex.run_until_idle();
  EXPECT_EQ(at_car.data, "LOGI:MV:STOP:88#");
  EXPECT_EQ(at_car.closed, end_of_stream());
  EXPECT_EQ(at_car.closed_at, milliseconds(100));
  ASSERT_TRUE(recorder->close.has_value());
  EXPECT_EQ(recorder->close->by, LinkClose::By::client);
  EXPECT_EQ(recorder->close->mode, CloseMode::graceful);
  EXPECT_FALSE(link->is_open());
}

TEST_F(LinkTest, AClientHalfCloseLetsTheCarAnswerBeforeTheLinkCloses) {
  // 100 ms on the way to the car, 50 ms on the way back: every step has
  // its own instant.
  open("rules:\n  - kind: delay\n    delay: 100ms\n", "rules:\n  - kind: delay\n    delay: 50ms\n",
       true);
  ex.run_until(milliseconds(10));
  client_app->write(to_bytes("LOGI:SP:050:D7#"));
  client_app->shutdown_send();  // the request, then shutdown(SHUT_WR)
  EXPECT_TRUE(client_app->is_open()) << "the client still reads";
  // The car answers 20 ms after it sees the end of the request, then ends.
  at_car.on_end = [&] {
    ex.call_at(ex.now() + milliseconds(20), [&] {
      car_app->write(to_bytes("LOGI:FB:SP:1:35#"));
      car_app->shutdown_send();
    });
  };
  ex.run_until_idle();

  EXPECT_EQ(at_car.data, "LOGI:SP:050:D7#");
  ASSERT_EQ(at_car.arrivals.size(), 1u);
  EXPECT_EQ(at_car.arrivals[0].first, milliseconds(110));
  EXPECT_EQ(at_car.ended_at, milliseconds(110)) << "the end follows the request it held";
  EXPECT_EQ(at_client.data, "LOGI:FB:SP:1:35#");
  ASSERT_EQ(at_client.arrivals.size(), 1u);
  EXPECT_EQ(at_client.arrivals[0].first, milliseconds(180));
  EXPECT_EQ(at_client.ended_at, milliseconds(180));
  // Each end closes once both of its directions have ended.
  EXPECT_EQ(at_car.closed, end_of_stream());
  EXPECT_EQ(at_car.closed_at, milliseconds(130));
  EXPECT_EQ(at_client.closed, end_of_stream());
  EXPECT_EQ(at_client.closed_at, milliseconds(180));

  const std::vector<std::pair<Time, Direction>> half = {{milliseconds(110), Direction::to_car}};
  EXPECT_EQ(recorder->half_closes, half);
  ASSERT_TRUE(recorder->close.has_value());
  EXPECT_EQ(recorder->closed_at, milliseconds(180)) << "not before the car ended too";
  EXPECT_EQ(recorder->close->by, LinkClose::By::client);
  EXPECT_EQ(recorder->close->mode, CloseMode::graceful);
  EXPECT_EQ(recorder->close->reason, "client and car closed");
  EXPECT_FALSE(link->is_open());
}

TEST_F(LinkTest, ASlowCloseHoldsAHalfCloseWhileTheBytesBeforeItPass) {
  open("rules:\n  - kind: slow_close\n    delay: 500ms\n", "rules: []", true);
  client_app->write(to_bytes("LOGI:SP:050:D7#"));
  client_app->shutdown_send();
  at_car.on_end = [&] { car_app->write(to_bytes("LOGI:FB:SP:1:35#")); };
  ex.run_until(milliseconds(499));
  EXPECT_EQ(at_car.data, "LOGI:SP:050:D7#");
  EXPECT_EQ(at_car.ended_at, Time{-1});
  EXPECT_TRUE(recorder->half_closes.empty());
  ex.run_until(milliseconds(600));
  EXPECT_EQ(at_car.ended_at, milliseconds(500));
  const std::vector<std::pair<Time, Direction>> half = {{milliseconds(500), Direction::to_car}};
  EXPECT_EQ(recorder->half_closes, half);
  EXPECT_EQ(at_client.data, "LOGI:FB:SP:1:35#") << "the answer to the end still flows back";
  EXPECT_TRUE(link->is_open());
}

TEST_F(LinkTest, AfterAHalfCloseTheOtherDirectionFlowsUntilItEnds) {
  open("rules: []", "rules: []", true);
  car_app->shutdown_send();  // a car that greets nobody and only answers
  ex.run_until(milliseconds(5));
  EXPECT_EQ(at_client.ended_at, Time{0});
  EXPECT_TRUE(link->is_open());
  for (int i = 1; i <= 3; ++i) {
    client_app->write(to_bytes("LOGI:MV:FWD:23#"));
    ex.run_for(seconds(1));
  }
  EXPECT_EQ(at_car.data, "LOGI:MV:FWD:23#LOGI:MV:FWD:23#LOGI:MV:FWD:23#");
  EXPECT_TRUE(link->is_open());
  EXPECT_FALSE(at_car.closed.has_value());
  client_app->close();  // an outright close ends the rest
  ex.run_until_idle();
  EXPECT_EQ(at_car.closed, end_of_stream());
  EXPECT_EQ(at_car.closed_at, milliseconds(3005));
  ASSERT_TRUE(recorder->close.has_value());
  EXPECT_EQ(recorder->close->by, LinkClose::By::car);
  EXPECT_EQ(recorder->close->reason, "car and client closed");
}

TEST_F(LinkTest, AHalfCloseToACarThatCannotTakeOneClosesTheLinkAsBefore) {
  open();  // the car end has no on_end: a half-close reaches it as a close
  client_app->write(to_bytes("LOGI:SP:050:D7#"));
  client_app->shutdown_send();
  ex.run_until_idle();
  EXPECT_EQ(at_car.data, "LOGI:SP:050:D7#");
  EXPECT_EQ(at_car.closed, end_of_stream());
  EXPECT_EQ(at_car.ended_at, Time{-1});
  EXPECT_TRUE(recorder->half_closes.empty());
  ASSERT_TRUE(recorder->close.has_value());
  EXPECT_EQ(recorder->close->by, LinkClose::By::client);
  EXPECT_EQ(recorder->close->reason, "client closed");
}

TEST_F(LinkTest, AResetDuringAHalfCloseEndsTheLinkAtOnce) {
  open("rules: []", "rules: []", true);
  client_app->write(to_bytes("LOGI:SP:050:D7#"));
  client_app->shutdown_send();
  ex.run_until(milliseconds(10));
  ASSERT_TRUE(link->is_open());
  car_app->close(CloseMode::reset);
  ex.run_until_idle();
  EXPECT_EQ(at_client.closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_EQ(at_client.closed_at, milliseconds(10));
  ASSERT_TRUE(recorder->close.has_value());
  EXPECT_EQ(recorder->close->by, LinkClose::By::car);
  EXPECT_EQ(recorder->close->mode, CloseMode::reset);
}

TEST_F(LinkTest, ResetFaultAbortsBothSides) {
  open("rules: []", "rules:\n  - kind: reset\n    at: 2s\n");
  ex.run_until_idle();
  EXPECT_EQ(at_client.closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_EQ(at_car.closed, std::make_error_code(std::errc::connection_reset));
  EXPECT_EQ(at_client.closed_at, seconds(2));
  ASSERT_TRUE(recorder->close.has_value());
  EXPECT_EQ(recorder->close->by, LinkClose::By::fault);
  EXPECT_EQ(recorder->close->mode, CloseMode::reset);
}

TEST_F(LinkTest, ATimedResetWhoseTimeHasPassedSparesALaterConnection) {
  ex.run_until(Time(seconds(5)));  // a connection made after the rule's time
  open("rules: []", "rules:\n  - kind: reset\n    at: 2s\n");
  ex.run_until(Time(seconds(10)));
  EXPECT_FALSE(at_client.closed.has_value());
  EXPECT_FALSE(at_car.closed.has_value());
  EXPECT_TRUE(recorder->faults.empty());
  EXPECT_TRUE(link->is_open());
}

TEST(LinkSeed, SameSeedSameFaultsUnderTheLink) {
  const auto run_once = [](std::uint64_t seed) {
    VirtualExecutor ex;
    auto [client_app, client_side] = make_mem_pipe(ex, "c");
    auto [car_side, car_app] = make_mem_pipe(ex, "k");
    std::string got;
    car_app->start({[&](ByteView b) { got.append(b.begin(), b.end()); }, {}});
    client_app->start({});
    LinkOptions o;
    o.protocol = protocol_adapter("logi");
    o.to_car = parse_fault_profile_text(
        "rules:\n  - kind: drop\n    probability: 0.5\n  - kind: fragment\n    sizes: [1, 5]\n    "
        "gap: [0ms, 3ms]\n",
        "t");
    o.seed = seed;
    auto link = Link::create(ex, client_side, car_side, o);
    link->start();
    for (int i = 0; i < 40; ++i) {
      client_app->write(to_bytes(i % 2 == 0 ? "LOGI:MV:FWD:23#" : "LOGI:MV:STOP:88#"));
      ex.run_for(milliseconds(50));
    }
    ex.run_until_idle();
    return got;
  };
  EXPECT_EQ(run_once(42), run_once(42));
  EXPECT_NE(run_once(42), run_once(43));
}

}  // namespace
}  // namespace hil::link
