#pragma once
// The stream decoder of a text protocol (LOGI, Arduino): a DelimitedFramer
// cuts the stream into header..terminator frames, each frame is decoded on
// its own, and the bytes that make no frame become DecodeErrors.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/common/delimited_framer.hpp"

namespace hil::protocol {

/// Keeps the stream decoder contract (protocol/common/decode.hpp); holds at
/// most `max_frame_bytes` bytes.
template <class Message, class Options>
class DelimitedDecoder {
 public:
  using Item = DecodeItem<Message>;
  /// Decodes one frame, header to terminator.
  using FrameDecoder = Item (*)(ByteView frame, const Options& options);
  /// The error for an event that is not a frame (to_error by default).
  using EventError = DecodeError (*)(DelimitedFramer::Event&& event, std::size_t max_frame_bytes);

  DelimitedDecoder(Options options, std::string_view header, std::uint8_t terminator,
                   std::size_t max_frame_bytes, FrameDecoder decode, EventError error = to_error)
      : options_(std::move(options)),
        decode_(decode),
        error_(error),
        framer_(header, terminator, max_frame_bytes) {}

  void feed(ByteView bytes, std::vector<Item>& out) {
    framer_.feed(bytes, events_);
    if (!events_.empty()) convert(out);
  }
  void finish(std::vector<Item>& out) {
    framer_.finish(events_);
    convert(out);
  }
  std::size_t buffered() const { return framer_.buffered(); }

 private:
  void convert(std::vector<Item>& out) {
    for (auto& event : events_) {
      if (event.kind == DelimitedFramer::Kind::frame) {
        out.push_back(decode_(event.bytes, options_));
      } else {
        out.emplace_back(error_(std::move(event), framer_.max_frame_bytes()));
      }
    }
    events_.clear();
  }

  Options options_;
  FrameDecoder decode_;
  EventError error_;
  DelimitedFramer framer_;
  std::vector<DelimitedFramer::Event> events_;
};

}  // namespace hil::protocol
