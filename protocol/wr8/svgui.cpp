#include "protocol/wr8/svgui.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <stdexcept>
#include <string>

#include "base/enum_names.hpp"
#include "protocol/common/car_profile.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/wr8/length_prefix.hpp"

namespace hil::protocol::wr8::svgui {
namespace {

enum Code : std::uint8_t {
  kAuth = 1,
  kAuthReply = 2,
  kTask = 3,
  kSet = 4,
  kAnswer = 5,
  kSix = 6,  // v2019 DATA, head SET-REQUEST
  kMap = 7,
  kLowFreq = 8,
  kHighFreq = 9,
  kControl = 10,
};

constexpr std::size_t kMaxTaskParams = 31;  // 4 + 31 * 4 = 124 packet bytes

// ---- writing ----

class Writer {
 public:
  explicit Writer(std::uint8_t code) { out_.push_back(code); }
  void u8(std::uint8_t v) { out_.push_back(v); }
  void be32(std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8)
      out_.push_back(static_cast<std::uint8_t>(v >> shift));
  }
  void le32(std::uint32_t v) {
    for (int shift = 0; shift <= 24; shift += 8)
      out_.push_back(static_cast<std::uint8_t>(v >> shift));
  }
  void be64(std::uint64_t v) {
    for (int shift = 56; shift >= 0; shift -= 8)
      out_.push_back(static_cast<std::uint8_t>(v >> shift));
  }
  void real(double v) { be64(std::bit_cast<std::uint64_t>(v)); }
  /// A 4-byte data code and the double after it.
  void coded(std::uint32_t code, double v) {
    be32(code);
    real(v);
  }
  void bytes(ByteView b) { out_.insert(out_.end(), b.begin(), b.end()); }
  Bytes take() { return std::move(out_); }

 private:
  Bytes out_;
};

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("WR8 (smart_vehicle_gui) encode: " + what);
}

// ---- reading ----

std::optional<State> state_of(std::uint8_t b) {
  if (b > 3) return std::nullopt;
  return static_cast<State>(b);
}

/// Reads a packet front to back; the first failure sticks, so a parse can
/// read everything and check once.
class Reader {
 public:
  explicit Reader(ByteView packet) : p_(packet), at_(1) {}
  bool ok() const { return ok_; }
  std::size_t at() const { return at_; }
  bool done() const { return at_ == p_.size(); }
  std::uint8_t u8() { return have(1) ? p_[at_++] : 0; }
  std::uint32_t be32() {
    if (!have(4)) return 0;
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
      v = (v << 8) | p_[at_++];
    return v;
  }
  std::uint32_t le32() {
    if (!have(4)) return 0;
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
      v |= static_cast<std::uint32_t>(p_[at_++]) << (8 * i);
    return v;
  }
  double real() {
    if (!have(8)) return 0;
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i)
      v = (v << 8) | p_[at_++];
    return std::bit_cast<double>(v);
  }
  /// A 4-byte data code that must be `expected`; records the first mismatch.
  void code(std::uint32_t expected) {
    const std::size_t where = at_;
    const std::uint32_t got = be32();
    if (ok_ && got != expected && !wrong_code_) {
      wrong_code_ = "data code at byte " + std::to_string(where) + " is " + std::to_string(got) +
                    ", expected " + std::to_string(expected);
    }
  }
  /// A 4-byte data code that must be `expected`, and the double after it.
  double coded_real(std::uint32_t expected) {
    code(expected);
    return real();
  }
  /// A 4-byte data code that must be `expected`, and the u32 after it.
  std::uint32_t coded_u32(std::uint32_t expected) {
    code(expected);
    return be32();
  }
  const std::optional<std::string>& wrong_code() const { return wrong_code_; }
  /// A state byte; one that is no state reads as FAULT and is recorded.
  State state() {
    const std::uint8_t b = u8();
    if (auto s = state_of(b)) return *s;
    if (ok_ && !bad_state_) bad_state_ = b;
    return State::fault;
  }
  /// The first state byte that was no state.
  const std::optional<std::uint8_t>& bad_state() const { return bad_state_; }

 private:
  bool have(std::size_t n) {
    if (!ok_ || p_.size() - at_ < n) {
      ok_ = false;
      return false;
    }
    return true;
  }
  ByteView p_;
  std::size_t at_;
  bool ok_ = true;
  std::optional<std::string> wrong_code_;
  std::optional<std::uint8_t> bad_state_;
};

Item error(ErrorKind kind, ByteView packet, std::string detail, std::string_view context) {
  return DecodeError{kind, Bytes(packet.begin(), packet.end()), std::move(detail),
                     std::string(context)};
}

/// The shortest text that reads back as exactly `v`.
std::string shortest(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc{} ? std::string(buf, end) : std::string("?");
}

}  // namespace

const std::array<std::string_view, 12> kSetNames = {
    "steering-p", "steering-i",  "steering-d", "steering-zero", "forward-p",  "forward-i",
    "forward-d",  "forward-int", "backward-p", "backward-i",    "backward-d", "backward-int"};

constexpr auto kSvgui2019PacketNames =
    base::enum_names<std::uint8_t>({kAuth, "AUTH"}, {kAuthReply, "AUTH-REPLY"}, {kTask, "TASK"},
                                   {kSet, "SETTINGS"}, {kAnswer, "ANSWER"}, {kSix, "DATA"});
constexpr auto kSvguiHeadPacketNames = base::enum_names<std::uint8_t>(
    {kAuth, "AUTH"}, {kAuthReply, "AUTH-REPLY"}, {kSet, "SET"}, {kAnswer, "ANSWER"},
    {kSix, "SET-REQUEST"}, {kMap, "MAP"}, {kLowFreq, "LOW-FREQ-DATA"},
    {kHighFreq, "HIGH-FREQ-DATA"}, {kControl, "CONTROL"});

std::string_view packet_name(std::uint8_t code, Version version) {
  if (version == Version::v2019) return kSvgui2019PacketNames.name(code, "");
  return kSvguiHeadPacketNames.name(code, "");
}

std::string kind_name(std::uint8_t code, Version version) {
  std::string kind(packet_name(code, version));
  std::replace(kind.begin(), kind.end(), '-', '_');
  return kind;
}

std::string_view to_string(Version version) {
  return version == Version::v2019 ? "v2019" : "head";
}

std::optional<Version> version_of_profile(std::string_view profile) {
  const CarProfile& p = find_car_profile("wr8", profile);
  if (p.name == profile_of(Version::v2019)) return Version::v2019;
  if (p.name == profile_of(Version::head)) return Version::head;
  return std::nullopt;
}

std::string_view profile_of(Version version) {
  return version == Version::v2019 ? "svgui-2019" : "svgui-head";
}

std::uint8_t code_of(const Message& m) {
  return std::visit(Overloaded{
                        [](const Auth&) { return std::uint8_t{kAuth}; },
                        [](const AuthReply&) { return std::uint8_t{kAuthReply}; },
                        [](const Task&) { return std::uint8_t{kTask}; },
                        [](const Settings&) { return std::uint8_t{kSet}; },
                        [](const Set&) { return std::uint8_t{kSet}; },
                        [](const Answer&) { return std::uint8_t{kAnswer}; },
                        [](const SetRequest&) { return std::uint8_t{kSix}; },
                        [](const Data&) { return std::uint8_t{kSix}; },
                        [](const Map&) { return std::uint8_t{kMap}; },
                        [](const LowFreqData&) { return std::uint8_t{kLowFreq}; },
                        [](const HighFreqData&) { return std::uint8_t{kHighFreq}; },
                        [](const Control&) { return std::uint8_t{kControl}; },
                    },
                    m);
}

bool has_packet(Version version, const Message& m) {
  const bool v2019_only = std::holds_alternative<Task>(m) || std::holds_alternative<Settings>(m) ||
                          std::holds_alternative<Data>(m);
  const bool common = std::holds_alternative<Auth>(m) || std::holds_alternative<AuthReply>(m) ||
                      std::holds_alternative<Answer>(m);
  if (common) return true;
  return version == Version::v2019 ? v2019_only : !v2019_only;
}

Bytes encode(const Message& m, Version version) {
  require(has_packet(version, m), "the " + std::string(to_string(version)) +
                                      " programs have no such packet (code " +
                                      std::to_string(code_of(m)) + ")");
  Writer w(code_of(m));
  std::visit(Overloaded{
                 [&](const Auth& a) {
                   require(a.text.size() < kLongestPrefixedPacket, "an AUTH text over 126 bytes");
                   w.bytes(a.text);
                 },
                 [&](const AuthReply& r) {
                   w.u8(r.device_code);
                   w.u8(r.device_id);
                   w.u8(static_cast<std::uint8_t>(r.state));
                 },
                 [&](const Task& t) {
                   require(t.params.size() <= kMaxTaskParams, "a TASK of more than 31 parameters");
                   w.u8(t.coi);
                   w.u8(t.type);
                   w.u8(static_cast<std::uint8_t>(t.params.size()));
                   for (const std::int32_t p : t.params)
                     w.le32(static_cast<std::uint32_t>(p));
                 },
                 [&](const Settings& s) {
                   w.u8(s.coi);
                   for (const std::int32_t v : s.values)
                     w.le32(static_cast<std::uint32_t>(v));
                 },
                 [&](const Set& s) {
                   for (const double v : s.values)
                     w.real(v);
                 },
                 [&](const Answer& a) {
                   require(a.coi.has_value() == (version == Version::v2019),
                           version == Version::v2019 ? "a v2019 ANSWER needs its COI"
                                                     : "a head ANSWER has no COI");
                   if (a.coi) w.u8(*a.coi);
                   w.u8(a.code);
                 },
                 [&](const SetRequest&) {},
                 [&](const Data& d) {
                   w.u8(static_cast<std::uint8_t>(d.state));
                   w.be32(d.timestamp_ms);
                   w.be32(1);
                   w.be32(static_cast<std::uint32_t>(d.encoder));
                   w.coded(2, d.steering);
                   w.be32(3);
                   w.be32(d.motor_battery);
                   w.be32(4);
                   w.be32(d.computer_battery);
                 },
                 [&](const Map& map) {
                   w.u8(static_cast<std::uint8_t>(map.width));
                   w.u8(static_cast<std::uint8_t>(map.height));
                   w.be32(static_cast<std::uint32_t>(map.rows.size()));
                   for (const auto& row : map.rows) {
                     w.be32(static_cast<std::uint32_t>(row.size()));
                     for (const std::int8_t c : row)
                       w.u8(static_cast<std::uint8_t>(c));
                   }
                 },
                 [&](const LowFreqData& d) {
                   w.u8(static_cast<std::uint8_t>(d.state));
                   w.be32(d.timestamp_ms);
                   w.be32(1);
                   w.be32(d.motor_battery);
                   w.be32(2);
                   w.be32(d.computer_battery);
                   w.coded(3, d.temperature);
                 },
                 [&](const HighFreqData& d) {
                   w.be32(d.timestamp_ms);
                   w.coded(1, d.encoder);
                   w.coded(2, d.steering);
                   w.coded(3, d.x);
                   w.coded(4, d.y);
                   w.coded(5, d.angle);
                 },
                 [&](const Control& c) {
                   w.coded(1, c.x_axis);
                   w.coded(2, c.y_axis);
                 },
             },
             m);
  Bytes out = w.take();
  require(out.size() <= kLongestPrefixedPacket,
          "a packet of " + std::to_string(out.size()) + " bytes; one length byte frames 127");
  return out;
}

Bytes encode_prefixed(const Message& m, Version version) {
  return prefix_length(encode(m, version));
}

namespace {

Map read_map(Reader& r) {
  Map map;
  map.width = static_cast<std::int8_t>(r.u8());
  map.height = static_cast<std::int8_t>(r.u8());
  // Every row and cell read takes bytes or fails, so the loops end
  // with the packet whatever the counts claim.
  const std::size_t rows = r.be32();
  for (std::size_t i = 0; i < rows && r.ok(); ++i) {
    const std::size_t cells = r.be32();
    std::vector<std::int8_t> row;
    for (std::size_t j = 0; j < cells && r.ok(); ++j)
      row.push_back(static_cast<std::int8_t>(r.u8()));
    map.rows.push_back(std::move(row));
  }
  return map;
}

/// The message of a packet of `code` (not AUTH), read field by field;
/// nullopt for a code that has no packet.
std::optional<Message> read_message(Reader& r, Version version, std::uint8_t code) {
  const bool v2019 = version == Version::v2019;
  switch (code) {
    case kAuthReply: {
      AuthReply a;
      a.device_code = r.u8();
      a.device_id = r.u8();
      a.state = r.state();
      return a;
    }
    case kTask: {
      Task t;
      t.coi = r.u8();
      t.type = r.u8();
      const std::size_t n = r.u8();
      for (std::size_t i = 0; i < n && r.ok(); ++i)
        t.params.push_back(static_cast<std::int32_t>(r.le32()));
      return t;
    }
    case kSet: {
      if (v2019) {
        Settings s;
        s.coi = r.u8();
        for (auto& v : s.values)
          v = static_cast<std::int32_t>(r.le32());
        return s;
      }
      Set s;
      for (auto& v : s.values)
        v = r.real();
      return s;
    }
    case kAnswer: {
      Answer a;
      if (v2019) a.coi = r.u8();
      a.code = r.u8();
      return a;
    }
    case kSix: {
      if (!v2019) return SetRequest{};
      Data d;
      d.state = r.state();
      d.timestamp_ms = r.be32();
      d.encoder = static_cast<std::int32_t>(r.coded_u32(1));
      d.steering = r.coded_real(2);
      d.motor_battery = r.coded_u32(3);
      d.computer_battery = r.coded_u32(4);
      return d;
    }
    case kMap:
      return read_map(r);
    case kLowFreq: {
      LowFreqData d;
      d.state = r.state();
      d.timestamp_ms = r.be32();
      d.motor_battery = r.coded_u32(1);
      d.computer_battery = r.coded_u32(2);
      d.temperature = r.coded_real(3);
      return d;
    }
    case kHighFreq: {
      HighFreqData d;
      d.timestamp_ms = r.be32();
      d.encoder = r.coded_real(1);
      d.steering = r.coded_real(2);
      d.x = r.coded_real(3);
      d.y = r.coded_real(4);
      d.angle = r.coded_real(5);
      return d;
    }
    case kControl: {
      Control c;
      c.x_axis = r.coded_real(1);
      c.y_axis = r.coded_real(2);
      return c;
    }
    default:
      return std::nullopt;
  }
}

Item parse(ByteView packet, Version version, std::uint8_t code, std::string_view name) {
  if (code == kAuth) {
    return Frame<Message>{Auth{Bytes(packet.begin() + 1, packet.end())},
                          Bytes(packet.begin(), packet.end()), std::nullopt};
  }
  Reader r(packet);
  const std::optional<Message> m = read_message(r, version, code);
  if (!m) {  // decode_packet names only the codes read_message reads
    return error(ErrorKind::unknown_code, packet, "packet code " + std::to_string(code), name);
  }
  if (!r.ok()) {
    return error(ErrorKind::bad_format, packet,
                 std::string(name) + " of " + std::to_string(packet.size()) +
                     " bytes is cut short at byte " + std::to_string(r.at()),
                 name);
  }
  if (!r.done()) {
    return error(ErrorKind::bad_format, packet,
                 std::string(name) + " has " + std::to_string(packet.size() - r.at()) +
                     " bytes after its last field (at byte " + std::to_string(r.at()) + ")",
                 name);
  }
  if (r.wrong_code()) {
    return error(ErrorKind::bad_format, packet, std::string(name) + ": " + *r.wrong_code(), name);
  }
  if (r.bad_state()) {
    return error(ErrorKind::bad_value, packet,
                 std::string(name) + ": state " + std::to_string(*r.bad_state()) +
                     " is none of 0 FAULT, 1 RUN, 2 STOP, 3 WAIT",
                 name);
  }
  return Frame<Message>{*m, Bytes(packet.begin(), packet.end()), std::nullopt};
}

}  // namespace

Item decode_packet(ByteView packet, Version version) {
  if (packet.empty()) return error(ErrorKind::bad_format, packet, "an empty packet", "");
  const std::uint8_t code = packet[0];
  const std::string_view name = packet_name(code, version);
  if (name.empty()) {
    return error(ErrorKind::unknown_code, packet,
                 "packet code " + std::to_string(code) + " is none of the " +
                     std::string(to_string(version)) + " programs' packets",
                 "");
  }
  return parse(packet, version, code, name);
}

void Decoder::feed(ByteView bytes, std::vector<Item>& out) {
  framed_.clear();
  splitter_.feed(bytes, framed_);
  convert(out);
}

void Decoder::finish(std::vector<Item>& out) {
  framed_.clear();
  splitter_.finish(framed_);
  convert(out);
}

void Decoder::convert(std::vector<Item>& out) {
  for (auto& item : framed_) {
    if (auto* e = std::get_if<DecodeError>(&item)) {
      out.emplace_back(std::move(*e));
      continue;
    }
    auto& framed = std::get<Frame<Bytes>>(item);
    Item decoded = decode_packet(framed.message, version_);
    // The item stands for the bytes on the wire: the length byte as well.
    if (auto* f = std::get_if<Frame<Message>>(&decoded)) {
      f->raw = std::move(framed.raw);
    } else {
      std::get<DecodeError>(decoded).raw = std::move(framed.raw);
    }
    out.push_back(std::move(decoded));
  }
}

std::string describe(const Message& m) {
  return std::visit(
      Overloaded{
          [](const Auth& a) { return "Auth text=\"" + escape(a.text) + "\""; },
          [](const AuthReply& r) {
            return "AuthReply device=" + std::to_string(r.device_code) +
                   " id=" + std::to_string(r.device_id) +
                   " state=" + std::string(to_string(r.state));
          },
          [](const Task& t) {
            std::string s = "Task coi=" + std::to_string(t.coi) + " type=" + std::to_string(t.type);
            for (const std::int32_t p : t.params)
              s += ' ' + std::to_string(p);
            return s;
          },
          [](const Settings& st) {
            return "Settings coi=" + std::to_string(st.coi) + " p=" + std::to_string(st.values[0]) +
                   " i=" + std::to_string(st.values[1]) + " d=" + std::to_string(st.values[2]) +
                   " servo-zero=" + std::to_string(st.values[3]);
          },
          [](const Set& st) {
            std::string s = "Set";
            for (std::size_t i = 0; i < st.values.size(); ++i)
              s += ' ' + std::string(kSetNames[i]) + '=' + shortest(st.values[i]);
            return s;
          },
          [](const Answer& a) {
            return "Answer" + (a.coi ? " coi=" + std::to_string(*a.coi) : std::string()) +
                   " code=" + std::to_string(a.code);
          },
          [](const SetRequest&) { return std::string("SetRequest"); },
          [](const Data& d) {
            return "Data state=" + std::string(to_string(d.state)) +
                   " t=" + std::to_string(d.timestamp_ms) +
                   "ms encoder=" + std::to_string(d.encoder) + " steering=" + shortest(d.steering) +
                   " motor-battery=" + std::to_string(d.motor_battery) +
                   " computer-battery=" + std::to_string(d.computer_battery);
          },
          [](const Map& map) {
            return "Map " + std::to_string(map.width) + "x" + std::to_string(map.height) + " (" +
                   std::to_string(map.rows.size()) + " rows)";
          },
          [](const LowFreqData& d) {
            return "LowFreqData state=" + std::string(to_string(d.state)) +
                   " t=" + std::to_string(d.timestamp_ms) +
                   "ms motor-battery=" + std::to_string(d.motor_battery) +
                   " computer-battery=" + std::to_string(d.computer_battery) +
                   " temperature=" + shortest(d.temperature);
          },
          [](const HighFreqData& d) {
            return "HighFreqData t=" + std::to_string(d.timestamp_ms) +
                   "ms encoder=" + shortest(d.encoder) + " steering=" + shortest(d.steering) +
                   " x=" + shortest(d.x) + " y=" + shortest(d.y) + " angle=" + shortest(d.angle);
          },
          [](const Control& c) {
            return "Control x=" + shortest(c.x_axis) + " y=" + shortest(c.y_axis);
          },
      },
      m);
}

}  // namespace hil::protocol::wr8::svgui
