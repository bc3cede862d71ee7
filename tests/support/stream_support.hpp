#pragma once
// Helpers shared by the decoder tests of every protocol: feeding a stream in
// chosen pieces, and keeping only the frames of a decoder's output.

#include <rapidcheck.h>

#include <algorithm>
#include <cstddef>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::test {

using protocol::Bytes;
using protocol::ByteView;

/// Feeds the whole stream at once, then finishes.
template <class Decoder, class Item>
std::vector<Item> decode_whole(Decoder decoder, ByteView stream) {
  std::vector<Item> out;
  decoder.feed(stream, out);
  decoder.finish(out);
  return out;
}

/// Feeds the stream in pieces of the given sizes (cycled; a size of 0 counts
/// as 1), then finishes.
template <class Decoder, class Item>
std::vector<Item> decode_chunked(Decoder decoder, ByteView stream,
                                 const std::vector<std::size_t>& pieces) {
  std::vector<Item> out;
  std::size_t pos = 0;
  std::size_t i = 0;
  while (pos < stream.size()) {
    const std::size_t want =
        pieces.empty() ? stream.size() : std::max<std::size_t>(1, pieces[i++ % pieces.size()]);
    const std::size_t n = std::min(want, stream.size() - pos);
    decoder.feed(stream.subspan(pos, n), out);
    pos += n;
  }
  decoder.finish(out);
  return out;
}

/// The messages of the frames among decoder output, in order.
template <class Message>
std::vector<Message> messages_of(const std::vector<protocol::DecodeItem<Message>>& items) {
  std::vector<Message> out;
  for (const auto& item : items) {
    if (const auto* f = std::get_if<protocol::Frame<Message>>(&item)) out.push_back(f->message);
  }
  return out;
}

/// The raw bytes of all items, joined: equals the input when every byte is
/// accounted for exactly once.
template <class Message>
Bytes raw_of_all(const std::vector<protocol::DecodeItem<Message>>& items) {
  Bytes out;
  for (const auto& item : items) {
    const Bytes& raw = protocol::raw_of(item);
    out.insert(out.end(), raw.begin(), raw.end());
  }
  return out;
}

/// Number of error items of a kind.
template <class Message>
std::size_t count_errors(const std::vector<protocol::DecodeItem<Message>>& items,
                         protocol::ErrorKind kind) {
  return static_cast<std::size_t>(std::count_if(items.begin(), items.end(), [&](const auto& item) {
    const auto* e = std::get_if<protocol::DecodeError>(&item);
    return e != nullptr && e->kind == kind;
  }));
}

/// Piece sizes for re-chunking a stream: mostly small, sometimes large.
inline rc::Gen<std::vector<std::size_t>> gen_pieces() {
  return rc::gen::nonEmpty(rc::gen::container<std::vector<std::size_t>>(
      rc::gen::weightedOneOf<std::size_t>({{4, rc::gen::inRange<std::size_t>(1, 4)},
                                           {2, rc::gen::inRange<std::size_t>(1, 40)},
                                           {1, rc::gen::inRange<std::size_t>(1, 2000)}})));
}

inline Bytes concat(const std::vector<Bytes>& parts) {
  Bytes out;
  for (const auto& p : parts)
    out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace hil::test
