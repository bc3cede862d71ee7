// The live view's model under the virtual-time driver: what the page is
// sent about a LOGI car a client drives, what each API request does to the
// car, its world and its link, and the counters GET /metrics serves.

#include "view/live_model.hpp"
#include "view/server.hpp"

#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"

namespace hil::view {
namespace {

using nlohmann::json;
namespace logi = protocol::logi;

// One LOGI car behind a MockServer on mem://, a client connected to it, and
// the model the view would build.
class Desk {
 public:
  explicit Desk(mocks::CarOptions car = {}) : car_(std::move(car)) {
    mocks::ServerOptions options;
    options.listen = link::MemEndpoint{"car"};
    options.observers.push_back(watch_);
    server_ = std::make_unique<mocks::MockServer>(context_, car_.firmware(), std::move(options));
    server_->start();
    model_ = std::make_unique<LiveModel>(
        std::vector<ViewedCar>{ViewedCar{&car_, server_.get(), watch_, {}, {}}});
  }

  void connect() {
    link::connect(
        context_, link::MemEndpoint{"car"}, [this](std::error_code ec, link::BytePipePtr pipe) {
          ASSERT_FALSE(ec);
          client_ = pipe;
          client_->start({[this](protocol::ByteView b) { received_.append(b.begin(), b.end()); },
                          [this](std::error_code) { closed_ = true; }});
        });
    run_for(link::milliseconds(1));
  }
  void disconnect() {
    client_->close(link::CloseMode::graceful);
    run_for(link::milliseconds(50));
  }
  void send(const logi::Message& m) { send_bytes(logi::encode(m)); }
  void send_bytes(const protocol::Bytes& bytes) {
    client_->write(bytes);
    run_for(link::milliseconds(20));
  }
  void run_for(link::Duration d) {
    // The view samples at 20 Hz beside the car.
    const auto end = executor_.now() + d;
    while (executor_.now() < end) {
      executor_.run_until(std::min(end, executor_.now() + link::milliseconds(50)));
      model_->sample();
    }
  }
  json snapshot() const { return model_->snapshot(executor_.now())["cars"][0]; }
  Reply api(std::string_view action, const json& body) {
    return model_->handle(action, body.dump());
  }
  Reply model_handle(std::string_view action, std::string_view body) {
    return model_->handle(action, body);
  }
  std::string take_received() { return std::exchange(received_, {}); }
  const std::string& received() const { return received_; }
  bool closed() const { return closed_; }
  mocks::MockCar& car() { return car_; }
  link::Executor& executor() { return executor_; }
  LiveModel& model() { return *model_; }

 private:
  link::VirtualExecutor executor_;
  link::TransportContext context_{executor_};
  mocks::MockCar car_;
  std::shared_ptr<WireWatch> watch_ = std::make_shared<WireWatch>(car_.firmware().adapter());
  std::unique_ptr<mocks::MockServer> server_;
  std::unique_ptr<LiveModel> model_;
  link::BytePipePtr client_;
  std::string received_;
  bool closed_ = false;
};

TEST(LiveModel, SnapshotDrawsTheWarehouseAndTheCarAtItsStart) {
  Desk desk;
  const json car = desk.snapshot();
  const json& arena = car["arena"];
  EXPECT_EQ(arena["name"], "warehouse");
  EXPECT_DOUBLE_EQ(arena["width"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(arena["height"].get<double>(), 3.0);
  ASSERT_EQ(arena["obstacles"].size(), 2U);
  EXPECT_EQ(arena["obstacles"][0]["name"], "shelf");
  EXPECT_EQ(arena["obstacles"][1]["shape"], "circle");
  ASSERT_EQ(arena["tapes"].size(), 1U);
  EXPECT_TRUE(arena["tapes"][0]["closed"].get<bool>());
  ASSERT_EQ(arena["stations"].size(), 2U);
  EXPECT_EQ(arena["stations"][0]["id"], "001");
  EXPECT_NEAR(car["pose"]["x"].get<double>(), arena["start"]["x"].get<double>(), 1e-6);
  EXPECT_NEAR(car["pose"]["y"].get<double>(), arena["start"]["y"].get<double>(), 1e-6);
  EXPECT_EQ(car["kind"], "logi");
  EXPECT_EQ(car["profile"], "guide") << "the car plays its default profile";
  EXPECT_EQ(car["reply_latency_ms"], 5.0) << "the LOGI profile's processing time";
  EXPECT_FALSE(car["client_connected"].get<bool>());
  // The start pose is on the tape: the middle line sensors see it.
  EXPECT_EQ(car["line"]["sensors"].size(), 4U);
  EXPECT_EQ(car["line"]["mask"], "0110");
  EXPECT_TRUE(car["line"]["sensors"][1]["on_tape"].get<bool>());
  EXPECT_FALSE(car["line"]["sensors"][0]["on_tape"].get<bool>());
  EXPECT_EQ(car["sonar"]["rays"].size(), 5U);
}

TEST(LiveModel, LastFramesEachWayAreDecoded) {
  Desk desk;
  desk.connect();
  desk.send(logi::SetSpeed{50});
  desk.run_for(link::milliseconds(700));
  const json car = desk.snapshot();
  EXPECT_TRUE(car["client_connected"].get<bool>());
  const json& to_car = car["frames"]["to_car"];
  ASSERT_EQ(to_car.size(), 1U);
  EXPECT_EQ(to_car[0]["kind"], "SP");
  EXPECT_TRUE(to_car[0]["valid"].get<bool>());
  EXPECT_NE(to_car[0]["text"].get<std::string>().find("50"), std::string::npos) << to_car[0];
  EXPECT_EQ(to_car[0]["hex"].get<std::string>().substr(0, 11), "4c 4f 47 49");  // "LOGI"
  const json& to_client = car["frames"]["to_client"];
  bool feedback = false;
  bool status = false;
  for (const auto& f : to_client) {
    feedback = feedback || f["kind"] == "FB:SP";
    status = status || f["kind"] == "STAT";
  }
  EXPECT_TRUE(feedback) << to_client;
  EXPECT_TRUE(status) << to_client;
  EXPECT_NE(car["mode"].get<std::string>().find("SP 50"), std::string::npos) << car["mode"];
}

TEST(LiveModel, AWr8LoginStringNeverReachesThePage) {
  mocks::CarOptions options;
  options.kind = mocks::CarKind::wr8;
  const auto profile = options.configs.wr8.profile;
  Desk desk(std::move(options));
  desk.connect();
  namespace wr8 = protocol::wr8;
  const auto login = wr8::encode(wr8::Auth{profile.auth_text}, profile);
  desk.send_bytes(login);
  desk.run_for(link::milliseconds(300));
  const json car = desk.snapshot();
  const json& to_car = car["frames"]["to_car"];
  ASSERT_EQ(to_car.size(), 1U) << to_car;
  EXPECT_EQ(to_car[0]["kind"], "AUTH");
  const std::string secret(profile.auth_text.begin(), profile.auth_text.end());
  EXPECT_EQ(car.dump().find(secret), std::string::npos) << car["frames"];
  EXPECT_NE(to_car[0]["text"].get<std::string>().find("**********"), std::string::npos) << to_car;
  // The hex stays, for whoever debugs the link byte by byte.
  EXPECT_FALSE(to_car[0]["hex"].get<std::string>().empty());
  // Logged in: the car answers and streams DATA.
  EXPECT_GT(car["frames"]["to_client"].size(), 1U) << car["frames"];
}

TEST(LiveViewServer, StopsAtOnceWhenStoppedRightAfterStarting) {
  // hil mock stops the page server as soon as a Ctrl-C arrives, which may
  // be before the server's thread has begun to accept connections. A hang
  // is a cycle that never ends; a cycle is slow only under a sanitizer
  // (each start makes httplib's thread pool: about 0.2 s under GCC's
  // ThreadSanitizer), so each cycle gets its own 10 s.
  constexpr int kCycles = 100;
  Desk desk;
  asio::io_context io;
  std::atomic<int> cycles{0};
  std::thread([&] {
    for (int i = 0; i < kCycles; ++i) {
      ViewOptions options;
      options.port = 0;
      LiveViewServer server(io, desk.executor(), desk.model(), options);
      server.start();
      server.stop();
      ++cycles;
    }
  }).detach();
  int seen = 0;
  auto last_progress = std::chrono::steady_clock::now();
  while (seen < kCycles) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (const int now = cycles.load(); now != seen) {
      seen = now;
      last_progress = std::chrono::steady_clock::now();
    } else if (std::chrono::steady_clock::now() - last_progress > std::chrono::seconds(10)) {
      // The server thread will never end: the process cannot be left cleanly.
      std::fprintf(stderr,
                   "LiveViewServer.stop() right after start() did not return in 10 s (cycle %d)\n",
                   seen + 1);
      std::_Exit(1);
    }
  }
}

// What GET /metrics answered.
struct Scrape {
  int status = 0;
  std::string content_type;
  std::string body;
  std::map<std::string, double> samples;  ///< `name{labels}` -> value
};

// GET /metrics over real HTTP from another thread, while this thread (the
// cars' thread) runs the handlers the server posts to `io`.
Scrape scrape(asio::io_context& io, std::uint16_t port) {
  auto reply = std::async(std::launch::async, [port] {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(10, 0);
    Scrape s;
    if (const auto res = c.Get("/metrics")) {
      s.status = res->status;
      s.content_type = res->get_header_value("Content-Type");
      s.body = res->body;
    }
    return s;
  });
  while (reply.wait_for(std::chrono::milliseconds(1)) != std::future_status::ready) {
    io.restart();
    io.poll();
  }
  Scrape s = reply.get();
  std::istringstream lines(s.body);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.rfind(' ');
    if (space == std::string::npos) continue;
    s.samples[line.substr(0, space)] = std::stod(line.substr(space + 1));
  }
  return s;
}

// How many frames of the car's protocol `bytes` hold.
std::size_t frames_in(mocks::MockCar& car, const std::string& bytes) {
  auto splitter = car.firmware().adapter()->splitter_for(link::Direction::to_client);
  std::vector<link::WireFrame> frames;
  splitter->feed(
      protocol::ByteView(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
      frames);
  return frames.size();
}

TEST(LiveViewServer, MetricsCountWhatAClientSentAndWhatItGot) {
  Desk desk;
  asio::io_context io;
  ViewOptions options;
  options.port = 0;
  LiveViewServer server(io, desk.executor(), desk.model(), options);
  server.start();

  // Before any client: every family, every fault kind, all at zero.
  Scrape s = scrape(io, server.port());
  ASSERT_EQ(s.status, 200) << s.body;
  EXPECT_EQ(s.content_type, base::kPrometheusContentType);
  EXPECT_EQ(s.samples.size(), 2U + 2U + 1U + link::kFaultKindNames.size() + 1U + 1U) << s.body;
  for (const auto& [sample, value] : s.samples)
    EXPECT_EQ(value, 0) << sample;
  EXPECT_NE(s.body.find("# TYPE hil_mock_open_connections gauge"), std::string::npos) << s.body;
  EXPECT_NE(s.body.find("# TYPE hil_mock_faults_total counter"), std::string::npos) << s.body;

  desk.connect();
  // No telemetry, so the car writes only its answers; and every MD frame
  // the client sends is dropped on its way to the car.
  ASSERT_EQ(desk.api("behaviour", {{"action", "stall-telemetry"}, {"duration_ms", 600000}}).status,
            200);
  ASSERT_EQ(desk.api("faults", {{"profile",
                                 "rules:\n  - kind: drop\n    direction: to_car\n    match: MD\n"}})
                .status,
            200);
  desk.run_for(link::milliseconds(10));
  const auto speed_50 = logi::encode(logi::SetSpeed{50});
  const auto speed_60 = logi::encode(logi::SetSpeed{60});
  const std::string bad_checksum = "LOGI:SP:050:D8#";
  desk.send(logi::SetSpeed{50});
  desk.send(logi::SetSpeed{60});
  desk.send_bytes(protocol::Bytes(bad_checksum.begin(), bad_checksum.end()));
  desk.send(logi::SetMode{logi::Mode::manual});
  desk.run_for(link::milliseconds(100));
  const std::string got = desk.received();
  ASSERT_EQ(frames_in(desk.car(), got), 2U) << "FB:SP for each good SP: " << got;

  s = scrape(io, server.port());
  ASSERT_EQ(s.status, 200) << s.body;
  const auto sample = [&](const std::string& key) {
    const auto it = s.samples.find(key);
    EXPECT_NE(it, s.samples.end()) << key << " is missing from\n" << s.body;
    return it == s.samples.end() ? -1.0 : it->second;
  };
  const double sent_to_car =
      static_cast<double>(speed_50.size() + speed_60.size() + bad_checksum.size());
  EXPECT_EQ(sample(R"(hil_mock_bytes_total{car="car0",direction="to_car"})"), sent_to_car);
  EXPECT_EQ(sample(R"(hil_mock_bytes_total{car="car0",direction="to_client"})"),
            static_cast<double>(got.size()));
  EXPECT_EQ(sample(R"(hil_mock_frames_total{car="car0",direction="to_car"})"), 2);
  EXPECT_EQ(sample(R"(hil_mock_frames_total{car="car0",direction="to_client"})"), 2);
  EXPECT_EQ(sample(R"(hil_mock_bad_frames_total{car="car0"})"), 1);
  EXPECT_EQ(sample(R"(hil_mock_faults_total{car="car0",kind="drop"})"), 1);
  EXPECT_EQ(sample(R"(hil_mock_faults_total{car="car0",kind="corrupt"})"), 0);
  EXPECT_EQ(sample(R"(hil_mock_connections_total{car="car0"})"), 1);
  EXPECT_EQ(sample(R"(hil_mock_open_connections{car="car0"})"), 1);

  // The client leaves and another comes: the counters go on, the gauge
  // follows the connection.
  desk.disconnect();
  s = scrape(io, server.port());
  EXPECT_EQ(sample(R"(hil_mock_open_connections{car="car0"})"), 0);
  EXPECT_EQ(sample(R"(hil_mock_connections_total{car="car0"})"), 1);
  desk.connect();
  desk.send(logi::SetMode{logi::Mode::manual});
  s = scrape(io, server.port());
  EXPECT_EQ(sample(R"(hil_mock_open_connections{car="car0"})"), 1);
  EXPECT_EQ(sample(R"(hil_mock_connections_total{car="car0"})"), 2);
  EXPECT_EQ(sample(R"(hil_mock_faults_total{car="car0",kind="drop"})"), 2);
  EXPECT_EQ(sample(R"(hil_mock_bytes_total{car="car0",direction="to_car"})"), sent_to_car);
  server.stop();
}

TEST(LiveModel, PoseAndTrailFollowADrivenCar) {
  Desk desk;
  desk.connect();
  desk.send(logi::SetMode{logi::Mode::manual});
  desk.send(logi::SetSpeed{60});
  const json before = desk.snapshot();
  desk.send(logi::Move{logi::Direction::fwd});
  desk.run_for(link::seconds(1));
  const json after = desk.snapshot();
  const double moved =
      std::hypot(after["pose"]["x"].get<double>() - before["pose"]["x"].get<double>(),
                 after["pose"]["y"].get<double>() - before["pose"]["y"].get<double>());
  EXPECT_GT(moved, 0.1);
  EXPECT_GT(after["telemetry"]["speed_mps"].get<double>(), 0.05);
  EXPECT_GT(after["trail"].size(), 5U);
  EXPECT_GT(after["trail"].size(), before["trail"].size());
}

TEST(LiveModel, FaultRulesTakeEffectOnTheWireAndTurnOff) {
  Desk desk;
  desk.connect();
  const Reply on = desk.api("faults", {{"profile",
                                        "rules:\n  - kind: corrupt\n    direction: to_client\n"
                                        "    target: checksum\n    every: 1\n"}});
  ASSERT_EQ(on.status, 200) << on.body;
  EXPECT_EQ(on.body["rules"][0]["kind"], "corrupt");
  desk.run_for(link::milliseconds(1100));  // two STATs
  json car = desk.snapshot();
  EXPECT_EQ(car["fault_rules"].size(), 1U);
  EXPECT_GE(car["faults_injected"].get<int>(), 2);
  ASSERT_FALSE(car["faults"].empty());
  EXPECT_EQ(car["faults"][0]["kind"], "corrupt");
  EXPECT_EQ(car["faults"][0]["direction"], "to_client");
  ASSERT_FALSE(car["frames"]["to_client"].empty());
  EXPECT_FALSE(car["frames"]["to_client"].back()["valid"].get<bool>());

  // A JSON object works as well as YAML text; null turns faults off.
  const Reply off = desk.api("faults", {{"profile", nullptr}});
  ASSERT_EQ(off.status, 200) << off.body;
  const auto injected = desk.snapshot()["faults_injected"].get<int>();
  desk.run_for(link::milliseconds(1100));
  car = desk.snapshot();
  EXPECT_TRUE(car["fault_rules"].empty());
  EXPECT_EQ(car["faults_injected"].get<int>(), injected);
  EXPECT_TRUE(car["frames"]["to_client"].back()["valid"].get<bool>());

  const Reply as_json = desk.api(
      "faults", {{"profile", {{"rules", {{{"kind", "drop"}, {"direction", "to_client"}}}}}}});
  ASSERT_EQ(as_json.status, 200) << as_json.body;
  desk.take_received();
  desk.run_for(link::milliseconds(1100));
  EXPECT_EQ(desk.take_received(), "");
}

TEST(LiveModel, BehavioursDropTheLinkRejectAndStallTelemetry) {
  Desk desk;
  desk.connect();
  ASSERT_EQ(desk.api("behaviour", {{"action", "reject-next"}, {"match", "SP"}}).status, 200);
  desk.take_received();
  desk.send(logi::SetSpeed{40});
  EXPECT_NE(desk.take_received().find("FB:SP:0"), std::string::npos);
  desk.send(logi::SetSpeed{40});
  EXPECT_NE(desk.take_received().find("FB:SP:1"), std::string::npos);

  ASSERT_EQ(desk.api("behaviour", {{"action", "stall-telemetry"}, {"duration_ms", 2000}}).status,
            200);
  desk.run_for(link::milliseconds(10));
  desk.take_received();
  desk.run_for(link::milliseconds(1900));
  EXPECT_EQ(desk.take_received().find("STAT"), std::string::npos);
  desk.run_for(link::milliseconds(700));
  EXPECT_NE(desk.take_received().find("STAT"), std::string::npos);

  ASSERT_EQ(desk.api("behaviour", {{"action", "fault"}}).status, 200);
  desk.run_for(link::milliseconds(10));
  EXPECT_TRUE(desk.snapshot()["in_fault"].get<bool>());
  ASSERT_EQ(desk.api("behaviour", {{"action", "clear-fault"}}).status, 200);
  desk.run_for(link::milliseconds(10));
  EXPECT_FALSE(desk.snapshot()["in_fault"].get<bool>());

  EXPECT_FALSE(desk.closed());
  ASSERT_EQ(desk.api("behaviour", {{"action", "drop-link"}}).status, 200);
  desk.run_for(link::milliseconds(100));
  EXPECT_TRUE(desk.closed());
  EXPECT_FALSE(desk.snapshot()["client_connected"].get<bool>());
}

TEST(LiveModel, MovesTheCarAndObstaclesAndResetsTheArena) {
  Desk desk;
  ASSERT_EQ(desk.api("car", {{"x", 1.0}, {"y", 1.0}, {"heading_deg", 90}}).status, 200);
  json car = desk.snapshot();
  EXPECT_NEAR(car["pose"]["x"].get<double>(), 1.0, 1e-6);
  EXPECT_NEAR(car["pose"]["heading_deg"].get<double>(), 90.0, 1e-3);

  const Reply added = desk.api("obstacle", {{"x", 3.5}, {"y", 2.5}});
  ASSERT_EQ(added.status, 200) << added.body;
  const auto parcel = added.body["index"].get<int>();
  EXPECT_EQ(parcel, 2);
  const Reply moved = desk.api("obstacle", {{"op", "move"}, {"index", 0}, {"x", 1.0}, {"y", 2.5}});
  ASSERT_EQ(moved.status, 200) << moved.body;
  car = desk.snapshot();
  ASSERT_EQ(car["arena"]["obstacles"].size(), 3U);  // pillar, parcel, shelf in its new place
  bool shelf_moved = false;
  for (const auto& o : car["arena"]["obstacles"])
    shelf_moved = shelf_moved || (o["name"] == "shelf" && o["x"] == 1.0 && o["y"] == 2.5);
  EXPECT_TRUE(shelf_moved) << car["arena"]["obstacles"];
  ASSERT_EQ(desk.api("obstacle", {{"op", "remove"}, {"index", parcel}}).status, 200);
  EXPECT_EQ(desk.snapshot()["arena"]["obstacles"].size(), 2U);

  ASSERT_EQ(desk.api("reset", json::object()).status, 200);
  car = desk.snapshot();
  // The shelf is back where the world file put it (under a new index).
  ASSERT_EQ(car["arena"]["obstacles"].size(), 2U);
  bool shelf_home = false;
  for (const auto& o : car["arena"]["obstacles"])
    shelf_home = shelf_home || (o["name"] == "shelf" && o["x"] == 2.0 && o["y"] == 1.5);
  EXPECT_TRUE(shelf_home) << car["arena"]["obstacles"];
  EXPECT_NEAR(car["pose"]["x"].get<double>(), car["arena"]["start"]["x"].get<double>(), 1e-6);
  EXPECT_TRUE(car["trail"].size() <= 1U);
}

TEST(LiveModel, BadRequestsAnswer400SayingWhatWasWrong) {
  Desk desk;
  struct Case {
    std::string action;
    std::string body;
    int status;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"car", "not json", 400, "not valid JSON"},
      {"car", "[1, 2]", 400, "JSON object"},
      {"car", R"({"x": "a"})", 400, "'x' must be a number"},
      {"car", R"({"x": 9, "y": 1})", 400, "inside the arena"},
      {"car", R"({"car": 1})", 400, "'car' must be a car number from 0 to 0"},
      {"faults", "{}", 400, "'profile' is missing"},
      {"faults", R"({"profile": 3})", 400, "'profile' must be"},
      {"faults", R"({"profile": "rules:\n  - kind: drop\n    probability: 2\n"})", 400,
       "profile:3:18: rule 1 (drop): 'probability' must be a number in [0, 1]"},
      {"faults", R"({"profile": "rules: [ {kind: explode} ]"})", 400, "explode"},
      {"faults", R"({"profile": "rules: [ unclosed"})", 400, "profile"},
      {"behaviour", R"({"action": "explode"})", 400, "'action' must be one of"},
      {"behaviour", R"({"action": "stall-telemetry", "duration_ms": -1})", 400, "duration_ms"},
      {"behaviour", R"({"action": "reject-next", "count": 1.5})", 400, "'count'"},
      {"behaviour", R"({"yaml": "- at: nonsense"})", 400, "behaviour"},
      {"obstacle", R"({"op": "add"})", 400, "'x' and 'y'"},
      {"obstacle", R"({"op": "add", "x": 1, "y": 1, "width": 0})", 400, "above 0"},
      {"obstacle", R"({"op": "add", "x": 1, "y": 1, "shape": "star"})", 400, "'shape'"},
      {"obstacle", R"({"op": "move", "index": 7})", 400, "'index'"},
      {"obstacle", R"({"op": "spin"})", 400, "'op'"},
      {"launch", "{}", 404, "no such action 'launch'"},
  };
  for (const auto& c : cases) {
    const Reply r = desk.model_handle(c.action, c.body);
    EXPECT_EQ(r.status, c.status) << c.action << " " << c.body << " -> " << r.body;
    ASSERT_TRUE(r.body.contains("error")) << c.action << " " << c.body;
    EXPECT_NE(r.body["error"].get<std::string>().find(c.says), std::string::npos)
        << c.action << " " << c.body << " -> " << r.body["error"];
  }
  // Nothing changed.
  EXPECT_EQ(desk.snapshot()["arena"]["obstacles"].size(), 2U);
}

}  // namespace
}  // namespace hil::view
