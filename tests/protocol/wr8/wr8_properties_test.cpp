#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "protocol/wr8/codec.hpp"
#include "tests/protocol/decoder_test_support.hpp"
#include "tests/protocol/wr8/wr8_generators.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::protocol::wr8 {
namespace {

using test::decode_chunked;
using test::decode_whole;
using test::fit;
using test::messages_of;
using test::raw_of_all;

std::vector<Message> fitted(std::vector<Message> ms, const Profile& profile) {
  for (auto& m : ms)
    m = fit(std::move(m), profile);
  return ms;
}

std::vector<Bytes> packets_of(const std::vector<Message>& ms,
                              const Profile& profile = default_profile()) {
  std::vector<Bytes> packets;
  for (const auto& m : ms)
    packets.push_back(encode(m, profile));
  return packets;
}

// Bytes that are no packet code: the garbage the decoder can always skip.
rc::Gen<Bytes> non_code_garbage() {
  return rc::gen::container<Bytes>(rc::gen::inRange<std::uint8_t>(kPacketCodeCount, 255));
}

RC_GTEST_PROP(Wr8Properties, DecodeOfEncodeIsIdentity,
              (const Message& any, const Profile& profile)) {
  const Message m = fit(any, profile);
  const Bytes packet = encode(m, profile);
  const auto item = decode_packet(packet, DecoderOptions{profile});
  const auto* frame = std::get_if<Frame<Message>>(&item);
  RC_ASSERT(frame != nullptr);
  RC_ASSERT(frame->message == m);
  RC_ASSERT(frame->raw == packet);
  const auto* d = std::get_if<Data>(&m);
  const bool has_unparsed = d != nullptr && !d->unparsed.empty();
  RC_ASSERT(frame->tolerated ==
            (has_unparsed ? std::optional{ErrorKind::unknown_code} : std::nullopt));
}

RC_GTEST_PROP(Wr8Properties, AnyChunkingDecodesLikeTheWholeStream,
              (const std::vector<Message>& any, const Profile& profile)) {
  // Arbitrary noise so errors and resynchronisation are compared too.
  const auto noise = *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>());
  const Bytes stream = test::with_noise_somewhere(packets_of(fitted(any, profile), profile), noise);
  DecoderOptions options{profile};
  options.max_packet_bytes = *rc::gen::element<std::size_t>(0, 16, 40, 300);
  test::assert_any_chunking_decodes_alike<Decoder, Item>(Decoder(options), stream);
}

RC_GTEST_PROP(Wr8Properties, EveryByteIsAccountedForOnce,
              (const std::vector<Message>& any, const Profile& profile)) {
  const Bytes stream = test::interleave(packets_of(fitted(any, profile), profile), [] {
    return *rc::gen::container<Bytes>(rc::gen::arbitrary<std::uint8_t>());
  });
  DecoderOptions options{profile};
  options.max_packet_bytes = *rc::gen::element<std::size_t>(0, 16, 40, 300);
  Decoder decoder(options);
  const auto items = test::decode_within<Decoder, Item>(decoder, stream, decoder.max_buffered());
  RC_ASSERT(raw_of_all(items) == stream);
}

RC_GTEST_PROP(Wr8Properties, GarbageOfNonCodeBytesBetweenPacketsLosesNoPacket,
              (const std::vector<Message>& any, const Profile& profile)) {
  const auto ms = fitted(any, profile);
  const Bytes stream = test::interleave(
      packets_of(ms, profile), [] { return *non_code_garbage(); }, /*noise_first=*/true);
  const auto items =
      decode_chunked<Decoder, Item>(Decoder(DecoderOptions{profile}), stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

RC_GTEST_PROP(Wr8Properties, GuiSideDecoderAlsoSkipsGuiPacketCodes,
              (const std::vector<Message>& any)) {
  // A GUI decodes what the vehicle sends; stray AUTH and TASK code bytes
  // then cannot start a packet, so they are skipped like garbage.
  std::vector<Message> ms;
  for (const auto& m : any) {
    if (sends(Sender::vehicle, static_cast<std::uint8_t>(code_of(m)))) ms.push_back(m);
  }
  const auto gui_codes_and_garbage = [] {
    return *rc::gen::container<Bytes>(
        rc::gen::oneOf(rc::gen::element<std::uint8_t>(1, 3),
                       rc::gen::inRange<std::uint8_t>(kPacketCodeCount, 255)));
  };
  const Bytes stream =
      test::interleave(packets_of(ms), gui_codes_and_garbage, /*noise_first=*/true);
  DecoderOptions options;
  options.sender = Sender::vehicle;
  const auto items = decode_chunked<Decoder, Item>(Decoder(options), stream, *test::gen_pieces());
  RC_ASSERT(messages_of(items) == ms);
}

RC_GTEST_PROP(Wr8Properties, ChangedParameterValueBytesGoUnnoticedButKeepSync,
              (const Task& any, const Response& next)) {
  // No checksum: a value byte changed in transit yields a packet with
  // another value, and the next packet still decodes.
  RC_PRE(!any.params.empty());
  const Bytes packet = encode(any);
  Bytes changed = packet;
  const auto pos = *rc::gen::inRange<std::size_t>(4, packet.size());
  changed[pos] = static_cast<std::uint8_t>(changed[pos] ^ *rc::gen::inRange<std::uint8_t>(1, 255));
  const Bytes tail = encode(next);
  changed.insert(changed.end(), tail.begin(), tail.end());
  const auto items = decode_whole<Decoder, Item>(Decoder{}, changed);
  const auto ms = messages_of(items);
  RC_ASSERT(ms.size() == 2u);
  const auto& got = std::get<Task>(ms[0]);
  RC_ASSERT(got.coi == any.coi);
  RC_ASSERT(got.task == any.task);
  RC_ASSERT(got.params != any.params);
  RC_ASSERT(ms[1] == Message{next});
}

RC_GTEST_PROP(Wr8Properties, TruncatingAPacketAlwaysReportsIt, (const Message& m)) {
  const Bytes packet = encode(m);
  RC_PRE(packet.size() > 1u);
  const auto cut = *rc::gen::inRange<std::size_t>(1, packet.size());
  const auto items = decode_whole<Decoder, Item>(Decoder{}, ByteView(packet).first(cut));
  RC_ASSERT(items.size() == 1u);
  const auto* e = std::get_if<DecodeError>(&items[0]);
  RC_ASSERT(e != nullptr);
  RC_ASSERT(e->kind == ErrorKind::truncated);
  RC_ASSERT(e->context == std::string(to_string(code_of(m))));
}

}  // namespace
}  // namespace hil::protocol::wr8
