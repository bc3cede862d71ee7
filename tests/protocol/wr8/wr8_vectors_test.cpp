// The WR8 document gives packet layouts but no byte examples, so these
// vectors are the worked examples of the documented profile
// (docs/protocols/wr8.md): one or more per packet kind, in each profile
// variant. Encode must produce them byte for byte and decode must give the
// message back, alone and as one stream.

#include <gtest/gtest.h>

#include "protocol/wr8/codec.hpp"
#include "tests/support/hex.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::wr8 {
namespace {

using test::hex;

Profile big_endian() {
  Profile p;
  p.byte_order = ByteOrder::big;
  return p;
}

Profile entries() {
  Profile p;
  p.block_unit = BlockSizeUnit::entries;
  return p;
}

Auth auth_of(std::string_view text) {
  Auth a;
  std::copy(text.begin(), text.end(), a.text.begin());
  return a;
}

// A running car's report with odometry, speed, wheel angle and battery.
Data all_four_parameters() {
  return Data{State::run,
              1500,
              {{data_code::odometry, Word::from_i32(120)},
               {data_code::speed, Word::from_f32(0.5f)},
               {data_code::wheel_angle, Word::from_f32(-10.0f)},
               {data_code::battery, Word{87}}},
              {}};
}

struct Vector {
  const char* name;
  const char* packet;
  Message message;
  Profile profile;
  std::optional<ErrorKind> tolerated;
};

std::vector<Vector> vectors() {
  const Profile defaults;
  return {
      {"empty keepalive", "00", Empty{}, defaults, {}},
      {"auth with the profile string",
       "01 48 49 4C 2D 57 52 38 2D 30 31",
       auth_of("HIL-WR8-01"),
       defaults,
       {}},
      {"auth-reply device 8 id 1 WAIT", "02 08 01 03", AuthReply{8, 1, State::wait}, defaults, {}},
      {"task check", "03 07 00 00", Task{7, TaskCode::check, {}}, defaults, {}},
      {"task drive 100 cm",
       "03 01 01 04 64 00 00 00",
       Task{1, TaskCode::drive, {Word::from_i32(100)}},
       defaults,
       {}},
      {"task turn -15 degrees",
       "03 02 02 04 F1 FF FF FF",
       Task{2, TaskCode::turn, {Word::from_i32(-15)}},
       defaults,
       {}},
      {"task blink", "03 03 03 00", Task{3, TaskCode::blink, {}}, defaults, {}},
      {"task get settings", "03 04 04 00", Task{4, TaskCode::get_settings, {}}, defaults, {}},
      {"settings all four",
       "04 05 14 00 00 00 C0 3F 01 00 00 80 3E 02 CD CC 4C 3D 03 5A 00 00 00",
       Settings{5,
                {{SettingCode::p, Word::from_f32(1.5f)},
                 {SettingCode::i, Word::from_f32(0.25f)},
                 {SettingCode::d, Word::from_f32(0.05f)},
                 {SettingCode::servo_zero, Word::from_i32(90)}}},
       defaults,
       {}},
      {"settings servo zero only",
       "04 06 05 03 5C 00 00 00",
       Settings{6, {{SettingCode::servo_zero, Word::from_i32(92)}}},
       defaults,
       {}},
      {"response started", "05 01 01", Response{1, ResponseCode::started}, defaults, {}},
      {"response completed", "05 01 02", Response{1, ResponseCode::completed}, defaults, {}},
      {"response error", "05 07 00", Response{7, ResponseCode::error}, defaults, {}},
      {"data with all four parameters",
       "06 01 DC 05 00 00 11 00 78 00 00 00 01 00 00 00 3F 02 00 00 20 C1 03 57",
       all_four_parameters(),
       defaults,
       {}},
      {"data without parameters",
       "06 03 00 00 00 00 00",
       Data{State::wait, 0, {}, {}},
       defaults,
       {}},
      {"data with a code the profile does not know", "06 01 10 00 00 00 07 00 0A 00 00 00 09 AA",
       Data{State::run, 16, {{data_code::odometry, Word::from_i32(10)}}, hex("09 AA")}, defaults,
       ErrorKind::unknown_code},
      {"big-endian task drive 100 cm",
       "03 01 01 04 00 00 00 64",
       Task{1, TaskCode::drive, {Word::from_i32(100)}},
       big_endian(),
       {}},
      {"big-endian data",
       "06 02 00 00 05 DC 07 00 00 00 00 78 03 1E",
       Data{State::stop, 1500, {{0, Word::from_i32(120)}, {3, Word{30}}}, {}},
       big_endian(),
       {}},
      {"entries task drive 100 cm",
       "03 01 01 01 64 00 00 00",
       Task{1, TaskCode::drive, {Word::from_i32(100)}},
       entries(),
       {}},
      {"entries settings p",
       "04 09 01 00 00 00 80 3F",
       Settings{9, {{SettingCode::p, Word::from_f32(1.0f)}}},
       entries(),
       {}},
      {"entries data with all four parameters",
       "06 01 DC 05 00 00 04 00 78 00 00 00 01 00 00 00 3F 02 00 00 20 C1 03 57",
       all_four_parameters(),
       entries(),
       {}},
  };
}

TEST(Wr8Vectors, EveryPacketKindHasAVector) {
  std::array<bool, kPacketCodeCount> seen{};
  for (const auto& v : vectors())
    seen[static_cast<std::size_t>(code_of(v.message))] = true;
  for (std::size_t i = 0; i < seen.size(); ++i)
    EXPECT_TRUE(seen[i]) << "packet code " << i;
}

TEST(Wr8Vectors, EncodeReproducesEveryVector) {
  for (const auto& v : vectors()) {
    EXPECT_EQ(to_hex(encode(v.message, v.profile)), v.packet) << v.name;
  }
}

TEST(Wr8Vectors, DecodeGivesBackEveryMessage) {
  for (const auto& v : vectors()) {
    const auto item = decode_packet(hex(v.packet), DecoderOptions{v.profile});
    const auto* frame = std::get_if<Frame<Message>>(&item);
    ASSERT_NE(frame, nullptr) << v.name << ": " << std::get<DecodeError>(item).detail;
    EXPECT_EQ(frame->message, v.message) << v.name << ": " << describe(frame->message);
    EXPECT_EQ(frame->tolerated, v.tolerated) << v.name;
    EXPECT_EQ(to_hex(frame->raw), v.packet) << v.name;
  }
}

TEST(Wr8Vectors, DefaultProfileVectorsDecodeAsOneStream) {
  Bytes stream;
  std::vector<Message> expected;
  for (const auto& v : vectors()) {
    if (!(v.profile == Profile{})) continue;
    const Bytes b = hex(v.packet);
    stream.insert(stream.end(), b.begin(), b.end());
    expected.push_back(v.message);
  }
  const auto items = test::decode_chunked<Decoder, Item>(Decoder{}, stream, {1});
  EXPECT_EQ(items.size(), expected.size());
  EXPECT_EQ(test::messages_of(items), expected);
}

TEST(Wr8Vectors, DescribeNamesFieldsWithUnits) {
  EXPECT_EQ(describe(Task{1, TaskCode::drive, {Word::from_i32(100)}}),
            "Task coi=1 drive distance_cm=100");
  EXPECT_EQ(describe(Task{2, TaskCode::turn, {Word::from_i32(-15)}}),
            "Task coi=2 turn angle_deg=-15");
  const auto data =
      decode_packet(hex("06 01 DC 05 00 00 11 00 78 00 00 00 01 00 00 00 3F 02 00 00 20 C1 03 57"));
  EXPECT_EQ(describe(std::get<Frame<Message>>(data).message),
            "Data state=RUN timestamp_ms=1500 odometry_cm=120 speed_mps=0.5 wheel_angle_deg=-10 "
            "battery_percent=87");
  EXPECT_EQ(describe(Settings{5,
                              {{SettingCode::p, Word::from_f32(1.5f)},
                               {SettingCode::servo_zero, Word::from_i32(90)}}}),
            "Settings coi=5 p=1.5 servo_zero=90");
  EXPECT_EQ(describe(auth_of("HIL-WR8-01")), "Auth text=\"HIL-WR8-01\" (profile string)");
  EXPECT_EQ(describe(AuthReply{8, 1, State::wait}),
            "AuthReply device_code=8 device_id=1 state=WAIT");
  EXPECT_EQ(describe(Response{7, ResponseCode::error}), "Response coi=7 error");
}

}  // namespace
}  // namespace hil::protocol::wr8
