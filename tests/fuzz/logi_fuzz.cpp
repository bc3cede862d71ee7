// libFuzzer target for the LOGI stream decoder. Beyond "no crash": the
// decoder contract (bounded buffer, every byte accounted for), agreement of
// chunked and whole decoding, and encode(decoded) reproducing the frame.

#include <algorithm>

#include "protocol/logi/codec.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil::protocol;
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  const auto items = hil::fuzz::decode_chunked_and_whole<logi::Decoder, logi::Message>(
      plan, stream, logi::kDefaultMaxFrameBytes);
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<logi::Message>>(&item)) {
      // Only canonical frames re-encode byte for byte (STAT keys may arrive
      // in another order); a re-encoded frame must always decode the same.
      hil::fuzz::check_decodes_the_same(logi::decode_frame(logi::encode(f->message)), f->message);
    }
  }
  return 0;
}
