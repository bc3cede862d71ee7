// libFuzzer target for the Leka stream decoder. Beyond "no crash": the
// decoder contract (bounded buffer, every byte accounted for), agreement of
// chunked and whole decoding, and decoded frames re-encoding to the same
// bytes and decoding to the same commands.

#include "protocol/leka/codec.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil::protocol;
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  // Half the inputs run the tolerant decoder, so out-of-range frames are
  // re-encoded too.
  leka::DecoderOptions options;
  options.accept_out_of_range = size % 2 == 1;
  const auto items = hil::fuzz::decode_chunked_and_whole<leka::Decoder, leka::Message>(
      plan, stream, leka::kMaxFrameBytes, options);
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<leka::Message>>(&item)) {
      // The group has one wire form, so the frame must re-encode byte for byte.
      const Bytes reencoded = leka::frame_group(leka::group_bytes(f->message));
      hil::fuzz::check(reencoded == f->raw, "re-encoded frame differs from the decoded bytes");
      hil::fuzz::check_decodes_the_same(leka::decode_frame(reencoded, options), f->message);
      if (!f->tolerated) {
        hil::fuzz::check(leka::encode(f->message) == f->raw, "encode() disagrees with the frame");
      }
    }
  }
  return 0;
}
