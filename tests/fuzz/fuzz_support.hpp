#pragma once
// Shared by the fuzz targets: split the fuzzer's input into a chunking
// plan and a byte stream, check the decoder contract, and run the wakeups a
// sans-I/O component asks for on a virtual clock.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <variant>
#include <vector>

#include "link/time.hpp"
#include "protocol/common/decode.hpp"

namespace hil::fuzz {

/// Aborts (which the fuzzer reports as a crash) when a contract is broken.
inline void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "decoder contract broken: %s\n", what);
    std::abort();
  }
}

/// Feeds `stream` in pieces whose sizes come from `plan` (cycled), checks
/// that the decoder never holds more than `bound` bytes and that every input
/// byte comes out in exactly one item, in order. Returns the items.
template <class Decoder, class Message>
std::vector<protocol::DecodeItem<Message>> feed_and_check(Decoder& decoder,
                                                          std::span<const std::uint8_t> plan,
                                                          std::span<const std::uint8_t> stream,
                                                          std::size_t bound) {
  std::vector<protocol::DecodeItem<Message>> items;
  std::size_t pos = 0;
  std::size_t i = 0;
  while (pos < stream.size()) {
    std::size_t n = plan.empty() ? stream.size() : std::size_t{plan[i++ % plan.size()]} + 1;
    if (n > stream.size() - pos) n = stream.size() - pos;
    decoder.feed(stream.subspan(pos, n), items);
    pos += n;
    check(decoder.buffered() <= bound, "buffer exceeds its bound");
  }
  decoder.finish(items);
  check(decoder.buffered() == 0, "finish() left bytes behind");
  std::vector<std::uint8_t> joined;
  for (const auto& item : items) {
    const auto& raw = protocol::raw_of(item);
    joined.insert(joined.end(), raw.begin(), raw.end());
  }
  check(joined.size() == stream.size() && std::equal(joined.begin(), joined.end(), stream.begin()),
        "item bytes differ from the input stream");
  return items;
}

/// feed_and_check() of `stream` twice, in the pieces `plan` gives and whole,
/// each into a fresh Decoder(options...); both must give the same items,
/// which are returned.
template <class Decoder, class Message, class... Options>
std::vector<protocol::DecodeItem<Message>> decode_chunked_and_whole(
    std::span<const std::uint8_t> plan, std::span<const std::uint8_t> stream, std::size_t bound,
    const Options&... options) {
  Decoder chunked(options...);
  auto items = feed_and_check<Decoder, Message>(chunked, plan, stream, bound);
  Decoder whole(options...);
  const auto again = feed_and_check<Decoder, Message>(whole, {}, stream, bound);
  check(items == again, "chunked and whole decoding differ");
  return items;
}

/// `round`, what decoding the re-encoded `message` gave, is a frame of that
/// same message.
template <class Message>
void check_decodes_the_same(const protocol::DecodeItem<Message>& round, const Message& message) {
  const auto* g = std::get_if<protocol::Frame<Message>>(&round);
  check(g != nullptr && g->message == message, "re-encoded frame does not decode the same");
}

/// Runs every wakeup `next_due()` reports up to `until` as a driver's timer
/// would: `now` moves to each (never back) and `wake()` runs there. Waking
/// `limit` times at one instant is a crash reported as `spinning`. Leaves
/// `now` at `until` at least.
template <class NextDue, class Wake>
void run_wakeups(link::Time& now, link::Time until, NextDue&& next_due, Wake&& wake, int limit,
                 const char* spinning) {
  int at_one_instant = 0;
  link::Time last{};
  while (const auto due = next_due()) {
    if (*due > until) break;
    const link::Time at = std::max(*due, now);
    at_one_instant = at == last ? at_one_instant + 1 : 0;
    check(at_one_instant < limit, spinning);
    last = now = at;
    wake();
  }
  now = std::max(now, until);
}

/// The first input byte gives the length of the chunking plan.
struct Split {
  std::span<const std::uint8_t> plan;
  std::span<const std::uint8_t> stream;
};
inline Split split_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return {};
  const std::size_t plan_len = std::min<std::size_t>(data[0] % 16, size - 1);
  return Split{{data + 1, plan_len}, {data + 1 + plan_len, size - 1 - plan_len}};
}

}  // namespace hil::fuzz
