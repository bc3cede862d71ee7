// The WR8 client session against the mock WR8 vehicle over real TCP
// (tcp://127.0.0.1:0) under the real-time driver; bounded waits only.

#include <gtest/gtest.h>

#include <vector>

#include "client/wr8/session.hpp"
#include "mocks/wr8.hpp"
#include "sim/presets.hpp"
#include "tests/client/tcp_session.hpp"

namespace hil::client::wr8 {
namespace {

TEST(Wr8SessionTcp, LogsInReadsDataAndCompletesATurnOverRealTcp) {
  test::SessionOverTcp<Wr8Session, mocks::Wr8Firmware, Event> tcp(sim::wr8_vehicle());
  ASSERT_TRUE(tcp.connect());
  ASSERT_TRUE(tcp.run_until([&] { return tcp.session.core().live().has_value(); }));
  EXPECT_EQ(tcp.session.core().live()->battery_percent, 100.0);

  const auto r = tcp.session.turn(10);
  ASSERT_TRUE(r);
  auto final_state = [&]() -> std::optional<RequestState> {
    for (const auto& e : tcp.events) {
      const auto* q = std::get_if<RequestEvent>(&e);
      if (q && q->coi == r.coi && q->state != RequestState::sent &&
          q->state != RequestState::started)
        return q->state;
    }
    return std::nullopt;
  };
  ASSERT_TRUE(tcp.run_until([&] { return final_state().has_value(); }));
  EXPECT_EQ(final_state(), RequestState::completed);
  EXPECT_NEAR(tcp.car.firmware.state().commanded_wheel_angle_deg, 10.0, 1e-9);
  EXPECT_FALSE(tcp.session.core().log()->to_string(client::LogFormat::ndjson).empty());
}

}  // namespace
}  // namespace hil::client::wr8
