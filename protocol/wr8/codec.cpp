#include "protocol/wr8/codec.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "protocol/common/overloaded.hpp"

namespace hil::protocol::wr8 {
namespace {

constexpr std::size_t kMaxSizeByte = 255;
constexpr std::size_t kWordBytes = 4;
constexpr std::size_t kSettingEntryBytes = 5;  // type byte + value
constexpr std::size_t kDataHeaderBytes = 7;    // code, state, timestamp(4), size

std::string hex_byte(std::uint8_t b) {
  constexpr char kHex[] = "0123456789ABCDEF";
  return std::string("0x") + kHex[b >> 4] + kHex[b & 0x0F];
}

std::string plural(std::size_t n, std::string_view word) {
  return std::to_string(n) + ' ' + std::string(word) + (n == 1 ? "" : "s");
}

void put(Bytes& out, std::uint32_t bits, std::size_t size, ByteOrder order) {
  for (std::size_t i = 0; i < size; ++i) {
    const std::size_t shift = 8 * (order == ByteOrder::little ? i : size - 1 - i);
    out.push_back(static_cast<std::uint8_t>(bits >> shift));
  }
}

std::uint32_t get(ByteView raw, std::size_t at, std::size_t size, ByteOrder order) {
  std::uint32_t bits = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const std::size_t shift = 8 * (order == ByteOrder::little ? i : size - 1 - i);
    bits |= static_cast<std::uint32_t>(raw[at + i]) << shift;
  }
  return bits;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("WR8 encode: " + what);
}

std::uint8_t size_byte(std::size_t entries, std::size_t bytes, const Profile& profile,
                       std::string_view packet) {
  const std::size_t value = profile.block_unit == BlockSizeUnit::bytes ? bytes : entries;
  require(value <= kMaxSizeByte, std::string(packet) + " block of " + std::to_string(value) + ' ' +
                                     std::string(to_string(profile.block_unit)) +
                                     " does not fit its size byte (255 at most)");
  return static_cast<std::uint8_t>(value);
}

Bytes encode_impl(const Message& m, const Profile& profile, bool checked) {
  const ByteOrder order = profile.byte_order;
  Bytes out;
  out.push_back(static_cast<std::uint8_t>(code_of(m)));
  std::visit(
      Overloaded{
          [&](const Empty&) {},
          [&](const Auth& v) { out.insert(out.end(), v.text.begin(), v.text.end()); },
          [&](const AuthReply& v) {
            require(
                !checked || static_cast<std::size_t>(v.state) < kAllStates.size(),
                "AUTH-REPLY state " + std::to_string(static_cast<int>(v.state)) + " is not 0..3");
            out.insert(out.end(), {v.device_code, v.device_id, static_cast<std::uint8_t>(v.state)});
          },
          [&](const Task& v) {
            const auto t = static_cast<std::size_t>(v.task);
            if (checked) {
              require(t < kTaskCount, "task code " + std::to_string(t) + " is not 0..4");
              require(v.params.size() == profile.task_parameter_count[t],
                      "task " + std::string(to_string(v.task)) + " takes " +
                          plural(profile.task_parameter_count[t], "parameter") + ", not " +
                          std::to_string(v.params.size()));
            }
            out.insert(out.end(),
                       {v.coi, static_cast<std::uint8_t>(v.task),
                        size_byte(v.params.size(), v.params.size() * kWordBytes, profile, "TASK")});
            for (const Word w : v.params)
              put(out, w.bits, kWordBytes, order);
          },
          [&](const Settings& v) {
            out.push_back(v.coi);
            out.push_back(size_byte(v.params.size(), v.params.size() * kSettingEntryBytes, profile,
                                    "SETTINGS"));
            for (const auto& s : v.params) {
              require(!checked || static_cast<std::size_t>(s.code) < kSettingCount,
                      "setting type " + std::to_string(static_cast<int>(s.code)) + " is not 0..3");
              out.push_back(static_cast<std::uint8_t>(s.code));
              put(out, s.value.bits, kWordBytes, order);
            }
          },
          [&](const Response& v) {
            require(!checked || static_cast<std::size_t>(v.code) < kAllResponseCodes.size(),
                    "response code " + std::to_string(static_cast<int>(v.code)) + " is not 0..2");
            out.insert(out.end(), {v.coi, static_cast<std::uint8_t>(v.code)});
          },
          [&](const Data& v) {
            require(!checked || static_cast<std::size_t>(v.state) < kAllStates.size(),
                    "DATA state " + std::to_string(static_cast<int>(v.state)) + " is not 0..3");
            out.push_back(static_cast<std::uint8_t>(v.state));
            put(out, v.timestamp_ms, kWordBytes, order);
            const std::size_t size_at = out.size();
            out.push_back(0);
            for (const auto& d : v.values) {
              const DataParameter* p = profile.data_parameter(d.code);
              require(p != nullptr, "DATA code " + std::to_string(d.code) +
                                        " is not in the profile, so its size is unknown");
              require(p->size_bytes >= 4 || (d.value.bits >> (8 * p->size_bytes)) == 0,
                      "DATA " + p->name + " value " + std::to_string(d.value.bits) +
                          " does not fit " + plural(p->size_bytes, "byte"));
              out.push_back(d.code);
              put(out, d.value.bits, p->size_bytes, order);
            }
            if (!v.unparsed.empty()) {
              require(profile.block_unit == BlockSizeUnit::bytes,
                      "DATA unparsed bytes cannot be carried when sizes count entries");
              require(!checked || profile.data_parameter(v.unparsed.front()) == nullptr,
                      "DATA unparsed bytes must start with a code the profile does not know");
              out.insert(out.end(), v.unparsed.begin(), v.unparsed.end());
            }
            out[size_at] = size_byte(v.values.size(), out.size() - size_at - 1, profile, "DATA");
          }},
      m);
  return out;
}

/// The length of a packet of `code` when it is fixed; 0 for the packets
/// whose block size byte gives it.
constexpr std::size_t fixed_length(PacketCode code) {
  switch (code) {
    case PacketCode::empty:
      return 1;
    case PacketCode::auth:
      return 1 + kAuthTextBytes;
    case PacketCode::auth_reply:
      return 4;
    case PacketCode::response:
      return 3;
    default:
      return 0;
  }
}

/// Where the block size byte of a packet of `code` is; 0 for fixed-length
/// packets.
constexpr std::size_t size_byte_at(PacketCode code) {
  switch (code) {
    case PacketCode::task:
      return 3;
    case PacketCode::settings:
      return 2;
    case PacketCode::data:
      return kDataHeaderBytes - 1;
    default:
      return 0;
  }
}

/// One complete packet being checked by decode_packet, and its items.
struct Packet {
  ByteView raw;
  std::string context;  ///< the packet's name, once its code is known

  Item error(ErrorKind kind, std::string detail) const {
    return Item{DecodeError{kind, Bytes(raw.begin(), raw.end()), std::move(detail), context}};
  }
  Item frame(Message m, std::optional<ErrorKind> tolerated = std::nullopt) const {
    return Item{Frame<Message>{std::move(m), Bytes(raw.begin(), raw.end()), tolerated}};
  }
  /// The error when the packet is not exactly `length` bytes long.
  std::optional<Item> length_error(std::size_t length) const {
    if (raw.size() < length) {
      return error(ErrorKind::truncated, context + " packet needs " + plural(length, "byte") +
                                             ", only " + std::to_string(raw.size()) + " present");
    }
    if (raw.size() > length) {
      return error(ErrorKind::bad_format, context + " packet is " + plural(length, "byte") + ", " +
                                              std::to_string(raw.size() - length) +
                                              " more follow it");
    }
    return std::nullopt;
  }
  /// How many entries of `entry_bytes` the block after the size byte at
  /// `at` holds, the block ending the packet; or the error: the packet ends
  /// before the size byte, a size in bytes is no multiple of `entry_bytes`
  /// (`entry_note` adds what an entry is), or the length does not match.
  std::variant<std::size_t, Item> block_entries(const Profile& profile, std::size_t at,
                                                std::size_t entry_bytes,
                                                std::string_view entry_note = {}) const {
    if (raw.size() < at + 1) return *length_error(at + 1);
    const bool in_bytes = profile.block_unit == BlockSizeUnit::bytes;
    const std::size_t size = raw[at];
    if (in_bytes && size % entry_bytes != 0) {
      return error(ErrorKind::bad_format, "parameter block size " + std::to_string(size) +
                                              " (byte " + std::to_string(at) +
                                              ") is not a multiple of " +
                                              std::to_string(entry_bytes) + " bytes" +
                                              std::string(entry_note));
    }
    const std::size_t count = in_bytes ? size / entry_bytes : size;
    if (auto e = length_error(at + 1 + count * entry_bytes)) return *e;
    return count;
  }
};

Item decode_task(const Packet& p, const Profile& profile) {
  const ByteView raw = p.raw;
  const auto entries = p.block_entries(profile, 3, kWordBytes);
  if (const auto* e = std::get_if<Item>(&entries)) return *e;
  const std::size_t count = std::get<std::size_t>(entries);
  const std::uint8_t t = raw[2];
  if (t >= kTaskCount) {
    return p.error(ErrorKind::unknown_code,
                   "task code " + std::to_string(t) + " (byte 2) is not 0..4; packet skipped");
  }
  const auto task = static_cast<TaskCode>(t);
  if (count != profile.task_parameter_count[t]) {
    return p.error(ErrorKind::bad_format, "task " + std::string(to_string(task)) + " takes " +
                                              plural(profile.task_parameter_count[t], "parameter") +
                                              ", the packet carries " + std::to_string(count));
  }
  Task m{raw[1], task, {}};
  for (std::size_t i = 0; i < count; ++i) {
    m.params.push_back(Word{get(raw, 4 + i * kWordBytes, kWordBytes, profile.byte_order)});
  }
  return p.frame(std::move(m));
}

Item decode_settings(const Packet& p, const Profile& profile) {
  const ByteView raw = p.raw;
  const auto entries =
      p.block_entries(profile, 2, kSettingEntryBytes, " (type byte + 4-byte value)");
  if (const auto* e = std::get_if<Item>(&entries)) return *e;
  const std::size_t count = std::get<std::size_t>(entries);
  Settings m{raw[1], {}};
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t at = 3 + i * kSettingEntryBytes;
    if (raw[at] >= kSettingCount) {
      return p.error(ErrorKind::unknown_code, "setting type " + std::to_string(raw[at]) +
                                                  " (entry " + std::to_string(i + 1) + ", byte " +
                                                  std::to_string(at) +
                                                  ") is not 0..3; packet skipped");
    }
    m.params.push_back(Setting{static_cast<SettingCode>(raw[at]),
                               Word{get(raw, at + 1, kWordBytes, profile.byte_order)}});
  }
  return p.frame(std::move(m));
}

/// DATA entries when the size byte counts bytes: the block is framed, so
/// a code the profile cannot size ends the entries and the rest is kept.
Item decode_data_values_in_bytes(const Packet& p, const Profile& profile, Data m) {
  const ByteView raw = p.raw;
  for (std::size_t at = kDataHeaderBytes; at < raw.size();) {
    const DataParameter* d = profile.data_parameter(raw[at]);
    if (d == nullptr) {
      m.unparsed.assign(raw.begin() + static_cast<std::ptrdiff_t>(at), raw.end());
      return p.frame(std::move(m), ErrorKind::unknown_code);
    }
    if (at + 1 + d->size_bytes > raw.size()) {
      return p.error(ErrorKind::bad_format,
                     "entry " + d->name + " (code " + std::to_string(d->code) + ") at byte " +
                         std::to_string(at) + " needs " + plural(d->size_bytes, "value byte") +
                         ", the block has " + std::to_string(raw.size() - at - 1) + " left");
    }
    m.values.push_back(
        DataValue{d->code, Word{get(raw, at + 1, d->size_bytes, profile.byte_order)}});
    at += 1 + d->size_bytes;
  }
  return p.frame(std::move(m));
}

/// DATA entries when the size byte counts entries: each code's size frames
/// the next entry, so a code the profile cannot size ends the packet.
Item decode_data_values_in_entries(const Packet& p, const Profile& profile, Data m) {
  const ByteView raw = p.raw;
  const std::size_t size = raw[kDataHeaderBytes - 1];
  std::size_t at = kDataHeaderBytes;
  for (std::size_t i = 0; i < size; ++i) {
    if (at >= raw.size()) return *p.length_error(at + 1);
    const DataParameter* d = profile.data_parameter(raw[at]);
    if (d == nullptr) {
      if (at + 1 == raw.size()) {
        return p.error(ErrorKind::unknown_code,
                       "entry " + std::to_string(i + 1) + " has code " + std::to_string(raw[at]) +
                           ", which the profile cannot size; with sizes counting entries the "
                           "packet cannot be framed past it, so decoding resumes after this byte");
      }
      return p.error(ErrorKind::unknown_code, "entry " + std::to_string(i + 1) + " has code " +
                                                  std::to_string(raw[at]) +
                                                  ", which the profile cannot size");
    }
    if (at + 1 + d->size_bytes > raw.size()) return *p.length_error(at + 1 + d->size_bytes);
    m.values.push_back(
        DataValue{d->code, Word{get(raw, at + 1, d->size_bytes, profile.byte_order)}});
    at += 1 + d->size_bytes;
  }
  if (auto e = p.length_error(at)) return *e;
  return p.frame(std::move(m));
}

Item decode_data(const Packet& p, const Profile& profile) {
  const ByteView raw = p.raw;
  const bool in_bytes = profile.block_unit == BlockSizeUnit::bytes;
  if (raw.size() < kDataHeaderBytes) return *p.length_error(kDataHeaderBytes);
  if (in_bytes) {
    if (auto e = p.length_error(kDataHeaderBytes + raw[kDataHeaderBytes - 1])) return *e;
  }
  if (raw[1] >= kAllStates.size()) {
    return p.error(ErrorKind::bad_value, "state code " + std::to_string(raw[1]) +
                                             " (byte 1) is not 0..3 (FAULT, RUN, STOP, WAIT)");
  }
  Data m;
  m.state = static_cast<State>(raw[1]);
  m.timestamp_ms = get(raw, 2, kWordBytes, profile.byte_order);
  if (in_bytes) return decode_data_values_in_bytes(p, profile, std::move(m));
  return decode_data_values_in_entries(p, profile, std::move(m));
}

}  // namespace

bool sends(Sender sender, std::uint8_t code) {
  if (code >= kPacketCodeCount) return false;
  switch (static_cast<PacketCode>(code)) {
    case PacketCode::empty:
    case PacketCode::settings:
      return true;
    case PacketCode::auth:
    case PacketCode::task:
      return sender != Sender::vehicle;
    case PacketCode::auth_reply:
    case PacketCode::response:
    case PacketCode::data:
      return sender != Sender::gui;
  }
  return false;
}

Bytes encode(const Message& m, const Profile& profile) {
  return encode_impl(m, profile, true);
}

Bytes encode_unchecked(const Message& m, const Profile& profile) {
  return encode_impl(m, profile, false);
}

Bytes raw_packet(std::uint8_t code, ByteView body) {
  Bytes out;
  out.reserve(body.size() + 1);
  out.push_back(code);
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

Item decode_packet(ByteView raw, const DecoderOptions& options) {
  Packet p{raw, {}};
  if (raw.empty()) return p.error(ErrorKind::bad_format, "no bytes");
  const std::uint8_t code = raw[0];
  if (code >= kPacketCodeCount) {
    return p.error(ErrorKind::garbage,
                   "first byte " + hex_byte(code) + " is not a packet code (0..6)");
  }
  const auto packet = static_cast<PacketCode>(code);
  p.context = to_string(packet);
  if (!sends(options.sender, code)) {
    return p.error(ErrorKind::unknown_code,
                   p.context + " is not a packet the " +
                       (options.sender == Sender::gui ? "GUI" : "vehicle") + " sends");
  }
  if (const std::size_t length = fixed_length(packet)) {
    if (auto e = p.length_error(length)) return *e;
  }
  switch (packet) {
    case PacketCode::empty:
      return p.frame(Empty{});
    case PacketCode::auth: {
      Auth a;
      std::copy(raw.begin() + 1, raw.end(), a.text.begin());
      return p.frame(a);
    }
    case PacketCode::auth_reply:
      if (raw[3] >= kAllStates.size()) {
        return p.error(ErrorKind::bad_value, "state code " + std::to_string(raw[3]) +
                                                 " (byte 3) is not 0..3 (FAULT, RUN, STOP, WAIT)");
      }
      return p.frame(AuthReply{raw[1], raw[2], static_cast<State>(raw[3])});
    case PacketCode::response:
      if (raw[2] >= kAllResponseCodes.size()) {
        return p.error(ErrorKind::unknown_code,
                       "response code " + std::to_string(raw[2]) + " (byte 2) is not 0..2");
      }
      return p.frame(Response{raw[1], static_cast<ResponseCode>(raw[2])});
    case PacketCode::task:
      return decode_task(p, options.profile);
    case PacketCode::settings:
      return decode_settings(p, options.profile);
    case PacketCode::data:
      return decode_data(p, options.profile);
  }
  return p.error(ErrorKind::bad_format, "unreachable");
}

Decoder::Decoder(DecoderOptions options) : options_(std::move(options)), limit_(0) {
  options_.profile.validate();
  limit_ = options_.max_packet_bytes == 0 ? longest_packet_bytes(options_.profile)
                                          : options_.max_packet_bytes;
  if (limit_ < kMinPacketLimit) {
    throw std::invalid_argument("WR8 decoder: max_packet_bytes " + std::to_string(limit_) +
                                " is below " + std::to_string(kMinPacketLimit));
  }
  for (const auto& p : options_.profile.data_parameters)
    data_size_[p.code] = p.size_bytes;
  buf_.reserve(limit_);
}

void Decoder::reset_packet() {
  mode_ = Mode::idle;
  buf_.clear();
  total_ = 0;
  size_at_ = 0;
  entries_left_ = 0;
  next_code_at_ = 0;
  cut_ = false;
  oversized_ = false;
  piece_start_ = 0;
}

void Decoder::flush_run(std::vector<Item>& out) {
  if (mode_ != Mode::run) return;
  DecodeError e;
  e.kind = run_kind_;
  if (run_kind_ == ErrorKind::garbage) {
    e.detail = plural(buf_.size(), "byte") +
               " skipped: not a packet code (codes are 0..6), first " + hex_byte(buf_.front());
  } else {
    e.context = std::string(to_string(static_cast<PacketCode>(buf_.front())));
    e.detail = plural(buf_.size(), "packet code byte") + " skipped: the " +
               (options_.sender == Sender::gui ? "GUI" : "vehicle") + " does not send " +
               e.context + " (first " + hex_byte(buf_.front()) + ")";
  }
  e.raw = std::move(buf_);
  out.emplace_back(std::move(e));
  buf_.clear();
  buf_.reserve(limit_);
  mode_ = Mode::idle;
}

void Decoder::start_packet(std::uint8_t code, std::vector<Item>& out) {
  reset_packet();
  mode_ = Mode::packet;
  code_ = code;
  buf_.push_back(code);
  pos_ = 1;
  total_ = fixed_length(static_cast<PacketCode>(code));
  size_at_ = size_byte_at(static_cast<PacketCode>(code));
  if (pos_ == total_) complete_packet(out);
}

void Decoder::packet_byte(std::uint8_t b, std::vector<Item>& out) {
  buf_.push_back(b);
  const std::size_t at = pos_++;
  if (total_ == 0) {
    const bool in_bytes = options_.profile.block_unit == BlockSizeUnit::bytes;
    if (at == size_at_) {
      if (in_bytes) {
        total_ = at + 1 + b;
      } else if (code_ == static_cast<std::uint8_t>(PacketCode::task)) {
        total_ = 4 + std::size_t{b} * kWordBytes;
      } else if (code_ == static_cast<std::uint8_t>(PacketCode::settings)) {
        total_ = 3 + std::size_t{b} * kSettingEntryBytes;
      } else {
        entries_left_ = b;
        next_code_at_ = kDataHeaderBytes;
        if (b == 0) total_ = kDataHeaderBytes;
      }
    } else if (at == next_code_at_ && at >= kDataHeaderBytes) {
      const std::size_t size = data_size_[b];
      if (size == 0) {
        cut_ = true;
        total_ = at + 1;
      } else {
        next_code_at_ = at + 1 + size;
        if (--entries_left_ == 0) total_ = next_code_at_;
      }
    }
  }
  if (total_ != 0 && pos_ == total_) {
    complete_packet(out);
  } else if (buf_.size() >= limit_) {
    emit_oversized_piece(out);
  }
}

void Decoder::emit_oversized_piece(std::vector<Item>& out) {
  const std::string name(to_string(static_cast<PacketCode>(code_)));
  const std::size_t from = piece_start_ + 1;
  const std::size_t to = piece_start_ + buf_.size();
  const bool last = total_ != 0 && pos_ == total_;
  DecodeError e;
  e.kind = ErrorKind::oversized;
  e.context = name;
  if (!oversized_) {
    e.detail = name + " packet longer than the " + std::to_string(limit_) + "-byte limit";
    if (total_ != 0) e.detail += " (its header declares " + std::to_string(total_) + " bytes)";
    e.detail += "; bytes 1.." + std::to_string(to) + " here, the rest follows in further pieces";
  } else {
    e.detail = "bytes " + std::to_string(from) + ".." + std::to_string(to) +
               (last ? " (the end)" : "") + " of an oversized " + name + " packet";
  }
  e.raw = std::move(buf_);
  out.emplace_back(std::move(e));
  buf_.clear();
  buf_.reserve(limit_);
  piece_start_ = to;
  oversized_ = true;
}

void Decoder::complete_packet(std::vector<Item>& out) {
  if (oversized_) {
    emit_oversized_piece(out);
  } else {
    out.push_back(decode_packet(buf_, options_));
  }
  reset_packet();
}

void Decoder::feed(ByteView bytes, std::vector<Item>& out) {
  for (const std::uint8_t b : bytes) {
    if (mode_ == Mode::packet) {
      packet_byte(b, out);
      continue;
    }
    if (sends(options_.sender, b)) {
      flush_run(out);
      start_packet(b, out);
      continue;
    }
    const ErrorKind kind = b < kPacketCodeCount ? ErrorKind::unknown_code : ErrorKind::garbage;
    if (mode_ == Mode::run && kind != run_kind_) flush_run(out);
    mode_ = Mode::run;
    run_kind_ = kind;
    buf_.push_back(b);
    if (buf_.size() >= limit_) flush_run(out);
  }
}

void Decoder::finish(std::vector<Item>& out) {
  if (mode_ == Mode::packet && !buf_.empty()) {
    // (Empty only right after an oversized piece: those bytes are reported.)
    const std::string name(to_string(static_cast<PacketCode>(code_)));
    DecodeError e;
    e.kind = ErrorKind::truncated;
    e.context = name;
    e.detail = "stream ended " + std::to_string(pos_) + " byte(s) into a " + name + " packet";
    if (total_ != 0) e.detail += " of " + std::to_string(total_);
    if (oversized_) e.detail += " (oversized; earlier bytes were reported before)";
    e.raw = std::move(buf_);
    out.emplace_back(std::move(e));
    buf_.clear();
  }
  flush_run(out);
  reset_packet();
}

}  // namespace hil::protocol::wr8
