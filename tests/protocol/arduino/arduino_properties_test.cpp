#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "protocol/arduino/codec.hpp"
#include "tests/protocol/arduino/arduino_generators.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::arduino {
namespace {

using test::concat;
using test::decode_chunked;
using test::decode_whole;
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
  std::vector<Bytes> parts;
  for (const auto& m : ms)
    parts.push_back(encode(m));
  // Noise made of the markers, so errors are part of the comparison too.
  const auto noise = *rc::gen::container<Bytes>(
      rc::gen::element<std::uint8_t>('^', '$', '*', '|', '0', 'V', '\n'));
  parts.insert(parts.begin() + *rc::gen::inRange<std::ptrdiff_t>(
                                   0, static_cast<std::ptrdiff_t>(parts.size()) + 1),
               noise);
  const Bytes stream = concat(parts);
  const auto whole = decode_whole<Decoder, Item>(Decoder{}, stream);
  const auto chunked = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  const auto bytewise = decode_chunked<Decoder, Item>(Decoder{}, stream, {1});
  RC_ASSERT(chunked == whole);
  RC_ASSERT(bytewise == whole);
  const auto firmware_whole =
      decode_whole<Decoder, Item>(Decoder{DecoderOptions::firmware()}, stream);
  const auto firmware_bytewise =
      decode_chunked<Decoder, Item>(Decoder{DecoderOptions::firmware()}, stream, {1});
  RC_ASSERT(firmware_bytewise == firmware_whole);
}

RC_GTEST_PROP(ArduinoProperties, EveryByteIsAccountedForOnce, (const std::vector<Message>& ms)) {
  Bytes stream;
  for (const auto& m : ms) {
    const auto frame = encode(m);
    stream.insert(stream.end(), frame.begin(), frame.end());
    const auto noise = *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>());
    stream.insert(stream.end(), noise.begin(), noise.end());
  }
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
  Bytes stream;
  for (const auto& m : ms) {
    const auto garbage = *rc::gen::container<Bytes>(rc::gen::suchThat(
        rc::gen::arbitrary<std::uint8_t>(), [](std::uint8_t b) { return b != kStart; }));
    stream.insert(stream.end(), garbage.begin(), garbage.end());
    const auto frame = encode(m);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
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
  const auto pos = *rc::gen::inRange<std::size_t>(0, frame.size());
  const auto value = *rc::gen::suchThat(rc::gen::arbitrary<std::uint8_t>(),
                                        [&](std::uint8_t v) { return v != frame[pos]; });
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
    for (std::size_t pos = 0; pos < frame.size(); ++pos) {
      for (int v = 0; v < 256; ++v) {
        if (v == frame[pos]) continue;
        Bytes changed = frame;
        changed[pos] = static_cast<std::uint8_t>(v);
        ASSERT_TRUE(single_byte_change_detected(frame, pos, static_cast<std::uint8_t>(v)))
            << text << " byte " << pos << " -> " << v;
        if (!messages_of(decode_whole<Decoder, Item>(Decoder{}, changed)).empty()) ++tolerated;
        ++checked;
      }
    }
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
