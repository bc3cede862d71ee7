// libFuzzer target for the WR8 stream decoder. Beyond "no crash": the
// decoder contract (bounded buffer, every byte accounted for), agreement of
// chunked and whole decoding, and re-encoding every decoded packet giving
// back its exact bytes (a WR8 packet has one encoding per message).

#include "protocol/wr8/codec.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil::protocol;
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  // The high bits of the first byte pick the profile variant and options,
  // so every decoder mode is explored (the low bits size the plan).
  const std::uint8_t mode = size == 0 ? 0 : static_cast<std::uint8_t>(data[0] >> 4);
  wr8::DecoderOptions options;
  options.profile.byte_order = (mode & 1) != 0 ? wr8::ByteOrder::big : wr8::ByteOrder::little;
  options.profile.block_unit =
      (mode & 2) != 0 ? wr8::BlockSizeUnit::entries : wr8::BlockSizeUnit::bytes;
  switch (mode >> 2) {
    case 1:
      options.sender = wr8::Sender::gui;
      break;
    case 2:
      options.sender = wr8::Sender::vehicle;
      break;
    case 3:
      options.max_packet_bytes = 40;
      break;
    default:
      break;
  }

  const auto items = hil::fuzz::decode_chunked_and_whole<wr8::Decoder, wr8::Message>(
      plan, stream, wr8::Decoder(options).max_buffered(), options);
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<wr8::Message>>(&item)) {
      hil::fuzz::check(wr8::encode(f->message, options.profile) == f->raw,
                       "re-encoded packet differs from the bytes it was decoded from");
      hil::fuzz::check(wr8::decode_packet(f->raw, options) == item,
                       "packet decodes differently alone");
    }
  }
  return 0;
}
