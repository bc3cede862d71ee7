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
  leka::Decoder chunked(options);
  const auto items = hil::fuzz::feed_and_check<leka::Decoder, leka::Message>(chunked, plan, stream,
                                                                             leka::kMaxFrameBytes);
  leka::Decoder whole(options);
  const auto again = hil::fuzz::feed_and_check<leka::Decoder, leka::Message>(whole, {}, stream,
                                                                             leka::kMaxFrameBytes);
  hil::fuzz::check(items == again, "chunked and whole decoding differ");
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<leka::Message>>(&item)) {
      // The group has one wire form, so the frame must re-encode byte for byte.
      const Bytes reencoded = leka::frame_group(leka::group_bytes(f->message));
      hil::fuzz::check(reencoded == f->raw, "re-encoded frame differs from the decoded bytes");
      const auto round = leka::decode_frame(reencoded, options);
      const auto* g = std::get_if<Frame<leka::Message>>(&round);
      hil::fuzz::check(g != nullptr && g->message == f->message,
                       "re-encoded frame does not decode the same");
      if (!f->tolerated) {
        hil::fuzz::check(leka::encode(f->message) == f->raw, "encode() disagrees with the frame");
      }
    }
  }
  return 0;
}
