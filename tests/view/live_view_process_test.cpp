// `hil mock logi --view 0` as a user runs it: the page and the event stream
// over real HTTP, the pose following a car logi-client drives, and a fault
// switched on through the API showing on the client's wire.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "tests/view/view_test_support.hpp"

namespace hil::view::test {
namespace {

TEST(LiveViewProcess, ServesThePageAndTheState) {
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  auto c = mock.client();
  const auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->get_header_value("Content-Type").find("text/html"), std::string::npos);
  EXPECT_NE(page->body.find("<canvas id=\"arena\""), std::string::npos);
  EXPECT_NE(page->body.find("new EventSource(\"/events\")"), std::string::npos);
  // No outside scripts, styles or fonts: the page works with no network.
  EXPECT_EQ(page->body.find("src=\"http"), std::string::npos);
  EXPECT_EQ(page->body.find("href=\"http"), std::string::npos);

  const json car = mock.state();
  ASSERT_FALSE(car.is_null());
  EXPECT_EQ(car["arena"]["name"], "warehouse");
  EXPECT_EQ(car["address"], "tcp://127.0.0.1:" + mock.car_port());

  const auto missing = c.Get("/nothing-here");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  const auto empty_post = c.Post("/api/reset", "", "application/json");
  ASSERT_TRUE(empty_post);
  EXPECT_EQ(empty_post->status, 200);
  const auto [status, body] = mock.post("car", {{"x", "left"}});
  EXPECT_EQ(status, 400);
  EXPECT_EQ(body["error"], "'x' must be a number");
}

// Reads server-sent events from /events until `stop` is set; counts them.
void count_events(int port, std::atomic<int>& events, std::atomic<bool>& stop, std::string& last) {
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(10, 0);
  std::string buffer;
  c.Get("/events", [&](const char* data, std::size_t n) {
    buffer.append(data, n);
    for (std::size_t end = buffer.find("\n\n"); end != std::string::npos;
         end = buffer.find("\n\n")) {
      const std::string event = buffer.substr(0, end);
      buffer.erase(0, end + 2);
      if (event.rfind("data: ", 0) == 0) {
        last = event.substr(6);
        ++events;
      }
    }
    return !stop.load();
  });
}

TEST(LiveViewProcess, StreamsUpdatesToSeveralViewersAtOnce) {
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  constexpr int kViewers = 3;
  std::atomic<int> events[kViewers]{};
  std::atomic<bool> stop{false};
  std::string last[kViewers];
  std::vector<std::thread> viewers;
  for (int i = 0; i < kViewers; ++i)
    viewers.emplace_back([&, i] { count_events(mock.view_port(), events[i], stop, last[i]); });
  ASSERT_TRUE(wait_until([&] {
    for (auto& e : events)
      if (e.load() == 0) return false;
    return true;
  }));
  // The view sends 20 updates a second (measured: 20.5 for each of three
  // viewers). The floor asserted is half the 10 a second the page needs, so
  // a loaded machine that delays the timer cannot fail the test, while a
  // stream that stalls or serves one viewer at a time still does.
  const auto start = std::chrono::steady_clock::now();
  int at_start[kViewers];
  for (int i = 0; i < kViewers; ++i)
    at_start[i] = events[i].load();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stop = true;
  for (auto& t : viewers)
    t.join();
  for (int i = 0; i < kViewers; ++i) {
    const double rate = (events[i].load() - at_start[i]) / seconds;
    std::printf("viewer %d: %.1f updates/s\n", i, rate);
    EXPECT_GE(rate, 5.0) << "viewer " << i;
    const json snapshot = json::parse(last[i]);
    EXPECT_EQ(snapshot["viewers"].get<int>(), kViewers);
    EXPECT_EQ(snapshot["cars"][0]["kind"], "logi");
  }
}

TEST(LiveViewProcess, PoseFollowsACarDrivenByLogiClient) {
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  const json before = mock.state();
  const std::string out = mock.drive(
      {"connect", "speed 60", "mode MAN", "press FWD", "wait 1500ms", "release", "wait 300ms"});
  EXPECT_NE(out.find("ok   press FWD"), std::string::npos) << out;
  const json after = mock.state();
  EXPECT_GT(distance_between(after["pose"], before["pose"]), 0.2)
      << before["pose"] << after["pose"];
  EXPECT_GT(after["trail"].size(), 5U);
  // The wire the page shows holds the client's MV:FWD, decoded.
  bool saw_move = false;
  for (const auto& f : after["frames"]["to_car"])
    saw_move = saw_move || f["kind"] == "MV:FWD";
  EXPECT_TRUE(saw_move) << after["frames"]["to_car"];
}

TEST(LiveViewProcess, AFaultSwitchedOnThroughTheApiShowsOnTheClientsWire) {
  ViewedMock mock;
  ASSERT_TRUE(mock.ready()) << mock.process().output();
  std::string out = mock.drive({"connect", "wait 1200ms"});
  EXPECT_EQ(out.find("bad_checksum"), std::string::npos) << out;

  const auto [status, body] = mock.post(
      "faults", {{"profile",
                  "rules:\n  - kind: corrupt\n    direction: to_client\n    target: checksum\n"
                  "    every: 1\n"}});
  ASSERT_EQ(status, 200) << body;
  out = mock.drive({"connect", "wait 1200ms"});
  EXPECT_NE(out.find("bad_checksum"), std::string::npos) << out;
  const json car = mock.state();
  EXPECT_GT(car["faults_injected"].get<int>(), 0);
  ASSERT_FALSE(car["faults"].empty());
  EXPECT_EQ(car["faults"].back()["kind"], "corrupt");

  ASSERT_EQ(mock.post("faults", {{"profile", nullptr}}).first, 200);
  out = mock.drive({"connect", "wait 1200ms"});
  EXPECT_EQ(out.find("bad_checksum"), std::string::npos) << out;
}

}  // namespace
}  // namespace hil::view::test
