#pragma once
// Part of the protocol adapters (protocol_adapter.hpp): the FrameSplitters
// they share. A protocol's stream decoder becomes a splitter through
// make_splitter; AmendingSplitter rewrites another splitter's frames.

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "link/protocol_adapter.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::link::splitters {

using protocol::ByteView;
using protocol::DecodeError;

/// A decode error as a frame's text: its kind, then ": " and its detail
/// when it has one.
inline std::string error_text(const DecodeError& e) {
  std::string text(protocol::to_string(e.kind));
  if (!e.detail.empty()) text += ": " + e.detail;
  return text;
}

/// Feeds a protocol's stream decoder and turns each item into a WireFrame;
/// `describe` gives a valid frame's kind and text.
template <class Decoder, class Message, class Describe>
class DecoderSplitter final : public FrameSplitter {
 public:
  DecoderSplitter(Decoder decoder, Describe describe, bool with_text)
      : decoder_(std::move(decoder)), describe_(std::move(describe)), with_text_(with_text) {}

  void feed(ByteView bytes, std::vector<WireFrame>& out) override {
    items_.clear();
    decoder_.feed(bytes, items_);
    convert(out);
  }
  void finish(std::vector<WireFrame>& out) override {
    items_.clear();
    decoder_.finish(items_);
    convert(out);
  }
  std::size_t buffered() const override { return decoder_.buffered(); }

 private:
  void convert(std::vector<WireFrame>& out) {
    for (auto& item : items_) {
      WireFrame frame;
      if (auto* f = std::get_if<protocol::Frame<Message>>(&item)) {
        frame.valid = true;
        auto [kind, text] = describe_(f->message, with_text_);
        frame.kind = std::move(kind);
        frame.text = std::move(text);
        frame.raw = std::move(f->raw);
      } else {
        auto& e = std::get<DecodeError>(item);
        frame.kind = e.context;
        frame.text = error_text(e);
        frame.raw = std::move(e.raw);
      }
      out.push_back(std::move(frame));
    }
  }

  Decoder decoder_;
  Describe describe_;
  bool with_text_;
  std::vector<protocol::DecodeItem<Message>> items_;
};

template <class Message, class Decoder, class Describe>
std::unique_ptr<FrameSplitter> make_splitter(Decoder decoder, Describe describe, bool with_text) {
  return std::make_unique<DecoderSplitter<Decoder, Message, Describe>>(
      std::move(decoder), std::move(describe), with_text);
}

/// A valid frame's kind and text, as a splitter's `describe` gives them.
using KindAndText = std::pair<std::string, std::string>;

/// Another splitter's frames, each amended by amend() as it comes out.
class AmendingSplitter : public FrameSplitter {
 public:
  explicit AmendingSplitter(std::unique_ptr<FrameSplitter> inner) : inner_(std::move(inner)) {}

  void feed(ByteView bytes, std::vector<WireFrame>& out) final {
    const std::size_t first = out.size();
    inner_->feed(bytes, out);
    amend(out, first);
  }
  void finish(std::vector<WireFrame>& out) final {
    const std::size_t first = out.size();
    inner_->finish(out);
    amend(out, first);
  }
  std::size_t buffered() const final { return inner_->buffered(); }

 private:
  /// Amends out[first..], the frames the inner splitter just gave.
  virtual void amend(std::vector<WireFrame>& out, std::size_t first) const = 0;

  std::unique_ptr<FrameSplitter> inner_;
};

/// Makes each write one valid frame; holds nothing.
class RawSplitter final : public FrameSplitter {
 public:
  explicit RawSplitter(bool with_text) : with_text_(with_text) {}
  void feed(ByteView bytes, std::vector<WireFrame>& out) override {
    if (bytes.empty()) return;
    WireFrame frame;
    frame.raw.assign(bytes.begin(), bytes.end());
    frame.valid = true;
    if (with_text_) frame.text = protocol::escape(bytes);
    out.push_back(std::move(frame));
  }
  void finish(std::vector<WireFrame>& /*out*/) override {}
  std::size_t buffered() const override { return 0; }

 private:
  bool with_text_;
};

}  // namespace hil::link::splitters
