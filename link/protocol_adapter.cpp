#include "link/protocol_adapter.hpp"

#include <algorithm>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "link/frame_splitters.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/sketch.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/svgui.hpp"

namespace hil::link {
namespace {

using protocol::ByteView;
using protocol::DecodeError;
using splitters::AmendingSplitter;
using splitters::KindAndText;
using splitters::make_splitter;
using splitters::RawSplitter;

std::optional<ByteRange> non_empty(std::size_t first, std::size_t last) {
  if (first >= last) return std::nullopt;
  return ByteRange{first, last};
}

// ---------------------------------------------------------------- raw

class RawAdapter final : public ProtocolAdapter {
 public:
  std::string_view name() const override { return "raw"; }
  std::string_view profile() const override { return {}; }
  bool text_frames() const override { return false; }
  std::unique_ptr<FrameSplitter> splitter(bool with_text) const override {
    return std::make_unique<RawSplitter>(with_text);
  }
  std::optional<ByteRange> checksum_field(ByteView /*frame*/) const override {
    return std::nullopt;
  }
  std::optional<ByteRange> field(ByteView frame, std::string_view name) const override {
    if (name == "payload" || name == "body") return non_empty(0, frame.size());
    return std::nullopt;
  }
  std::vector<std::string> field_names() const override { return {"payload", "body"}; }
};

// ---------------------------------------------------------------- text frames

/// LOGI and Arduino: frames of text whose checksum is the two hex digits
/// just before the frame's last byte.
class TextFrameAdapter : public ProtocolAdapter {
 public:
  bool text_frames() const final { return true; }
  std::optional<ByteRange> checksum_field(ByteView frame) const final {
    if (!framed(frame)) return std::nullopt;
    return ByteRange{frame.size() - 3, frame.size() - 1};
  }

 protected:
  /// Whether `frame` has the places of a frame: its markers and the
  /// separator before the checksum. A frame whose checksum is already wrong
  /// still has them.
  virtual bool framed(ByteView frame) const = 0;
};

// ---------------------------------------------------------------- LOGI
// LOGI:<payload>:<CS>#

class LogiAdapter final : public TextFrameAdapter {
 public:
  explicit LogiAdapter(protocol::logi::Dialect dialect = protocol::logi::Dialect::guide)
      : dialect_(dialect) {}
  std::string_view name() const override { return "logi"; }
  /// Both profiles frame the stream alike; they differ in what the car
  /// does with each delivery (mocks/logi.hpp).
  std::string_view profile() const override { return protocol::logi::to_string(dialect_); }

  std::unique_ptr<FrameSplitter> splitter(bool with_text) const override {
    namespace logi = protocol::logi;
    return make_splitter<logi::Message>(
        logi::Decoder{},
        [](const logi::Message& m, bool text) {
          return KindAndText{protocol::logi::kind_of(m), text ? logi::describe(m) : std::string()};
        },
        with_text);
  }

  std::optional<ByteRange> field(ByteView frame, std::string_view name) const override {
    if (!framed(frame)) return std::nullopt;
    const std::size_t begin = protocol::logi::kHeader.size();
    const std::size_t end = frame.size() - 4;  // the ':' before the checksum
    if (name == "payload" || name == "body") return non_empty(begin, end);
    const auto* first = frame.data() + begin;
    const auto* colon = std::find(first, frame.data() + end, ':');
    const auto split = static_cast<std::size_t>(colon - frame.data());
    if (name == "code") return non_empty(begin, split);
    if (name == "value") return split < end ? non_empty(split + 1, end) : std::nullopt;
    return std::nullopt;
  }

  std::vector<std::string> field_names() const override {
    return {"payload", "body", "code", "value"};
  }

 private:
  // Header, ':' before two checksum characters, '#'.
  bool framed(ByteView f) const override {
    const auto header = protocol::logi::kHeader;
    if (f.size() < header.size() + 5) return false;
    if (!std::equal(header.begin(), header.end(), f.begin())) return false;
    return f.back() == protocol::logi::kTail && f[f.size() - 4] == ':';
  }

  protocol::logi::Dialect dialect_;
};

// ---------------------------------------------------------------- Arduino
// ^SEQ|CMD|PAYLOAD*CS$

// Profile `firmware` towards the board: frames are cut by '^' .. '$' as the
// README decoder cuts them (so every byte is still forwarded once), then
// judged as the real sketch judges them: a frame it acts on is valid (the
// one-space payload of argument-less requests included), one it refuses
// with a NACK or drops is not (docs/protocols/arduino.md, "Profiles").
class SketchJudgedSplitter final : public AmendingSplitter {
 public:
  SketchJudgedSplitter(std::unique_ptr<FrameSplitter> inner, bool with_text)
      : AmendingSplitter(std::move(inner)), with_text_(with_text) {}

 private:
  void amend(std::vector<WireFrame>& out, std::size_t first) const override {
    namespace arduino = protocol::arduino;
    for (std::size_t i = first; i < out.size(); ++i) {
      WireFrame& f = out[i];
      if (f.raw.empty() || f.raw.front() != '^' || f.raw.back() != '$') continue;
      if (f.raw.size() > arduino::kSketchFrameBytes) {
        f.valid = false;
        f.text = "oversized: dropped by the firmware: " + std::to_string(f.raw.size()) +
                 " bytes pass its " + std::to_string(arduino::kSketchFrameBytes) + "-byte buffer";
        continue;
      }
      const std::string_view text(reinterpret_cast<const char*>(f.raw.data()), f.raw.size());
      std::visit(protocol::Overloaded{[&](const arduino::SketchRequest& r) {
                                        if (!f.valid && with_text_) {
                                          f.text =
                                              "request " + r.seq + "|" + r.cmd + "|" + r.payload;
                                        }
                                        f.valid = true;
                                        f.kind = protocol::ascii_upper(r.cmd);
                                      },
                                      [&](const arduino::SketchRefusal& r) {
                                        f.valid = false;
                                        f.text = std::string(error_named_by(r.code)) +
                                                 ": refused by the firmware: NACK " +
                                                 std::string(arduino::to_string(r.code));
                                      },
                                      [&](const arduino::SketchDrop& d) {
                                        f.valid = false;
                                        f.text = "bad_format: dropped by the firmware: " + d.reason;
                                      }},
                 arduino::judge_sketch_frame(text));
    }
  }

  // The decode error a sketch's NACK stands for, so that a frame's error
  // kind (the text before ':') reads the same in both profiles.
  static std::string_view error_named_by(protocol::arduino::NackCode code) {
    using protocol::ErrorKind;
    using protocol::arduino::NackCode;
    switch (code) {
      case NackCode::bad_cs:
        return protocol::to_string(ErrorKind::bad_checksum);
      case NackCode::bad_cmd:
        return protocol::to_string(ErrorKind::unknown_code);
      case NackCode::bad_v:
        return protocol::to_string(ErrorKind::bad_value);
      case NackCode::bad_fmt:
      case NackCode::bad_seq:
        break;
    }
    return protocol::to_string(ErrorKind::bad_format);
  }

  bool with_text_;
};

class ArduinoAdapter final : public TextFrameAdapter {
 public:
  explicit ArduinoAdapter(protocol::arduino::Dialect dialect = protocol::arduino::kDefaultDialect)
      : dialect_(dialect) {}
  std::string_view name() const override { return "arduino"; }
  std::string_view profile() const override { return protocol::arduino::to_string(dialect_); }

  std::unique_ptr<FrameSplitter> splitter_for(Direction direction, bool with_text) const override {
    if (direction == Direction::to_car && dialect_ == protocol::arduino::Dialect::firmware) {
      return std::make_unique<SketchJudgedSplitter>(splitter(with_text), with_text);
    }
    return splitter(with_text);
  }

  std::unique_ptr<FrameSplitter> splitter(bool with_text) const override {
    namespace arduino = protocol::arduino;
    return make_splitter<arduino::Message>(
        arduino::Decoder{},
        [](const arduino::Message& m, bool text) {
          return KindAndText{std::string(arduino::command_of(m.body)),
                             text ? arduino::describe(m) : std::string()};
        },
        with_text);
  }

  std::optional<ByteRange> field(ByteView frame, std::string_view name) const override {
    if (!framed(frame)) return std::nullopt;
    const std::size_t star = frame.size() - 4;
    if (name == "body") return non_empty(1, star);
    // SEQ, CMD and PAYLOAD are found by the separators inside the body.
    const auto* body = frame.data() + 1;
    const auto* body_end = frame.data() + star;
    const auto* bar1 = std::find(body, body_end, '|');
    const auto* bar2 = bar1 == body_end ? body_end : std::find(bar1 + 1, body_end, '|');
    const auto at = [&](const std::uint8_t* p) {
      return static_cast<std::size_t>(p - frame.data());
    };
    if (name == "seq") return bar1 == body_end ? std::nullopt : non_empty(1, at(bar1));
    if (name == "cmd") return bar2 == body_end ? std::nullopt : non_empty(at(bar1) + 1, at(bar2));
    if (name == "payload") return bar2 == body_end ? std::nullopt : non_empty(at(bar2) + 1, star);
    return std::nullopt;
  }

  std::vector<std::string> field_names() const override {
    return {"body", "seq", "cmd", "payload"};
  }

 private:
  // '^', '*' before two checksum characters, '$'.
  bool framed(ByteView f) const override {
    namespace arduino = protocol::arduino;
    return f.size() >= 5 && f.front() == arduino::kStart && f.back() == arduino::kEnd &&
           f[f.size() - 4] == static_cast<std::uint8_t>(arduino::kChecksumSeparator);
  }

  protocol::arduino::Dialect dialect_;
};

// ---------------------------------------------------------------- WR8
// code byte, then a body whose length follows from the code; no checksum.

class Wr8Adapter final : public ProtocolAdapter {
 public:
  explicit Wr8Adapter(protocol::wr8::Profile profile = protocol::wr8::default_profile())
      : profile_(std::make_shared<const protocol::wr8::Profile>(std::move(profile))) {}

  std::string_view name() const override { return "wr8"; }
  std::string_view profile() const override { return protocol::default_car_profile("wr8").name; }
  bool text_frames() const override { return false; }

  std::unique_ptr<FrameSplitter> splitter(bool with_text) const override {
    namespace wr8 = protocol::wr8;
    wr8::DecoderOptions options;
    options.profile = *profile_;
    return make_splitter<wr8::Message>(
        wr8::Decoder{options},
        [profile = profile_](const wr8::Message& m, bool text) {
          std::string kind(wr8::to_string(wr8::code_of(m)));
          std::replace(kind.begin(), kind.end(), '-', '_');  // AUTH-REPLY -> AUTH_REPLY
          return KindAndText{std::move(kind), text ? wr8::describe(m, *profile) : std::string()};
        },
        with_text);
  }

  std::optional<ByteRange> checksum_field(ByteView /*frame*/) const override {
    return std::nullopt;
  }

  std::optional<ByteRange> field(ByteView frame, std::string_view name) const override {
    namespace wr8 = protocol::wr8;
    if (frame.empty()) return std::nullopt;
    if (name == "code") return ByteRange{0, 1};
    if (name == "payload" || name == "body") return non_empty(1, frame.size());
    if (name == "coi") {
      const auto code = static_cast<wr8::PacketCode>(frame[0]);
      const bool has_coi = code == wr8::PacketCode::task || code == wr8::PacketCode::settings ||
                           code == wr8::PacketCode::response;
      return has_coi ? non_empty(1, std::min<std::size_t>(2, frame.size())) : std::nullopt;
    }
    return std::nullopt;
  }

  std::vector<std::string> field_names() const override {
    return {"payload", "body", "code", "coi"};
  }

 private:
  // Shared with the splitters' describe functions, which outlive no adapter copy.
  std::shared_ptr<const protocol::wr8::Profile> profile_;
};

// ---------------------------------------------------------------- WR8, smart_vehicle_gui
// length byte, code byte, body; no checksum (protocol/wr8/svgui.hpp).

// The decoder names a packet it could not parse as the programs do
// ("LOW-FREQ-DATA"); rules match the names of valid packets
// ("LOW_FREQ_DATA"), so broken ones are spelled the same way.
class UnderscoredKinds final : public AmendingSplitter {
 public:
  using AmendingSplitter::AmendingSplitter;

 private:
  void amend(std::vector<WireFrame>& out, std::size_t first) const override {
    for (std::size_t i = first; i < out.size(); ++i)
      std::replace(out[i].kind.begin(), out[i].kind.end(), '-', '_');
  }
};

class SvguiAdapter final : public ProtocolAdapter {
 public:
  explicit SvguiAdapter(protocol::wr8::svgui::Version version) : version_(version) {}

  std::string_view name() const override { return "wr8"; }
  std::string_view profile() const override { return protocol::wr8::svgui::profile_of(version_); }
  bool text_frames() const override { return false; }

  std::unique_ptr<FrameSplitter> splitter(bool with_text) const override {
    namespace svgui = protocol::wr8::svgui;
    return std::make_unique<UnderscoredKinds>(make_splitter<svgui::Message>(
        svgui::Decoder{version_},
        [version = version_](const svgui::Message& m, bool text) {
          return KindAndText{svgui::kind_name(svgui::code_of(m), version),
                             text ? svgui::describe(m) : std::string()};
        },
        with_text));
  }

  std::optional<ByteRange> checksum_field(ByteView /*frame*/) const override {
    return std::nullopt;
  }

  std::optional<ByteRange> field(ByteView frame, std::string_view name) const override {
    if (frame.empty()) return std::nullopt;
    if (name == "length") return ByteRange{0, 1};
    // The rest needs a length byte that can frame a packet and the code after it.
    if (frame.size() < 2 || frame[0] == 0 || frame[0] > protocol::wr8::kLongestPrefixedPacket) {
      return std::nullopt;
    }
    if (name == "code") return ByteRange{1, 2};
    if (name == "payload" || name == "body") return non_empty(2, frame.size());
    if (name == "coi") {
      // Only v2019's TASK (3), SETTINGS (4) and ANSWER (5) carry one, right after the code.
      const bool has_coi =
          version_ == protocol::wr8::svgui::Version::v2019 && frame[1] >= 3 && frame[1] <= 5;
      return has_coi ? non_empty(2, std::min<std::size_t>(3, frame.size())) : std::nullopt;
    }
    return std::nullopt;
  }

  std::vector<std::string> field_names() const override {
    std::vector<std::string> names{"length", "code", "payload", "body"};
    if (version_ == protocol::wr8::svgui::Version::v2019) names.emplace_back("coi");
    return names;
  }

 private:
  protocol::wr8::svgui::Version version_;
};

// ---------------------------------------------------------------- Leka
// 2A 2B 2C 2D, length, command group, checksum

// The robot's side of a Leka link: the only thing a robot sends is a text
// line (the answer to `info`), so that direction is cut at line ends. A run
// of kLineBound bytes with no line end is handed on as an invalid frame.
class LineSplitter final : public FrameSplitter {
 public:
  static constexpr std::size_t kLineBound = protocol::leka::kMaxFrameBytes;
  explicit LineSplitter(bool with_text) : with_text_(with_text) {}

  void feed(ByteView bytes, std::vector<WireFrame>& out) override {
    for (const auto b : bytes) {
      buf_.push_back(b);
      if (b == '\n') {
        emit(true, "reply", out);
      } else if (buf_.size() >= kLineBound) {
        emit(false, "oversized: no line end in " + std::to_string(kLineBound) + " bytes", out);
      }
    }
  }
  void finish(std::vector<WireFrame>& out) override {
    if (!buf_.empty()) emit(false, "truncated: the stream ended inside a line", out);
  }
  std::size_t buffered() const override { return buf_.size(); }

 private:
  void emit(bool valid, std::string what, std::vector<WireFrame>& out) {
    WireFrame frame;
    frame.valid = valid;
    frame.kind = valid ? "reply" : "";
    if (with_text_ || !valid) {
      frame.text = valid ? "reply \"" + protocol::escape(buf_) + "\"" : std::move(what);
    }
    frame.raw = std::move(buf_);
    buf_.clear();
    out.push_back(std::move(frame));
  }

  bool with_text_;
  protocol::Bytes buf_;
};

class LekaAdapter final : public ProtocolAdapter {
 public:
  explicit LekaAdapter(protocol::leka::Dialect dialect = protocol::leka::Dialect::readme)
      : dialect_(dialect) {}
  std::string_view name() const override { return "leka"; }
  std::string_view profile() const override { return protocol::leka::to_string(dialect_); }
  /// Command frames are binary; only the robot's replies are text.
  bool text_frames() const override { return false; }

  std::unique_ptr<FrameSplitter> splitter_for(Direction direction, bool with_text) const override {
    if (direction == Direction::to_client) return std::make_unique<LineSplitter>(with_text);
    return splitter(with_text);
  }

  std::unique_ptr<FrameSplitter> splitter(bool with_text) const override {
    namespace leka = protocol::leka;
    leka::DecoderOptions options;
    options.dialect = dialect_;
    return make_splitter<leka::Message>(
        leka::Decoder{options},
        [](const leka::Message& m, bool text) {
          std::string kind = m.commands.empty()
                                 ? std::string{}
                                 : std::string(leka::spec_of(m.commands.front()).name);
          return KindAndText{std::move(kind), text ? leka::describe(m) : std::string()};
        },
        with_text);
  }

  std::optional<ByteRange> checksum_field(ByteView frame) const override {
    if (!framed(frame)) return std::nullopt;
    return ByteRange{frame.size() - 1, frame.size()};
  }

  std::optional<ByteRange> field(ByteView frame, std::string_view name) const override {
    if (!framed(frame)) return std::nullopt;
    const std::size_t length_at = protocol::leka::kStartSequence.size();
    if (name == "length") return ByteRange{length_at, length_at + 1};
    if (name == "group" || name == "payload" || name == "body") {
      return non_empty(length_at + 1, frame.size() - 1);
    }
    return std::nullopt;
  }

  std::vector<std::string> field_names() const override {
    return {"length", "group", "payload", "body"};
  }

 private:
  // Start sequence and a length byte that agrees with the frame's size.
  static bool framed(ByteView f) {
    namespace leka = protocol::leka;
    if (f.size() < leka::kOverheadBytes + 1) return false;
    if (!std::equal(leka::kStartSequence.begin(), leka::kStartSequence.end(), f.begin())) {
      return false;
    }
    return f[leka::kStartSequence.size()] == f.size() - leka::kOverheadBytes;
  }

  protocol::leka::Dialect dialect_;
};

}  // namespace

std::shared_ptr<const ProtocolAdapter> wr8_adapter(const protocol::wr8::Profile& profile) {
  return std::make_shared<Wr8Adapter>(profile);
}

std::shared_ptr<const ProtocolAdapter> protocol_adapter(std::string_view name) {
  if (name == "logi") return std::make_shared<LogiAdapter>();
  if (name == "arduino") return std::make_shared<ArduinoAdapter>();
  if (name == "wr8") return std::make_shared<Wr8Adapter>();
  if (name == "leka") return std::make_shared<LekaAdapter>();
  if (name == "raw") return std::make_shared<RawAdapter>();
  throw std::invalid_argument("unknown protocol '" + std::string(name) +
                              "' (known: logi, wr8, arduino, leka, raw)");
}

std::shared_ptr<const ProtocolAdapter> protocol_adapter(std::string_view name,
                                                        std::string_view profile) {
  if (profile.empty()) return protocol_adapter(name);
  if (name == "raw") {
    throw protocol::ProfileError("protocol raw has no profiles; '" + std::string(profile) +
                                 "' names one");
  }
  const protocol::CarProfile& p = protocol::find_car_profile(name, profile);
  if (name == "arduino") {
    return std::make_shared<ArduinoAdapter>(protocol::arduino::dialect_named(p.name));
  }
  if (name == "leka") return std::make_shared<LekaAdapter>(protocol::leka::dialect_named(p.name));
  if (name == "logi") return std::make_shared<LogiAdapter>(protocol::logi::dialect_named(p.name));
  if (const auto version = protocol::wr8::svgui::version_of_profile(p.name)) {
    return std::make_shared<SvguiAdapter>(*version);
  }
  return std::make_shared<Wr8Adapter>();  // the document's packets
}

}  // namespace hil::link
