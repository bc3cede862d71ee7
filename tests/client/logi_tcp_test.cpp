// The LOGI client session against the mock LOGI car over real TCP
// (tcp://127.0.0.1:0) under the real-time driver; bounded waits only.

#include <gtest/gtest.h>

#include <vector>

#include "client/logi/session.hpp"
#include "mocks/logi.hpp"
#include "sim/presets.hpp"
#include "tests/client/tcp_session.hpp"

namespace hil::client::logi {
namespace {

using proto::Direction;
using proto::Mode;

TEST(LogiSessionTcp, DrivesTheMockCarOverRealTcpAndNoticesItsLoss) {
  test::SessionOverTcp<LogiSession, mocks::LogiFirmware, Event> tcp(sim::logi_car());
  ASSERT_TRUE(tcp.connect());

  auto accepted = [&](RequestId id) {
    for (const auto& e : tcp.events) {
      const auto* c = std::get_if<CommandEvent>(&e);
      if (c && c->request == id && c->state == CommandState::accepted) return true;
    }
    return false;
  };
  tcp.session.submit(proto::SetSpeed{40});
  const auto md = tcp.session.submit(proto::SetMode{Mode::manual});
  ASSERT_TRUE(tcp.run_until([&] { return accepted(md.request); }));
  const auto mv = tcp.session.press(Direction::fwd);
  ASSERT_TRUE(mv);
  ASSERT_TRUE(tcp.run_until([&] {
    const auto& s = tcp.session.core().last_status();
    return accepted(mv.request) && s && s->mode == Mode::manual && s->manual == Direction::fwd;
  }));
  tcp.session.release();
  ASSERT_TRUE(tcp.run_until([&] {
    const auto& s = tcp.session.core().last_status();
    return s && s->manual == Direction::stop && tcp.session.core().in_flight() == 0;
  }));
  EXPECT_EQ(tcp.car.firmware.state().manual, Direction::stop);

  // The car goes away: the client enters the safe state and waits to reconnect.
  tcp.car.server.close();
  ASSERT_TRUE(tcp.run_until([&] {
    return tcp.session.core().state() == ConnectionState::reconnecting ||
           tcp.session.core().state() == ConnectionState::connecting;
  }));
  EXPECT_FALSE(tcp.session.core().movement_enabled());
  EXPECT_EQ(tcp.session.press(Direction::fwd).refusal, Refusal::not_connected);

  tcp.session.disconnect();
  EXPECT_EQ(tcp.session.core().state(), ConnectionState::disconnected);
  const std::string log = tcp.session.log()->to_string(client::LogFormat::txt);
  EXPECT_NE(log.find("TX   LOGI:MV:FWD:23#"), std::string::npos) << log;
  EXPECT_NE(log.find("RX   LOGI:FB:MV:1:"), std::string::npos) << log;
}

}  // namespace
}  // namespace hil::client::logi
