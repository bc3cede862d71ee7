#include "protocol/common/delimited_framer.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace hil::protocol {

DelimitedFramer::DelimitedFramer(std::string_view header, std::uint8_t terminator,
                                 std::size_t max_frame_bytes)
    : header_(header), terminator_(terminator), max_frame_bytes_(max_frame_bytes) {
  if (header.empty() || max_frame_bytes <= header.size() + 1) {
    throw std::invalid_argument("DelimitedFramer: empty header or frame bound too small");
  }
  buf_.reserve(max_frame_bytes_ + 1);
}

void DelimitedFramer::emit(Kind kind, std::size_t count, std::vector<Event>& out) {
  const auto end = buf_.begin() + static_cast<std::ptrdiff_t>(count);
  out.push_back(Event{kind, Bytes(buf_.begin(), end)});
  buf_.erase(buf_.begin(), end);
}

void DelimitedFramer::feed(ByteView bytes, std::vector<Event>& out) {
  const std::size_t h = header_.size();
  for (const std::uint8_t b : bytes) {
    buf_.push_back(b);
    if (in_frame_ && b == terminator_) {
      // The bound counts the terminator too: one byte over it is oversized.
      emit(buf_.size() <= max_frame_bytes_ ? Kind::frame : Kind::oversized, buf_.size(), out);
      in_frame_ = false;
      header_.reset();
      continue;
    }
    if (header_.feed(b)) {
      // A header ends here: whatever came before it is garbage, or a frame
      // that never saw its terminator.
      const std::size_t before = buf_.size() - h;
      if (before > 0) emit(in_frame_ ? Kind::interrupted : Kind::garbage, before, out);
      in_frame_ = true;
      header_.reset();
      continue;
    }
    if (buf_.size() > max_frame_bytes_) {
      // Keep a possible header prefix at the end; everything before it goes.
      const std::size_t keep = header_.matched();
      emit(in_frame_ ? Kind::oversized : Kind::garbage, buf_.size() - keep, out);
      in_frame_ = false;
    }
  }
}

void DelimitedFramer::finish(std::vector<Event>& out) {
  if (!buf_.empty()) emit(in_frame_ ? Kind::truncated : Kind::garbage, buf_.size(), out);
  in_frame_ = false;
  header_.reset();
}

DecodeError to_error(DelimitedFramer::Event&& event, std::size_t max_frame_bytes) {
  DecodeError e;
  const std::size_t n = event.bytes.size();
  switch (event.kind) {
    case DelimitedFramer::Kind::garbage:
      e.kind = ErrorKind::garbage;
      e.detail = std::to_string(n) + " byte(s) outside any frame discarded";
      break;
    case DelimitedFramer::Kind::interrupted:
      e.kind = ErrorKind::bad_format;
      e.detail =
          "frame of " + std::to_string(n) + " byte(s) has no end marker before the next header";
      break;
    case DelimitedFramer::Kind::oversized:
      e.kind = ErrorKind::oversized;
      e.detail = "no end marker within " + std::to_string(max_frame_bytes) + " bytes of the header";
      break;
    case DelimitedFramer::Kind::truncated:
      e.kind = ErrorKind::truncated;
      e.detail = "stream ended " + std::to_string(n) + " byte(s) into a frame";
      break;
    case DelimitedFramer::Kind::frame:
      e.kind = ErrorKind::bad_format;
      e.detail = "internal: a frame event is not an error";
      break;
  }
  e.raw = std::move(event.bytes);
  return e;
}

}  // namespace hil::protocol
