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
      hil::fuzz::check_decodes_the_same(arduino::decode_frame(arduino::encode(f->message)),
                                        f->message);
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
  check_items(hil::fuzz::decode_chunked_and_whole<arduino::Decoder, arduino::Message>(
      plan, stream, options.max_frame_bytes, options));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  run(arduino::DecoderOptions{}, plan, stream);
  run(arduino::DecoderOptions::firmware(), plan, stream);
  return 0;
}
