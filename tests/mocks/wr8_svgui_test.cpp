// The WR8 vehicle as the real smart_vehicle_gui programs play it (profiles
// svgui-2019 and svgui-head) under the virtual-time driver: the length byte,
// the programs' way of reading, logins, DATA rates and timestamps, tasks and
// the busy rule, settings as the v2019 vehicle reads them, CONTROL, SET and
// MAP, with the real programs' bytes as vectors and exact times.

#include "mocks/wr8_svgui.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mocks/car.hpp"
#include "protocol/common/car_profile.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks {
namespace {

using link::milliseconds;
using link::seconds;
using protocol::Bytes;
using ::testing::ElementsAre;

using Car = test::VirtualCar<SvguiFirmware>;

using test::ms_of;

Bytes text_bytes(std::string_view text) {
  return Bytes(text.begin(), text.end());
}

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts)
    out.insert(out.end(), p.begin(), p.end());
  return out;
}

/// The v2019 GUI's AUTH: length 0x0B, code 1, the ten letters.
const Bytes kAuth2019 = cat({{0x0B, 0x01}, text_bytes("konnichiwa")});
/// The head GUI's AUTH: length 0x0C, code 1, the letters and a NUL.
const Bytes kAuthHead = cat({{0x0C, 0x01}, text_bytes("konnichiwa"), {0x00}});
/// Both vehicles' only AUTH-REPLY: device 1, id 2, state 3 (WAIT).
const Bytes kAuthReply = {0x04, 0x02, 0x01, 0x02, 0x03};

/// One packet the GUI received (its length byte included) and when.
struct Received {
  std::int64_t at_ms = 0;
  Bytes raw;
  svgui::Message message;
};

SvguiConfig config_of(svgui::Version version) {
  SvguiConfig config;
  config.version = version;
  return config;
}

/// A real-program vehicle on mem:// and a GUI connected to it at 1 ms,
/// decoding what the vehicle sends by the length byte.
class Gui {
 public:
  explicit Gui(SvguiConfig config)
      : version_(*config.version),
        car_(sim::wr8_vehicle(),
             [config](sim::World& w, sim::Vehicle& v) {
               return std::make_unique<SvguiFirmware>(w, v, config);
             }),
        decoder_(version_) {
    // The profile's reply latency, as `hil mock` and `hil run` give it.
    car_.firmware().set_reply_latency(std::chrono::duration_cast<Duration>(
        protocol::find_car_profile("wr8", svgui::profile_of(version_)).reply_latency));
    client_ = car_.connect();
  }
  explicit Gui(svgui::Version version) : Gui(config_of(version)) {}

  void send_bytes(const Bytes& bytes) {
    client_->write(protocol::ByteView(bytes));
    run_until(car_.now());
  }
  void send(const svgui::Message& m) { send_bytes(svgui::encode_prefixed(m, version_)); }

  void run_until(Time t) {
    car_.run_until_each(t, [this] { collect(); });
  }
  void run_for(Duration d) { run_until(car_.now() + d); }

  std::vector<Received> take() { return std::exchange(log_, {}); }
  template <class T>
  std::vector<std::pair<std::int64_t, T>> take_of() {
    std::vector<std::pair<std::int64_t, T>> out;
    for (const Received& r : take()) {
      if (const auto* m = std::get_if<T>(&r.message)) out.emplace_back(r.at_ms, *m);
    }
    return out;
  }

  Time now() const { return car_.now(); }
  SvguiFirmware& fw() { return car_.firmware(); }
  const SvguiState& state() { return car_.firmware().state(); }
  sim::Vehicle& vehicle() { return car_.vehicle(); }
  sim::AckermannChassis& chassis() { return *car_.vehicle().ackermann(); }
  test::ClientEnd& client() { return *client_; }

 private:
  void collect() {
    const Bytes bytes = client_->take();
    test::decode_frames<svgui::Message>(
        decoder_, bytes,
        "the vehicle sent bytes its GUI cannot decode: ", [this](const auto& frame) {
          log_.push_back(Received{ms_of(car_.now()), frame.raw, frame.message});
        });
  }

  svgui::Version version_;
  Car car_;
  std::shared_ptr<test::ClientEnd> client_;
  svgui::Decoder decoder_;
  std::vector<Received> log_;
};

Bytes task_2019(std::uint8_t coi, std::uint8_t type, std::vector<std::int32_t> params) {
  return svgui::encode_prefixed(svgui::Task{coi, type, std::move(params)}, svgui::Version::v2019);
}

// ---------------------------------------------------------------- profiles

TEST(Wr8SvguiProfiles, EachProfileBuildsItsVehicleAndListensOnTheRealPort) {
  FirmwareConfigs configs;
  apply_profile(configs, CarKind::wr8, "svgui-2019");
  EXPECT_EQ(configs.svgui.version, svgui::Version::v2019);
  apply_profile(configs, CarKind::wr8, "svgui-head");
  EXPECT_EQ(configs.svgui.version, svgui::Version::head);
  sim::World world{sim::WorldDef{}};
  sim::Vehicle& vehicle = world.add_vehicle(sim::wr8_vehicle());
  const auto head = make_firmware(CarKind::wr8, world, vehicle, configs);
  EXPECT_EQ(head->profile(), "svgui-head");
  EXPECT_EQ(head->reply_latency(), milliseconds(1));

  apply_profile(configs, CarKind::wr8, "document");
  EXPECT_FALSE(configs.svgui.version.has_value());
  EXPECT_NE(dynamic_cast<Wr8Firmware*>(make_firmware(CarKind::wr8, world, vehicle, configs).get()),
            nullptr);
  EXPECT_THROW(apply_profile(configs, CarKind::wr8, "svgui-2020"), protocol::ProfileError);

  // Both real programs listen on 5556; hil's own WR8 port stays 9100.
  EXPECT_EQ(std::get<link::TcpEndpoint>(default_endpoint(CarKind::wr8, 0, "svgui-head")).port,
            5556);
  EXPECT_EQ(std::get<link::TcpEndpoint>(default_endpoint(CarKind::wr8, 2, "svgui-2019")).port,
            5558);
  EXPECT_EQ(std::get<link::TcpEndpoint>(default_endpoint(CarKind::wr8, 1)).port, 9101);
}

TEST(Wr8SvguiProfiles, AConfigThatCannotWorkIsRefusedNamingTheField) {
  sim::World world{sim::WorldDef{}};
  sim::Vehicle& vehicle = world.add_vehicle(sim::wr8_vehicle());
  EXPECT_THAT([&] { (void)SvguiFirmware(world, vehicle, SvguiConfig{}); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  ::testing::HasSubstr("SvguiConfig: version must be set")));
  SvguiConfig config = config_of(svgui::Version::head);
  config.high_freq_period = Duration::zero();
  EXPECT_THAT([&] { (void)SvguiFirmware(world, vehicle, config); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  ::testing::HasSubstr("high_freq_period must be positive")));
  sim::World other{sim::WorldDef{}};
  sim::Vehicle& robot = other.add_vehicle(sim::arduino_robot());
  EXPECT_THAT([&] { (void)SvguiFirmware(other, robot, config_of(svgui::Version::v2019)); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  ::testing::HasSubstr("has no Ackermann chassis")));
}

// ---------------------------------------------------------------- login

TEST(Wr8SvguiLogin, TheHeadGuisAuthIsAnsweredWithTheFixedReplyThenTheMap) {
  Gui gui(svgui::Version::head);
  gui.send_bytes(kAuthHead);
  gui.run_for(milliseconds(2));
  const auto got = gui.take();
  std::vector<Received> replies;
  for (const auto& r : got) {
    if (!std::holds_alternative<svgui::HighFreqData>(r.message)) replies.push_back(r);
  }
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[0].raw, kAuthReply);
  EXPECT_EQ(replies[0].at_ms, 2);  // sent at 1 ms, 1 ms of reply latency
  const auto* map = std::get_if<svgui::Map>(&replies[1].message);
  ASSERT_NE(map, nullptr);
  EXPECT_EQ(replies[1].at_ms, 2);
  EXPECT_EQ(gui.state().logins, 1u);
  EXPECT_EQ(gui.state().maps_sent, 1u);
}

TEST(Wr8SvguiLogin, TheV2019GuisAuthIsAnsweredAndTheHeadFormIsNot) {
  Gui gui(svgui::Version::v2019);
  gui.send_bytes(kAuth2019);
  gui.run_for(milliseconds(1));
  auto got = gui.take();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].raw, kAuthReply);

  // v2019 reads an AUTH only with the length byte 11: the head GUI's form
  // (12, a NUL at the end) is no login there.
  gui.send_bytes(kAuthHead);
  gui.run_for(seconds(1));
  EXPECT_TRUE(gui.take_of<svgui::AuthReply>().empty());
  EXPECT_FALSE(gui.client().closed.has_value());
  EXPECT_EQ(gui.state().logins, 1u);
  EXPECT_EQ(gui.state().unusable_reads, 1u);
}

TEST(Wr8SvguiLogin, AWrongLoginIsNotAnsweredAndTheConnectionStaysOpen) {
  for (const auto version : {svgui::Version::v2019, svgui::Version::head}) {
    SCOPED_TRACE(std::string(svgui::to_string(version)));
    Gui gui(version);
    const Bytes wrong = version == svgui::Version::v2019
                            ? cat({{0x0B, 0x01}, text_bytes("sayonara!!")})
                            : cat({{0x0C, 0x01}, text_bytes("sayonara!!"), {0x00}});
    gui.send_bytes(wrong);
    gui.run_for(seconds(10));
    EXPECT_TRUE(gui.take_of<svgui::AuthReply>().empty());
    EXPECT_FALSE(gui.client().closed.has_value());
    EXPECT_EQ(gui.state().refused_logins, 1u);
    // A right login on the same connection is then answered.
    gui.send_bytes(version == svgui::Version::v2019 ? kAuth2019 : kAuthHead);
    gui.run_for(milliseconds(1));
    EXPECT_EQ(gui.take_of<svgui::AuthReply>().size(), 1u);
  }
}

TEST(Wr8SvguiLogin, HeadTakesAnyTextEndingInTheWordUpToItsFirstNul) {
  Gui gui(svgui::Version::head);
  // Code 1, "hello konnichiwa", a NUL, then bytes the comparison never sees.
  const Bytes auth = cat({{0x14, 0x01}, text_bytes("hello konnichiwa"), {0x00, 'x', 'y'}});
  gui.send_bytes(auth);
  gui.run_for(milliseconds(1));
  EXPECT_EQ(gui.take_of<svgui::AuthReply>().size(), 1u);
}

// ---------------------------------------------------------------- DATA

TEST(Wr8SvguiData, HeadStreamsHighFreqEvery50msAndLowFreqEverySecondBeforeAnyLogin) {
  Gui gui(svgui::Version::head);
  gui.run_until(Time(milliseconds(2002)));
  const auto got = gui.take();
  std::vector<std::int64_t> high;
  std::vector<std::int64_t> low;
  for (const auto& r : got) {
    if (std::holds_alternative<svgui::HighFreqData>(r.message)) {
      high.push_back(r.at_ms);
      EXPECT_EQ(r.raw.size(), 66u);  // the length byte 0x41 and 65 bytes
      EXPECT_EQ(r.raw[0], 0x41);
    } else if (std::holds_alternative<svgui::LowFreqData>(r.message)) {
      low.push_back(r.at_ms);
      EXPECT_EQ(r.raw.size(), 35u);  // 0x22 and 34 bytes
      EXPECT_EQ(r.raw[0], 0x22);
    } else {
      ADD_FAILURE() << "unexpected packet before a login";
    }
  }
  ASSERT_EQ(high.size(), 40u);  // ticks 50 .. 2000 ms, each out 1 ms later
  EXPECT_EQ(high.front(), 51);
  EXPECT_EQ(high[1], 101);
  EXPECT_EQ(high.back(), 2001);
  EXPECT_THAT(low, ElementsAre(1001, 2001));
  EXPECT_EQ(gui.state().logins, 0u);
}

TEST(Wr8SvguiData, TimestampsAreMillisecondsSinceLocalMidnight) {
  SvguiConfig config = config_of(svgui::Version::head);
  config.time_of_day_at_start =
      std::chrono::hours(23) + std::chrono::minutes(59) + seconds(59) + milliseconds(990);
  Gui gui(config);
  gui.run_until(Time(milliseconds(101)));
  const auto high = gui.take_of<svgui::HighFreqData>();
  ASSERT_EQ(high.size(), 2u);
  // 23:59:59.990 + 50 ms is 00:00:00.040 the next day.
  EXPECT_EQ(high[0].second.timestamp_ms, 86'399'990u + 50 - 86'400'000u);
  EXPECT_EQ(high[1].second.timestamp_ms, 90u);
  EXPECT_EQ(gui.fw().timestamp_ms(Time(milliseconds(10))), 0u);
}

TEST(Wr8SvguiData, V2019SendsItsFortyTwoByteDataOnTheConfiguredPeriod) {
  Gui gui(svgui::Version::v2019);
  gui.run_until(Time(milliseconds(301)));
  const auto got = gui.take();
  ASSERT_EQ(got.size(), 3u);
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].at_ms, 101 + 100 * static_cast<std::int64_t>(k));
    EXPECT_EQ(got[k].raw.size(), 43u);
    EXPECT_EQ(got[k].raw[0], 0x2A);
    EXPECT_EQ(got[k].raw[1], 0x06);
    const auto& data = std::get<svgui::Data>(got[k].message);
    EXPECT_EQ(data.state, protocol::wr8::State::wait);
    EXPECT_EQ(data.timestamp_ms, 100u * (k + 1));
    EXPECT_EQ(data.motor_battery, 100u);
  }
  SvguiConfig silent = config_of(svgui::Version::v2019);
  silent.v2019_data_period = Duration::zero();  // as the repository's console test car
  Gui quiet(silent);
  quiet.run_for(seconds(1));
  EXPECT_TRUE(quiet.take().empty());
}

// ---------------------------------------------------------------- reading

TEST(Wr8SvguiReading, HeadReadsOnePacketPerArrivalAndRunsOneBehind) {
  Gui gui(svgui::Version::head);
  gui.run_until(Time(milliseconds(10)));
  // AUTH and SET-REQUEST in one write: one read event, one packet.
  gui.send_bytes(
      cat({kAuthHead, svgui::encode_prefixed(svgui::SetRequest{}, svgui::Version::head)}));
  gui.run_for(milliseconds(1));
  EXPECT_EQ(gui.take_of<svgui::AuthReply>().size(), 1u);
  EXPECT_EQ(gui.fw().state().logins, 1u);
  // The SET-REQUEST waits unread until more bytes arrive.
  gui.run_for(milliseconds(30));
  EXPECT_TRUE(gui.take_of<svgui::Set>().empty());
  // A CONTROL arrives: its read event takes the SET-REQUEST, and the
  // CONTROL waits in its turn.
  gui.send(svgui::Control{0.0, 0.5});
  gui.run_for(milliseconds(1));
  EXPECT_EQ(gui.take_of<svgui::Set>().size(), 1u);
  EXPECT_FALSE(gui.state().control.has_value());
}

TEST(Wr8SvguiReading, V2019ReadsEverythingThatArrivedAsOnePacket) {
  Gui gui(svgui::Version::v2019);
  // Two tasks in one write: the program reads the first and never the second.
  gui.send_bytes(cat({task_2019(5, 3, {}), task_2019(0, 3, {})}));
  EXPECT_EQ(gui.state().current_coi, 5);
  EXPECT_EQ(gui.state().length_mismatches, 1u);
  EXPECT_EQ(gui.state().dropped_busy, 0u);
}

TEST(Wr8SvguiReading, LengthBytesNoProgramCanReadAreDroppedWithoutAnAnswer) {
  Gui gui(svgui::Version::head);
  gui.send_bytes({0x80, 0x01, 0x02});  // a body of 128 bytes: negative as a signed char
  gui.send_bytes({0x00});
  EXPECT_EQ(gui.state().unusable_reads, 2u);
  EXPECT_EQ(gui.state().logins, 0u);
  EXPECT_FALSE(gui.client().closed.has_value());
}

// ---------------------------------------------------------------- v2019 tasks

TEST(Wr8SvguiV2019, AForwardTaskDrivesAndIsAnsweredOnlyWhenDone) {
  Gui gui(svgui::Version::v2019);
  gui.send_bytes({0x08, 0x03, 0x05, 0x01, 0x01, 0x32, 0x00, 0x00, 0x00});  // COI 5, forward 50 cm
  EXPECT_EQ(gui.state().task, SvguiState::Task::forward);
  gui.run_for(milliseconds(200));
  EXPECT_TRUE(gui.take_of<svgui::Answer>().empty());  // no "started"
  gui.run_for(seconds(10));
  const auto answers = gui.take();
  std::vector<Bytes> raw;
  for (const auto& r : answers) {
    if (std::holds_alternative<svgui::Answer>(r.message)) raw.push_back(r.raw);
  }
  ASSERT_EQ(raw.size(), 1u);
  EXPECT_EQ(raw[0], (Bytes{0x03, 0x05, 0x05, 0x02}));  // COI 5, done
  EXPECT_NEAR(gui.vehicle().odometry().distance_m, 0.50, 0.01);
  EXPECT_EQ(gui.state().current_coi, 0);
}

TEST(Wr8SvguiV2019, ABusyCarDropsTasksAndSettingsWithoutAReply) {
  Gui gui(svgui::Version::v2019);
  gui.send_bytes(task_2019(5, 1, {100}));
  gui.run_for(milliseconds(100));
  gui.send_bytes(task_2019(6, 3, {}));
  gui.send(svgui::Settings{7, {1, 2, 3, 90}});
  EXPECT_EQ(gui.state().dropped_busy, 2u);
  gui.run_for(seconds(10));
  const auto answers = gui.take_of<svgui::Answer>();
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_EQ(answers[0].second, (svgui::Answer{5, 2}));
}

TEST(Wr8SvguiV2019, ATaskWithCoiZeroNeverMakesTheCarBusy) {
  Gui gui(svgui::Version::v2019);
  gui.send_bytes(task_2019(0, 3, {}));  // turn signals, COI 0
  EXPECT_EQ(gui.state().task, SvguiState::Task::signals);
  gui.send_bytes(task_2019(7, 2, {10}));  // taken at once: the car is idle by its COI
  EXPECT_EQ(gui.state().dropped_busy, 0u);
  EXPECT_EQ(gui.state().current_coi, 7);
  gui.run_for(seconds(3));
  const auto answers = gui.take_of<svgui::Answer>();
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_EQ(answers[0].second, (svgui::Answer{7, 2}));
  EXPECT_NEAR(sim::rad_to_deg(gui.chassis().steering_rad()), 10, 1e-9);
}

TEST(Wr8SvguiV2019, ATypeWithoutAnActionLeavesTheCarBusyForGood) {
  Gui gui(svgui::Version::v2019);
  gui.send_bytes(task_2019(9, 4, {}));
  gui.run_for(seconds(5));
  EXPECT_TRUE(gui.take_of<svgui::Answer>().empty());
  gui.send_bytes(task_2019(10, 3, {}));
  EXPECT_EQ(gui.state().current_coi, 9);
  EXPECT_EQ(gui.state().dropped_busy, 1u);
}

TEST(Wr8SvguiV2019, SettingsAreReadAtTheVehiclesOffsetsNotTheGuis) {
  Gui gui(svgui::Version::v2019);
  // The GUI writes COI 4 then p, i, d, servo zero as int32 LE: 18 bytes.
  const Bytes settings =
      svgui::encode_prefixed(svgui::Settings{4, {1, 2, 3, 90}}, svgui::Version::v2019);
  ASSERT_EQ(settings,
            (Bytes{0x12, 0x04, 0x04, 0x01, 0, 0, 0, 0x02, 0, 0, 0, 0x03, 0, 0, 0, 0x5A, 0, 0, 0}));
  gui.send_bytes(settings);
  gui.run_for(seconds(1));
  EXPECT_TRUE(gui.take_of<svgui::Answer>().empty());  // never answered
  // The vehicle reads at bytes 2, 7, 12 and 17: p right, then d's first
  // byte as i's top byte (3 -> 50331648), servo zero's 90 in d
  // (5898240), and past the packet for servo zero.
  EXPECT_THAT(gui.state().v2019_settings, ElementsAre(1, 50331648, 5898240, 0));
  EXPECT_EQ(gui.state().current_coi, 4);  // and busy from now on
}

// ---------------------------------------------------------------- head

TEST(Wr8SvguiHead, ControlDrivesAndSteersAndTheWatchdogStopsTheCar) {
  Gui gui(svgui::Version::head);
  for (int k = 0; k < 20; ++k) {  // 10 Hz for 2 s, as the GUI sends
    gui.send(svgui::Control{1.0, 1.0});
    gui.run_for(milliseconds(100));
  }
  EXPECT_GT(gui.vehicle().odometry().distance_m, 0.5);
  EXPECT_NEAR(gui.chassis().steering_target_rad(), -gui.chassis().def().max_steering_rad, 1e-12);
  gui.run_for(milliseconds(380));  // 480 ms after the last CONTROL
  EXPECT_TRUE(gui.state().control.has_value());
  gui.run_for(milliseconds(30));  // 500 ms after the last CONTROL, on the 10 ms loop
  EXPECT_FALSE(gui.state().control.has_value());
  gui.run_for(seconds(3));
  EXPECT_EQ(gui.chassis().speed_mps(), 0.0);
}

TEST(Wr8SvguiHead, SetChangesTheSettingsAndSetRequestReadsThemBack) {
  Gui gui(svgui::Version::head);
  svgui::Set set;
  for (std::size_t k = 0; k < set.values.size(); ++k)
    set.values[k] = 0.5 * static_cast<double>(k);
  set.values[3] = 100;  // steering zero 10 degrees off the centre
  gui.send(set);
  EXPECT_EQ(gui.state().head_settings, set.values);
  EXPECT_NEAR(sim::rad_to_deg(gui.chassis().steering_target_rad()), 10, 1e-9);
  gui.take();
  gui.send(svgui::SetRequest{});
  gui.run_for(milliseconds(1));
  const auto got = gui.take();
  std::vector<Received> sets;
  for (const auto& r : got) {
    if (std::holds_alternative<svgui::Set>(r.message)) sets.push_back(r);
  }
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(std::get<svgui::Set>(sets[0].message), set);
  EXPECT_EQ(sets[0].raw.size(), 98u);  // 0x61 and 97 bytes
  EXPECT_EQ(sets[0].raw[0], 0x61);
}

TEST(Wr8SvguiHead, ASetOrControlThatIsNotANumberIsDroppedAndTheCarStaysFinite) {
  Gui gui(svgui::Version::head);
  svgui::Set set;
  set.values.fill(1.0);
  set.values[3] = std::numeric_limits<double>::quiet_NaN();  // steering zero
  gui.send(set);
  gui.send(svgui::Control{std::numeric_limits<double>::infinity(), 0.5});
  EXPECT_EQ(gui.state().unusable_reads, 2u);
  EXPECT_EQ(gui.state().head_settings, SvguiConfig{}.head_settings);
  EXPECT_FALSE(gui.state().control.has_value());
  gui.run_for(seconds(1));
  EXPECT_TRUE(std::isfinite(gui.vehicle().pose().x_m));
  EXPECT_TRUE(std::isfinite(gui.chassis().steering_rad()));
}

TEST(Wr8SvguiHead, TheMapDescribesTheArenaWithItsWallsAndObstacles) {
  sim::World world{sim::WorldDef{}};
  sim::Vehicle& vehicle = world.add_vehicle(sim::wr8_vehicle());
  SvguiFirmware fw(world, vehicle, config_of(svgui::Version::head));
  const svgui::Map map = fw.map();
  // The 4 m x 3 m warehouse in 0.5 m cells and a ring of walls: 10 x 8.
  EXPECT_EQ(map.width, 10);
  EXPECT_EQ(map.height, 8);
  ASSERT_EQ(map.rows.size(), 8u);
  EXPECT_THAT(map.rows.front(), ::testing::Each(1));
  EXPECT_THAT(map.rows.back(), ::testing::Each(1));
  int inner = 0;
  for (std::size_t r = 1; r + 1 < map.rows.size(); ++r) {
    EXPECT_EQ(map.rows[r].front(), 1);
    EXPECT_EQ(map.rows[r].back(), 1);
    for (std::size_t c = 1; c + 1 < map.rows[r].size(); ++c)
      inner += map.rows[r][c];
  }
  EXPECT_GT(inner, 0);   // the shelf and the pillar
  EXPECT_LT(inner, 48);  // not the whole floor
  EXPECT_LE(svgui::encode_prefixed(map, svgui::Version::head).size(), 128u);
}

}  // namespace
}  // namespace hil::mocks
