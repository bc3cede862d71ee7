// libFuzzer target for the real WR8 programs' framing and packets
// (protocol/wr8/svgui.hpp): the stream decoder's contract (bounded buffer,
// every byte in one item), chunked and whole decoding agreeing, every
// decoded packet re-encoding to its exact bytes, and the programs' own
// way of reading (ProgramReceiver) never losing or inventing a byte.

#include "protocol/wr8/svgui.hpp"
#include "protocol/wr8/svgui_receiver.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hil::protocol;
  namespace svgui = wr8::svgui;
  const auto [plan, stream] = hil::fuzz::split_input(data, size);
  // The high bit of the first byte picks the version.
  const auto version =
      size > 0 && (data[0] & 0x80) != 0 ? svgui::Version::head : svgui::Version::v2019;

  svgui::Decoder chunked(version);
  const auto items = hil::fuzz::feed_and_check<svgui::Decoder, svgui::Message>(
      chunked, plan, stream, wr8::kLongestPrefixedPacket + 1);
  svgui::Decoder whole(version);
  const auto again = hil::fuzz::feed_and_check<svgui::Decoder, svgui::Message>(
      whole, {}, stream, wr8::kLongestPrefixedPacket + 1);
  // Compared by bytes and outcome: a double that is NaN never equals itself.
  const auto outcome = [](const svgui::Item& item) {
    const auto* e = std::get_if<DecodeError>(&item);
    return std::pair{raw_of(item), e != nullptr ? static_cast<int>(e->kind) : -1};
  };
  hil::fuzz::check(items.size() == again.size(), "chunked and whole decoding differ");
  for (std::size_t k = 0; k < items.size() && k < again.size(); ++k)
    hil::fuzz::check(outcome(items[k]) == outcome(again[k]), "chunked and whole decoding differ");
  for (const auto& item : items) {
    if (const auto* f = std::get_if<Frame<svgui::Message>>(&item)) {
      hil::fuzz::check(svgui::encode_prefixed(f->message, version) == f->raw,
                       "re-encoded packet differs from the bytes it was decoded from");
    }
  }

  // The real programs' reads: each arrival one event; every byte is either
  // in an event (length byte and packet) or still unread.
  svgui::ProgramReceiver receiver(version);
  std::size_t pos = 0;
  std::size_t i = 0;
  std::size_t accounted = 0;
  while (pos < stream.size()) {
    std::size_t n = plan.empty() ? stream.size() : std::size_t{plan[i++ % plan.size()]} + 1;
    if (n > stream.size() - pos) n = stream.size() - pos;
    svgui::ReadEvent event;
    if (receiver.on_arrival(stream.subspan(pos, n), event)) {
      accounted += 1 + event.packet.size();
      hil::fuzz::check(
          event.packet.size() <=
              (version == svgui::Version::head ? wr8::kLongestPrefixedPacket : stream.size()),
          "a head read took more than a length byte can declare");
    }
    pos += n;
    hil::fuzz::check(accounted + receiver.unread() == pos, "the reads lost or invented bytes");
  }
  return 0;
}
