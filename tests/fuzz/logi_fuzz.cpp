// libFuzzer target for the LOGI stream decoder. Beyond "no crash": the
// decoder contract (bounded buffer, every byte accounted for), agreement of
// chunked and whole decoding, and encode(decoded) reproducing the frame.

#include <algorithm>

#include "protocol/logi/codec.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil::protocol;
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  logi::Decoder chunked;
  const auto items = hil::fuzz::feed_and_check<logi::Decoder, logi::Message>(
      chunked, plan, stream, logi::kDefaultMaxFrameBytes);
  logi::Decoder whole;
  const auto again = hil::fuzz::feed_and_check<logi::Decoder, logi::Message>(
      whole, {}, stream, logi::kDefaultMaxFrameBytes);
  hil::fuzz::check(items == again, "chunked and whole decoding differ");
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<logi::Message>>(&item)) {
      // Only canonical frames re-encode byte for byte (STAT keys may arrive
      // in another order); a re-encoded frame must always decode the same.
      const auto round = logi::decode_frame(logi::encode(f->message));
      const auto* g = std::get_if<Frame<logi::Message>>(&round);
      hil::fuzz::check(g != nullptr && g->message == f->message,
                       "re-encoded frame does not decode the same");
    }
  }
  return 0;
}
