#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "protocol/logi/codec.hpp"
#include "tests/protocol/logi/logi_generators.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::logi {
namespace {

using test::concat;
using test::decode_chunked;
using test::decode_whole;
using test::messages_of;
using test::raw_of_all;

bool contains_header(const Bytes& b) {
  return to_string(b).find(kHeader) != std::string::npos;
}

RC_GTEST_PROP(LogiProperties, DecodeOfEncodeIsIdentity, (const Message& m)) {
  const auto item = decode_frame(encode(m));
  const auto* frame = std::get_if<Frame<Message>>(&item);
  RC_ASSERT(frame != nullptr);
  RC_ASSERT(frame->message == m);
  RC_ASSERT(frame->raw == encode(m));
}

RC_GTEST_PROP(LogiProperties, AnyChunkingDecodesLikeTheWholeStream,
              (const std::vector<Message>& ms)) {
  std::vector<Bytes> frames;
  for (const auto& m : ms)
    frames.push_back(encode(m));
  // Some noise so errors are part of the comparison too.
  const auto noise =
      *rc::gen::container<Bytes>(rc::gen::element<std::uint8_t>('L', 'O', 'G', 'I', ':', '#', 'x'));
  frames.insert(frames.begin() + *rc::gen::inRange<std::ptrdiff_t>(
                                     0, static_cast<std::ptrdiff_t>(frames.size()) + 1),
                noise);
  const Bytes stream = concat(frames);
  const auto pieces = *test::gen_pieces();
  const auto whole = decode_whole<Decoder, Item>(Decoder{}, stream);
  const auto chunked = decode_chunked<Decoder, Item>(Decoder{}, stream, pieces);
  const auto bytewise = decode_chunked<Decoder, Item>(Decoder{}, stream, {1});
  RC_ASSERT(chunked == whole);
  RC_ASSERT(bytewise == whole);
}

RC_GTEST_PROP(LogiProperties, EveryByteIsAccountedForOnce, (const std::vector<Message>& ms)) {
  Bytes stream;
  for (const auto& m : ms) {
    const auto frame = encode(m);
    stream.insert(stream.end(), frame.begin(), frame.end());
    const auto noise = *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>());
    stream.insert(stream.end(), noise.begin(), noise.end());
  }
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(raw_of_all(items) == stream);
}

RC_GTEST_PROP(LogiProperties, RandomGarbageBetweenFramesLosesNoFrame,
              (const std::vector<Message>& ms)) {
  Bytes stream;
  for (const auto& m : ms) {
    const auto garbage = *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>());
    RC_PRE(!contains_header(garbage));
    stream.insert(stream.end(), garbage.begin(), garbage.end());
    const auto frame = encode(m);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

RC_GTEST_PROP(LogiProperties, HeaderLikeGarbageLosesNoFrame, (const std::vector<Message>& ms)) {
  // Garbage made of the header's own letters (even whole headers), but no
  // tail: the decoder must resynchronise on the real header each time.
  Bytes stream;
  for (const auto& m : ms) {
    const auto garbage = *rc::gen::container<Bytes>(
        rc::gen::element<std::uint8_t>('L', 'O', 'G', 'I', ':', 'S', 'P', '0', 0x00, 0xFF));
    stream.insert(stream.end(), garbage.begin(), garbage.end());
    const auto frame = encode(m);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

// A single changed byte anywhere in a frame never yields a frame.
bool single_byte_change_detected(const Bytes& frame, std::size_t pos, std::uint8_t value) {
  Bytes changed = frame;
  changed[pos] = value;
  const auto items = decode_whole<Decoder, Item>(Decoder{}, changed);
  return messages_of(items).empty();
}

RC_GTEST_PROP(LogiProperties, EverySingleByteChangeIsDetected, (const Message& m)) {
  const Bytes frame = encode(m);
  const auto pos = *rc::gen::inRange<std::size_t>(0, frame.size());
  const auto value = *rc::gen::suchThat(rc::gen::arbitrary<std::uint8_t>(),
                                        [&](std::uint8_t v) { return v != frame[pos]; });
  RC_ASSERT(single_byte_change_detected(frame, pos, value));
}

TEST(LogiProperties, EverySingleByteChangeOfEverySpecCommandIsDetected) {
  // Exhaustive over positions and values for the command set.
  std::vector<Message> commands = {SetSpeed{0},           SetSpeed{100},           SetRun{true},
                                   SetRun{false},         SetStation{1},           SetStation{2},
                                   SetMode{Mode::manual}, SetMode{Mode::automatic}};
  for (const auto d : kAllDirections)
    commands.push_back(Move{d});
  std::size_t checked = 0;
  for (const auto& m : commands) {
    const Bytes frame = encode(m);
    for (std::size_t pos = 0; pos < frame.size(); ++pos) {
      for (int v = 0; v < 256; ++v) {
        if (v == frame[pos]) continue;
        ASSERT_TRUE(single_byte_change_detected(frame, pos, static_cast<std::uint8_t>(v)))
            << to_string(frame) << " byte " << pos << " -> " << v;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 50000u);
}

}  // namespace
}  // namespace hil::protocol::logi
