#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>

#include "protocol/leka/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/protocol/leka/leka_generators.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::leka {
namespace {

using test::concat;
using test::decode_chunked;
using test::decode_whole;
using test::frames_of;
using test::messages_of;
using test::raw_of_all;

bool contains_start(const Bytes& b) {
  return std::search(b.begin(), b.end(), kStartSequence.begin(), kStartSequence.end()) != b.end();
}

// Garbage that looks like the start of frames: start sequences, lengths
// and command bytes, but never a complete frame on its own.
rc::Gen<Bytes> header_like_garbage() {
  const auto piece =
      rc::gen::oneOf(rc::gen::just(Bytes(kStartSequence.begin(), kStartSequence.end())),
                     rc::gen::map(rc::gen::arbitrary<std::uint8_t>(),
                                  [](std::uint8_t len) {
                                    Bytes b(kStartSequence.begin(), kStartSequence.end());
                                    b.push_back(len);
                                    return b;
                                  }),
                     rc::gen::container<Bytes>(rc::gen::element<std::uint8_t>(
                         0x2A, 0x2B, 0x2C, 0x2D, 0x00, 0x01, 0x70, 0x15, 0xFF)));
  return rc::gen::map(rc::gen::resize(6, rc::gen::container<std::vector<Bytes>>(piece)),
                      [](const std::vector<Bytes>& parts) { return concat(parts); });
}

// True when some start sequence inside stream[from, to) begins a candidate
// whose checksum happens to match: such garbage is indistinguishable from a
// frame, the documented limit of resynchronisation.
bool has_accidental_frame(const Bytes& stream, std::size_t from, std::size_t to) {
  for (std::size_t p = from; p + kHeaderBytes <= stream.size() && p < to; ++p) {
    if (!std::equal(kStartSequence.begin(), kStartSequence.end(),
                    stream.begin() + static_cast<std::ptrdiff_t>(p))) {
      continue;
    }
    const std::size_t len = stream[p + 4];
    if (len == 0 || len > kMaxGroupBytes || p + kOverheadBytes + len > stream.size()) continue;
    const ByteView group(stream.data() + p + kHeaderBytes, len);
    if (checksum(group) == stream[p + kHeaderBytes + len]) return true;
  }
  return false;
}

RC_GTEST_PROP(LekaProperties, DecodeOfEncodeIsIdentity, (const CommandGroup& g)) {
  const Bytes frame = encode(g);
  RC_ASSERT(frame.size() <= kMaxFrameBytes);
  const auto item = decode_frame(frame);
  const auto* f = std::get_if<Frame<Message>>(&item);
  RC_ASSERT(f != nullptr);
  RC_ASSERT(f->message == g);
  RC_ASSERT(f->raw == frame);
  RC_ASSERT(!f->tolerated);
}

RC_GTEST_PROP(LekaProperties, ParseOfGroupBytesIsIdentity, (const CommandGroup& g)) {
  const auto parsed = parse_group(group_bytes(g));
  RC_ASSERT(std::holds_alternative<CommandGroup>(parsed));
  RC_ASSERT(std::get<CommandGroup>(parsed) == g);
}

RC_GTEST_PROP(LekaProperties, AnyChunkingDecodesLikeTheWholeStream,
              (const std::vector<CommandGroup>& gs)) {
  // Header-like noise so that errors and resynchronisation are compared too.
  const auto noise = *header_like_garbage();
  const Bytes stream = test::with_noise_somewhere(frames_of(gs), noise);
  test::assert_any_chunking_decodes_alike<Decoder, Item>(Decoder{}, stream);
}

RC_GTEST_PROP(LekaProperties, EveryByteIsAccountedForOnce, (const std::vector<CommandGroup>& gs)) {
  const Bytes stream = test::interleave(frames_of(gs), [] {
    return *rc::gen::oneOf(rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>()),
                           header_like_garbage());
  });
  Decoder d;
  const auto items = test::decode_within<Decoder, Item>(d, stream, kMaxFrameBytes);
  RC_ASSERT(raw_of_all(items) == stream);
}

RC_GTEST_PROP(LekaProperties, RandomGarbageBetweenFramesLosesNoFrame,
              (const std::vector<CommandGroup>& gs)) {
  const Bytes stream = test::interleave(frames_of(gs), test::noise_without(contains_start),
                                        /*noise_first=*/true);
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == std::vector<Message>(gs.begin(), gs.end()));
}

RC_GTEST_PROP(LekaProperties, HeaderLikeGarbageLosesNoFrame,
              (const std::vector<CommandGroup>& gs)) {
  // Garbage with start sequences and lengths whose candidates run over the
  // following frames: each must be cut at the next start sequence.
  Bytes stream;
  std::vector<std::pair<std::size_t, std::size_t>> garbage_spans;
  for (const auto& g : gs) {
    const auto garbage = *header_like_garbage();
    garbage_spans.emplace_back(stream.size(), stream.size() + garbage.size());
    stream.insert(stream.end(), garbage.begin(), garbage.end());
    const auto frame = encode(g);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  for (const auto& [from, to] : garbage_spans)
    RC_PRE(!has_accidental_frame(stream, from, to));
  const auto items = decode_chunked<Decoder, Item>(Decoder{}, stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == std::vector<Message>(gs.begin(), gs.end()));
}

RC_GTEST_PROP(LekaProperties, ChangingTheChecksumOrLastGroupByteIsAlwaysDetected,
              (const CommandGroup& g)) {
  // Both land unrotated in the low byte of the sum: any change shows.
  const Bytes frame = encode(g);
  const std::size_t pos = *rc::gen::element(frame.size() - 1, frame.size() - 2);
  const auto value = *rc::gen::suchThat(rc::gen::arbitrary<std::uint8_t>(),
                                        [&](std::uint8_t v) { return v != frame[pos]; });
  Bytes changed = frame;
  changed[pos] = value;
  RC_ASSERT(messages_of(decode_whole<Decoder, Item>(Decoder{}, changed)).empty());
}

RC_GTEST_PROP(LekaProperties, ChecksumIsTheLowByteOfTheRotatingSum, (const Bytes& group)) {
  // An independent statement of the rotation: each byte is added, and every
  // later byte rotates the sum right by one more bit.
  std::uint32_t sum = 0;
  for (const std::uint8_t b : group) {
    sum = ((sum >> 1) | ((sum & 1u) << 15)) & 0xFFFFu;
    sum = (sum + b) & 0xFFFFu;
  }
  RC_ASSERT(bsd_checksum16(group) == sum);
  RC_ASSERT(checksum(group) == (sum & 0xFFu));
}

}  // namespace
}  // namespace hil::protocol::leka
