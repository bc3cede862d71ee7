#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "protocol/arduino/codec.hpp"
#include "tests/protocol/arduino/arduino_generators.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::arduino {
namespace {

using test::decode_chunked;
using test::decode_whole;
using test::frames_of;
using test::messages_of;
using test::raw_of_all;

RC_GTEST_PROP(ArduinoProperties, DecodeOfEncodeIsIdentity, (const Message& m)) {
  const Bytes frame = encode(m);
  const auto item = decode_frame(frame);
  const auto* f = std::get_if<Frame<Message>>(&item);
  RC_ASSERT(f != nullptr);
  RC_ASSERT(f->message == m);
  RC_ASSERT(f->raw == frame);
  RC_ASSERT(!f->tolerated.has_value());
}

RC_GTEST_PROP(ArduinoProperties, EnvelopeLayerRoundTripsAnyFieldText, (std::uint8_t seq)) {
  // The generic layer carries any field text, known command or not.
  const Envelope e{seq, *rc::gen::nonEmpty(test::arduino::gen_field_text()),
                   *test::arduino::gen_field_text()};
  const auto item = parse_envelope(to_bytes(frame_text(e)));
  const auto* f = std::get_if<Frame<Envelope>>(&item);
  RC_ASSERT(f != nullptr);
  RC_ASSERT(f->message == e);
}

RC_GTEST_PROP(ArduinoProperties, AnyChunkingDecodesLikeTheWholeStream,
              (const std::vector<Message>& ms)) {
  const std::vector<Bytes> parts = frames_of(ms);
  // Noise made of the markers, so errors are part of the comparison too.
  const auto noise = *rc::gen::container<Bytes>(
      rc::gen::element<std::uint8_t>('^', '$', '*', '|', '0', 'V', '\n'));
  const Bytes stream = test::with_noise_somewhere(parts, noise);
  test::assert_any_chunking_decodes_alike<Decoder, Item>(Decoder{}, stream);
  const auto firmware_whole =
      decode_whole<Decoder, Item>(Decoder{DecoderOptions::firmware()}, stream);
  const auto firmware_bytewise =
      decode_chunked<Decoder, Item>(Decoder{DecoderOptions::firmware()}, stream, {1});
  RC_ASSERT(firmware_bytewise == firmware_whole);
}

RC_GTEST_PROP(ArduinoProperties, EveryByteIsAccountedForOnce, (const std::vector<Message>& ms)) {
  const Bytes stream = test::interleave(
      frames_of(ms), [] { return *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>()); });
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(raw_of_all(items) == stream);
  const auto firmware = decode_chunked<Decoder, Item>(Decoder{DecoderOptions::firmware()}, stream,
                                                      *test::gen_pieces());
  RC_ASSERT(raw_of_all(firmware) == stream);
}

RC_GTEST_PROP(ArduinoProperties, RandomGarbageBetweenFramesLosesNoFrame,
              (const std::vector<Message>& ms)) {
  // Garbage may hold '$', '*', '|' and anything else, but no '^': a '^'
  // would open a frame that overlaps the next real one.
  const Bytes stream = test::interleave(
      frames_of(ms),
      [] {
        return *rc::gen::container<Bytes>(rc::gen::suchThat(
            rc::gen::arbitrary<std::uint8_t>(), [](std::uint8_t b) { return b != kStart; }));
      },
      /*noise_first=*/true);
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

RC_GTEST_PROP(ArduinoProperties, UnterminatedFrameBeforeAFrameDoesNotSwallowIt,
              (const std::vector<Message>& ms)) {
  // Half-sent frames ("^" and no "$") right before each real frame: the real
  // frame's own '^' must restart framing every time.
  Bytes stream;
  for (const auto& m : ms) {
    const auto frame = encode(m);
    const auto cut = *rc::gen::inRange<std::size_t>(1, frame.size());
    stream.insert(stream.end(), frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(cut));
    if (stream.back() == kEnd) stream.pop_back();
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

// True when a changed frame is noticed: no frame comes out at all, or the
// only difference the decoder lets through is visibly flagged (a checksum
// letter changed to lowercase, which the default options tolerate).
bool change_detected(const Bytes& changed, const DecoderOptions& options) {
  const auto items = decode_whole<Decoder, Item>(Decoder{options}, changed);
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<Message>>(&item)) {
      if (f->tolerated != ErrorKind::lowercase_checksum) return false;
    }
  }
  return true;
}

bool single_byte_change_detected(const Bytes& frame, std::size_t pos, std::uint8_t value) {
  Bytes changed = frame;
  changed[pos] = value;
  const bool strict_silent =
      messages_of(decode_whole<Decoder, Item>(
                      Decoder{DecoderOptions{.accept_lowercase_checksum = false}}, changed))
          .empty();
  return strict_silent && change_detected(changed, DecoderOptions{});
}

RC_GTEST_PROP(ArduinoProperties, EverySingleByteChangeIsDetected, (const Message& m)) {
  const Bytes frame = encode(m);
  const auto [pos, value] = test::gen_single_byte_change(frame);
  RC_ASSERT(single_byte_change_detected(frame, pos, value));
}

TEST(ArduinoProperties, EverySingleByteChangeOfEverySeedFrameIsDetected) {
  // Exhaustive over every position and every other byte value.
  const char* seed_frames[] = {"^01|PING|*11$", "^02|V|160*63$", "^03|M|25*49$", "^04|R|-90*72$",
                               "^05|B|*47$",    "^06|I|*4F$",    "^07|S|*54$",   "^08|STATUS|*1C$"};
  std::size_t checked = 0;
  std::size_t tolerated = 0;
  for (const char* text : seed_frames) {
    const Bytes frame = to_bytes(text);
    test::for_each_single_byte_change(frame, [&](std::size_t pos, std::uint8_t v) {
      Bytes changed = frame;
      changed[pos] = v;
      ASSERT_TRUE(single_byte_change_detected(frame, pos, v))
          << text << " byte " << pos << " -> " << int{v};
      if (!messages_of(decode_whole<Decoder, Item>(Decoder{}, changed)).empty()) ++tolerated;
      ++checked;
    });
    ASSERT_FALSE(HasFatalFailure());
  }
  EXPECT_EQ(checked, (13u + 13 + 12 + 13 + 10 + 10 + 10 + 15) * 255);
  // Only "^06|I|*4F$" and "^08|STATUS|*1C$" have a checksum letter, so
  // exactly two changes (F -> f, C -> c) are let through, both flagged.
  EXPECT_EQ(tolerated, 2u);
}

TEST(ArduinoProperties, XorMissesTwoCompensatingChanges) {
  // Documented limit: two changes that flip the same bit cancel in XOR.
  // "02|V|160" -> "02|V|061": '1'^'0' and '0'^'1' cancel.
  const auto item = decode_frame(to_bytes("^02|V|061*63$"));
  ASSERT_TRUE(std::holds_alternative<Frame<Message>>(item));
  EXPECT_EQ(std::get<Frame<Message>>(item).message, (Message{2, SetSpeed{61}}));
}

}  // namespace
}  // namespace hil::protocol::arduino
