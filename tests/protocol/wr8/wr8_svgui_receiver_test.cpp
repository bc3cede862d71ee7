// How the real smart_vehicle_gui programs take packets off their socket,
// one read event per arrival (v2019 = 8d80e92, head = 431e8d4), fed the
// bytes their GUIs send.
#include <gtest/gtest.h>

#include "protocol/wr8/svgui_receiver.hpp"
#include "tests/support/hex.hpp"

namespace hil::protocol::wr8::svgui {
namespace {

using test::hex;

constexpr std::string_view kAuth2019 = "0B 01 6B 6F 6E 6E 69 63 68 69 77 61";
constexpr std::string_view kAuthHead = "0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00";
constexpr std::string_view kForward100 = "08 03 01 01 01 64 00 00 00";
constexpr std::string_view kSetRequest = "01 06";
constexpr std::string_view kControl =
    "19 0A 00 00 00 01 3F E0 00 00 00 00 00 00 00 00 00 02 BF F0 00 00 00 00 00 00";

Bytes joined(std::initializer_list<std::string_view> parts) {
  Bytes out;
  for (const auto p : parts) {
    const Bytes b = hex(p);
    out.insert(out.end(), b.begin(), b.end());
  }
  return out;
}

ReadEvent event_of(ProgramReceiver& receiver, const Bytes& arrived) {
  ReadEvent event;
  EXPECT_TRUE(receiver.on_arrival(arrived, event));
  return event;
}

TEST(Wr8SvguiReceiver, V2019ReadsOneWholePacketAsSent) {
  ProgramReceiver car(Version::v2019);
  const ReadEvent e = event_of(car, hex(kAuth2019));
  EXPECT_EQ(e.length_byte, 0x0B);
  EXPECT_EQ(e.packet, hex("01 6B 6F 6E 6E 69 63 68 69 77 61"));
  EXPECT_FALSE(e.length_mismatch);
}

TEST(Wr8SvguiReceiver, V2019ReadsCoalescedPacketsAsOne) {
  ProgramReceiver car(Version::v2019);
  const ReadEvent e = event_of(car, joined({kAuth2019, kForward100}));
  EXPECT_EQ(e.length_byte, 0x0B);
  EXPECT_EQ(e.packet.size(), 11u + 9u);  // the TASK, length byte and all, rides in the AUTH
  EXPECT_TRUE(e.length_mismatch);
  EXPECT_EQ(car.unread(), 0u);
}

TEST(Wr8SvguiReceiver, V2019ReadsTheRestOfASplitPacketAsANewOne) {
  ProgramReceiver car(Version::v2019);
  const Bytes auth = hex(kAuth2019);
  const ReadEvent first = event_of(car, Bytes(auth.begin(), auth.begin() + 4));
  EXPECT_EQ(first.packet, hex("01 6B 6F"));
  EXPECT_TRUE(first.length_mismatch);
  const ReadEvent second = event_of(car, Bytes(auth.begin() + 4, auth.end()));
  EXPECT_EQ(second.length_byte, 0x6E);  // the letter n taken for a length
  EXPECT_EQ(second.packet, hex("6E 69 63 68 69 77 61"));
}

TEST(Wr8SvguiReceiver, HeadTakesOnePacketPerEventAndRunsOneBehind) {
  ProgramReceiver car(Version::head);
  // AUTH and SET-REQUEST arrive together: the event takes the AUTH only.
  const ReadEvent first = event_of(car, joined({kAuthHead, kSetRequest}));
  EXPECT_EQ(first.length_byte, 0x0C);
  EXPECT_EQ(first.packet.size(), 12u);
  EXPECT_FALSE(first.length_mismatch);
  EXPECT_EQ(car.unread(), 2u);
  // A CONTROL arrives: its event takes the SET-REQUEST left from before.
  const ReadEvent second = event_of(car, hex(kControl));
  EXPECT_EQ(second.packet, hex("06"));
  EXPECT_EQ(car.unread(), 26u);
  // The CONTROL is taken only when something else arrives.
  const ReadEvent third = event_of(car, hex(kSetRequest));
  EXPECT_EQ(third.length_byte, 0x19);
  EXPECT_EQ(third.packet.size(), 25u);
  EXPECT_EQ(car.unread(), 2u);
}

TEST(Wr8SvguiReceiver, HeadTakesAShortPacketWhenOnlyPartOfItHasCome) {
  ProgramReceiver car(Version::head);
  const Bytes control = hex(kControl);
  const ReadEvent first = event_of(car, Bytes(control.begin(), control.begin() + 10));
  EXPECT_EQ(first.packet.size(), 9u);
  EXPECT_TRUE(first.length_mismatch);
  EXPECT_EQ(car.unread(), 0u);
}

TEST(Wr8SvguiReceiver, HeadCannotReadALengthOfZeroOrOf128AndMore) {
  ProgramReceiver car(Version::head);
  const ReadEvent negative = event_of(car, hex("80 05 01"));
  EXPECT_TRUE(negative.unreadable_length);
  EXPECT_TRUE(negative.packet.empty());
  EXPECT_EQ(car.unread(), 2u);  // only the length byte was consumed
  ProgramReceiver other(Version::head);
  EXPECT_TRUE(event_of(other, hex("00")).unreadable_length);
}

TEST(Wr8SvguiReceiver, NothingUnreadRaisesNoEvent) {
  ProgramReceiver car(Version::head);
  ReadEvent event;
  event.length_byte = 0x42;
  EXPECT_FALSE(car.on_arrival(Bytes{}, event));
  EXPECT_EQ(event.length_byte, 0x42);
}

}  // namespace
}  // namespace hil::protocol::wr8::svgui
