#pragma once
// What the decoder tests and properties of every protocol share: picking an
// item of a decoder's output by its alternative, checking an error item
// against what it should say, feeding a frame in several reads, and building
// streams of frames and noise for the properties.

#include <gtest/gtest.h>
#include <rapidcheck.h>

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::test {

/// Item `i` of a decoder's output, which must be an error.
template <class Message>
const protocol::DecodeError& error_at(const std::vector<protocol::DecodeItem<Message>>& items,
                                      std::size_t i) {
  return std::get<protocol::DecodeError>(items.at(i));
}

/// Item `i` of a decoder's output, which must be a frame.
template <class Message>
const protocol::Frame<Message>& frame_at(const std::vector<protocol::DecodeItem<Message>>& items,
                                         std::size_t i) {
  return std::get<protocol::Frame<Message>>(items.at(i));
}

/// The message of item `i`, which must be a frame.
template <class Message>
const Message& message_at(const std::vector<protocol::DecodeItem<Message>>& items, std::size_t i) {
  return frame_at(items, i).message;
}

/// What an error item should say; a field left empty is not checked.
struct ExpectedError {
  protocol::ErrorKind kind;
  std::optional<std::string> context = std::nullopt;
  /// Text the error's detail contains.
  std::optional<std::string> mentions = std::nullopt;
};

/// Expects item `i` to be an error of `want.kind`, with its context and a
/// detail mentioning its text where `want` names them.
template <class Message>
void expect_error_at(const std::vector<protocol::DecodeItem<Message>>& items, std::size_t i,
                     const ExpectedError& want) {
  SCOPED_TRACE("item " + std::to_string(i));
  const protocol::DecodeError& e = error_at(items, i);
  EXPECT_EQ(e.kind, want.kind);
  if (want.context) EXPECT_EQ(e.context, *want.context);
  if (want.mentions) EXPECT_NE(e.detail.find(*want.mentions), std::string::npos) << e.detail;
}

/// Expects exactly an error of `kind` over the bytes `raw`, then the frame of
/// `next`: what a decoder gives for one bad candidate and a good frame after.
template <class Message>
void expect_error_then_frame(const std::vector<protocol::DecodeItem<Message>>& items,
                             protocol::ErrorKind kind, const protocol::Bytes& raw,
                             const Message& next) {
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(error_at(items, 0).kind, kind);
  EXPECT_EQ(error_at(items, 0).raw, raw);
  EXPECT_EQ(message_at(items, 1), next);
}

/// Feeds `reads` one at a time into a fresh decoder: every read but the last
/// gives nothing (and then `waiting` bytes are buffered, where given); the
/// last gives exactly the frame of `message` and leaves `left` bytes buffered.
template <class Decoder, class Message>
void expect_reassembled(const std::vector<protocol::Bytes>& reads,
                        std::optional<std::size_t> waiting, const Message& message,
                        std::size_t left) {
  ASSERT_FALSE(reads.empty());
  Decoder d;
  std::vector<protocol::DecodeItem<Message>> out;
  for (std::size_t i = 0; i + 1 < reads.size(); ++i)
    d.feed(reads[i], out);
  EXPECT_TRUE(out.empty());
  if (waiting) EXPECT_EQ(d.buffered(), *waiting);
  d.feed(reads.back(), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(message_at(out, 0), message);
  EXPECT_EQ(d.buffered(), left);
}

/// A generated position in `frame` and a byte value other than the one there.
inline std::pair<std::size_t, std::uint8_t> gen_single_byte_change(const protocol::Bytes& frame) {
  const auto pos = *rc::gen::inRange<std::size_t>(0, frame.size());
  const auto value = *rc::gen::suchThat(rc::gen::arbitrary<std::uint8_t>(),
                                        [&](std::uint8_t v) { return v != frame[pos]; });
  return {pos, value};
}

/// Feeds `stream` to `decoder` a byte at a time, expecting no more than
/// `bound` bytes buffered after each, then finishes.
template <class Decoder, class Item>
std::vector<Item> decode_bytewise_within(Decoder decoder, ByteView stream, std::size_t bound) {
  std::vector<Item> out;
  for (std::size_t i = 0; i < stream.size(); ++i) {
    decoder.feed(stream.subspan(i, 1), out);
    EXPECT_LE(decoder.buffered(), bound) << "after byte " << i;
  }
  decoder.finish(out);
  return out;
}

/// Calls `check(pos, value)` for every position of `frame` and every byte
/// value other than the one there, until a check has a fatal failure.
template <class Check>
void for_each_single_byte_change(const protocol::Bytes& frame, Check&& check) {
  for (std::size_t pos = 0; pos < frame.size(); ++pos) {
    for (int v = 0; v < 256; ++v) {
      if (v == frame[pos]) continue;
      check(pos, static_cast<std::uint8_t>(v));
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
}

/// A frame written out as text, and the message it carries.
template <class Message>
struct TextVector {
  const char* frame;
  Message message;
};

/// Expects `item`, what decoding the vector's frame gave, to be that frame
/// with the vector's message and nothing tolerated.
template <class Message>
void expect_decoded_vector(const protocol::DecodeItem<Message>& item,
                           const TextVector<Message>& v) {
  const auto* frame = std::get_if<protocol::Frame<Message>>(&item);
  ASSERT_NE(frame, nullptr) << v.frame << ": " << std::get<protocol::DecodeError>(item).detail;
  EXPECT_EQ(frame->message, v.message) << v.frame;
  EXPECT_EQ(protocol::to_string(frame->raw), v.frame);
  EXPECT_FALSE(frame->tolerated);
}

/// Each of `messages` encoded by its protocol's encode().
template <class Message>
std::vector<protocol::Bytes> frames_of(const std::vector<Message>& messages) {
  std::vector<protocol::Bytes> frames;
  for (const auto& m : messages)
    frames.push_back(encode(m));
  return frames;
}

/// The frames joined, with `noise` put in at a generated place among them.
inline protocol::Bytes with_noise_somewhere(std::vector<protocol::Bytes> frames,
                                            const protocol::Bytes& noise) {
  frames.insert(frames.begin() + *rc::gen::inRange<std::ptrdiff_t>(
                                     0, static_cast<std::ptrdiff_t>(frames.size()) + 1),
                noise);
  return concat(frames);
}

/// Each frame followed by what `noise()` makes (noise_first: preceded by it).
template <class MakeNoise>
protocol::Bytes interleave(const std::vector<protocol::Bytes>& frames, MakeNoise&& noise,
                           bool noise_first = false) {
  protocol::Bytes stream;
  for (const auto& frame : frames) {
    if (!noise_first) stream.insert(stream.end(), frame.begin(), frame.end());
    const protocol::Bytes n = noise();
    stream.insert(stream.end(), n.begin(), n.end());
    if (noise_first) stream.insert(stream.end(), frame.begin(), frame.end());
  }
  return stream;
}

/// What makes arbitrary bytes for interleave(), discarding the case (RC_PRE)
/// when they hold what `unwanted` finds.
template <class Unwanted>
auto noise_without(Unwanted unwanted) {
  return [unwanted] {
    const auto noise = *rc::gen::container<protocol::Bytes>(rc::gen::arbitrary<std::uint8_t>());
    RC_PRE(!unwanted(noise));
    return noise;
  };
}

/// Asserts that `stream` decodes to the same items in generated pieces and a
/// byte at a time as all at once, each with a copy of the fresh `decoder`.
template <class Decoder, class Item>
void assert_any_chunking_decodes_alike(const Decoder& decoder, ByteView stream) {
  const auto whole = decode_whole<Decoder, Item>(decoder, stream);
  const auto chunked = decode_chunked<Decoder, Item>(decoder, stream, *gen_pieces());
  const auto bytewise = decode_chunked<Decoder, Item>(decoder, stream, {1});
  RC_ASSERT(chunked == whole);
  RC_ASSERT(bytewise == whole);
}

/// Feeds `stream` in generated pieces, asserting after each that no more
/// than `bound` bytes are buffered, then finishes and asserts none are.
template <class Decoder, class Item>
std::vector<Item> decode_within(Decoder& decoder, ByteView stream, std::size_t bound) {
  std::vector<Item> items;
  const auto pieces = *gen_pieces();
  std::size_t pos = 0;
  for (std::size_t i = 0; pos < stream.size(); ++i) {
    const std::size_t n =
        std::min(std::max<std::size_t>(1, pieces[i % pieces.size()]), stream.size() - pos);
    decoder.feed(stream.subspan(pos, n), items);
    pos += n;
    RC_ASSERT(decoder.buffered() <= bound);
  }
  decoder.finish(items);
  RC_ASSERT(decoder.buffered() == 0u);
  return items;
}

}  // namespace hil::test
