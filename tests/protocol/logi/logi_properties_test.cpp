#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "protocol/logi/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/protocol/logi/logi_generators.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::logi {
namespace {

using test::decode_chunked;
using test::frames_of;
using test::messages_of;

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
  // Some noise so errors are part of the comparison too.
  const auto noise =
      *rc::gen::container<Bytes>(rc::gen::element<std::uint8_t>('L', 'O', 'G', 'I', ':', '#', 'x'));
  const Bytes stream = test::with_noise_somewhere(frames_of(ms), noise);
  test::assert_any_chunking_decodes_alike<Decoder, Item>(Decoder{}, stream);
}

RC_GTEST_PROP(LogiProperties, EveryByteIsAccountedForOnce, (const std::vector<Message>& ms)) {
  const Bytes stream = test::interleave(
      frames_of(ms), [] { return *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>()); });
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(test::raw_of_all(items) == stream);
}

RC_GTEST_PROP(LogiProperties, RandomGarbageBetweenFramesLosesNoFrame,
              (const std::vector<Message>& ms)) {
  const Bytes stream = test::interleave(frames_of(ms), test::noise_without(contains_header),
                                        /*noise_first=*/true);
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

RC_GTEST_PROP(LogiProperties, HeaderLikeGarbageLosesNoFrame, (const std::vector<Message>& ms)) {
  // Garbage made of the header's own letters (even whole headers), but no
  // tail: the decoder must resynchronise on the real header each time.
  const auto header_letters = [] {
    return *rc::gen::container<Bytes>(
        rc::gen::element<std::uint8_t>('L', 'O', 'G', 'I', ':', 'S', 'P', '0', 0x00, 0xFF));
  };
  const Bytes stream = test::interleave(frames_of(ms), header_letters, /*noise_first=*/true);
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

// A single changed byte anywhere in a frame never yields a frame.
bool single_byte_change_detected(const Bytes& frame, std::size_t pos, std::uint8_t value) {
  Bytes changed = frame;
  changed[pos] = value;
  const auto items = test::decode_whole<Decoder, Item>(Decoder{}, changed);
  return messages_of(items).empty();
}

RC_GTEST_PROP(LogiProperties, EverySingleByteChangeIsDetected, (const Message& m)) {
  const Bytes frame = encode(m);
  const auto [pos, value] = test::gen_single_byte_change(frame);
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
    test::for_each_single_byte_change(frame, [&](std::size_t pos, std::uint8_t v) {
      ASSERT_TRUE(single_byte_change_detected(frame, pos, v))
          << to_string(frame) << " byte " << pos << " -> " << int{v};
      ++checked;
    });
    ASSERT_FALSE(HasFatalFailure());
  }
  EXPECT_GT(checked, 50000u);
}

}  // namespace
}  // namespace hil::protocol::logi
