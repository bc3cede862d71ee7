// libFuzzer target for the Arduino stream decoder. Beyond "no crash": the
// decoder contract (bounded buffer, every byte accounted for) for both the
// PC-side and the firmware-side bound, agreement of chunked and whole
// decoding, encode(decoded) decoding the same, and the NACK helpers never
// answering something that is not a complete frame.

#include "protocol/arduino/codec.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {

using namespace hil::protocol;

void check_items(const std::vector<arduino::Item>& items) {
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<arduino::Message>>(&item)) {
      // Frames arrive in non-canonical spellings too (+25, lowercase hex), so
      // the re-encoded frame must decode to the same message, not the same bytes.
      const auto round = arduino::decode_frame(arduino::encode(f->message));
      const auto* g = std::get_if<Frame<arduino::Message>>(&round);
      hil::fuzz::check(g != nullptr && g->message == f->message,
                       "re-encoded frame does not decode the same");
      hil::fuzz::check(f->raw.size() <= arduino::kMaxFrameBytes, "frame longer than the bound");
    } else {
      const auto& e = std::get<DecodeError>(item);
      hil::fuzz::check(!e.raw.empty(), "error item without bytes");
      hil::fuzz::check(!e.detail.empty(), "error item without a detail");
      if (const auto answer = arduino::nack_response(e)) {
        hil::fuzz::check(e.raw.front() == '^' && e.raw.back() == '$',
                         "NACK for bytes that are not a complete frame");
        hil::fuzz::check(std::holds_alternative<arduino::Nack>(answer->body),
                         "answer is not a NACK");
        (void)arduino::encode(*answer);
      }
    }
  }
}

void run(const arduino::DecoderOptions& options, std::span<const std::uint8_t> plan,
         std::span<const std::uint8_t> stream) {
  arduino::Decoder chunked(options);
  const auto items = hil::fuzz::feed_and_check<arduino::Decoder, arduino::Message>(
      chunked, plan, stream, options.max_frame_bytes);
  arduino::Decoder whole(options);
  const auto again = hil::fuzz::feed_and_check<arduino::Decoder, arduino::Message>(
      whole, {}, stream, options.max_frame_bytes);
  hil::fuzz::check(items == again, "chunked and whole decoding differ");
  check_items(items);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  run(arduino::DecoderOptions{}, plan, stream);
  run(arduino::DecoderOptions::firmware(), plan, stream);
  return 0;
}
