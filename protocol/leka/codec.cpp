#include "protocol/leka/codec.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace hil::protocol::leka {
namespace {

constexpr std::string_view kStartText = "\x2A\x2B\x2C\x2D";
constexpr std::size_t kMinFrameBytes = kOverheadBytes + 1;
constexpr std::size_t kLargestFrameBytes = kOverheadBytes + 255;

std::string where(std::size_t group_index) {
  return "group byte " + std::to_string(group_index) + ", frame byte " +
         std::to_string(group_index + kHeaderBytes);
}

// Name of the group's first command, when its id is known: the context of
// errors found before the group could be parsed.
std::string first_command_name(ByteView frame, Dialect dialect) {
  if (frame.size() <= kHeaderBytes) return {};
  const CommandSpec* spec = find_spec(frame[kHeaderBytes], dialect);
  return spec != nullptr ? std::string(spec->name) : std::string();
}

// Where the frame would pass in the car's other convention, say so: the
// commonest cause of a frame refused here is a client of the other profile.
std::string other_profile_hint(ByteView frame, Dialect dialect) {
  const Dialect other = dialect == Dialect::readme ? Dialect::comspecs_v3 : Dialect::readme;
  const ByteView group = frame.subspan(kHeaderBytes, frame.size() - kOverheadBytes);
  if (checksum(group, other) != frame.back()) return {};
  return "; it matches profile " + std::string(to_string(other)) + " (--profile " +
         std::string(to_string(other)) + ")";
}

// The command an id is in the car's other convention, for error messages.
std::string other_id_hint(std::uint8_t id, Dialect dialect) {
  const Dialect other = dialect == Dialect::readme ? Dialect::comspecs_v3 : Dialect::readme;
  const CommandSpec* spec = find_spec(id, other);
  if (spec == nullptr) return {};
  return "; in profile " + std::string(to_string(other)) + " it is " + std::string(spec->name);
}

Item error_item(ByteView raw, ErrorKind kind, std::string detail, std::string context = {}) {
  return Item{
      DecodeError{kind, Bytes(raw.begin(), raw.end()), std::move(detail), std::move(context)}};
}

// A frame whose checksum is already known to be right: parse, then ranges.
Item decode_checked(ByteView raw, const DecoderOptions& options) {
  const ByteView group = raw.subspan(kHeaderBytes, raw.size() - kOverheadBytes);
  auto parsed = parse_group(group, options.dialect);
  if (auto* e = std::get_if<GroupError>(&parsed)) {
    return error_item(raw, e->kind, std::move(e->detail), std::move(e->context));
  }
  auto& commands = std::get<CommandGroup>(parsed);
  std::optional<ErrorKind> tolerated;
  std::size_t offset = 0;
  for (std::size_t i = 0; i < commands.commands.size(); ++i) {
    const Command& c = commands.commands[i];
    const CommandSpec& spec = spec_of(c);
    if (auto problem = range_problem(c, options.limits)) {
      if (!options.accept_out_of_range) {
        return error_item(raw, ErrorKind::bad_value,
                          std::string(spec.name) + " (command " + std::to_string(i + 1) + ", " +
                              where(offset) + "): " + *problem,
                          std::string(spec.name));
      }
      tolerated = ErrorKind::bad_value;
    }
    offset += 1 + spec.data_bytes;
  }
  return Item{Frame<Message>{std::move(commands), Bytes(raw.begin(), raw.end()), tolerated}};
}

std::string checksum_detail(ByteView candidate, Dialect dialect) {
  const ByteView group = candidate.subspan(kHeaderBytes, candidate.size() - kOverheadBytes);
  return "checksum byte " + hex_literal(candidate.back()) + " at frame byte " +
         std::to_string(candidate.size() - 1) + " does not match " +
         hex_literal(checksum(group, dialect)) + " computed over the " +
         (dialect == Dialect::readme ? "" : "length byte and the ") + std::to_string(group.size()) +
         "-byte command group" + other_profile_hint(candidate, dialect);
}

// The BSD checksum in a sum of `Sum`'s width: per byte, rotate right by one
// bit within that width, then add the byte (mod 2^width).
template <class Sum>
Sum bsd_sum(ByteView bytes) {
  constexpr unsigned kTopBit = sizeof(Sum) * 8 - 1;
  Sum sum = 0;
  for (const std::uint8_t b : bytes) {
    sum = static_cast<Sum>((sum >> 1) | ((sum & 1u) << kTopBit));
    sum = static_cast<Sum>(sum + b);
  }
  return sum;
}

}  // namespace

std::uint16_t bsd_checksum16(ByteView bytes) {
  return bsd_sum<std::uint16_t>(bytes);
}

std::uint8_t bsd_checksum8(ByteView bytes) {
  return bsd_sum<std::uint8_t>(bytes);
}

std::uint8_t checksum(ByteView group, Dialect dialect) {
  if (dialect == Dialect::readme) return static_cast<std::uint8_t>(bsd_checksum16(group) & 0xFFu);
  Bytes covered;
  covered.reserve(group.size() + 1);
  covered.push_back(static_cast<std::uint8_t>(group.size()));
  covered.insert(covered.end(), group.begin(), group.end());
  return bsd_checksum8(covered);
}

Bytes group_bytes(const CommandGroup& group, Dialect dialect) {
  Bytes out;
  for (const Command& c : group.commands) {
    const CommandSpec& spec = spec_of(c);
    if (!spec.in(dialect)) {
      throw std::invalid_argument("Leka: " + std::string(spec.name) + " is not a command of the " +
                                  std::string(to_string(dialect)) + " profile");
    }
    out.push_back(spec.id(dialect));
    const Bytes data = data_of(c);
    out.insert(out.end(), data.begin(), data.end());
  }
  return out;
}

Bytes frame_group(ByteView group, Dialect dialect) {
  if (group.size() > 255) {
    throw std::invalid_argument("Leka frame: a command group of " + std::to_string(group.size()) +
                                " bytes does not fit the one-byte length field");
  }
  Bytes out(kStartSequence.begin(), kStartSequence.end());
  out.push_back(static_cast<std::uint8_t>(group.size()));
  out.insert(out.end(), group.begin(), group.end());
  out.push_back(checksum(group, dialect));
  return out;
}

Bytes encode(const Message& m, const ValueLimits& limits, Dialect dialect) {
  if (m.commands.empty())
    throw std::invalid_argument("Leka encode: a command group needs a command");
  for (std::size_t i = 0; i < m.commands.size(); ++i) {
    if (auto problem = range_problem(m.commands[i], limits)) {
      throw std::invalid_argument("Leka encode: command " + std::to_string(i + 1) + " (" +
                                  std::string(spec_of(m.commands[i]).name) + "): " + *problem);
    }
  }
  const Bytes group = group_bytes(m, dialect);
  if (group.size() > kMaxGroupBytes) {
    throw std::invalid_argument("Leka encode: command group of " + std::to_string(group.size()) +
                                " bytes exceeds the robot's " + std::to_string(kMaxGroupBytes));
  }
  return frame_group(group, dialect);
}

std::variant<CommandGroup, GroupError> parse_group(ByteView group, Dialect dialect) {
  if (group.empty()) return GroupError{ErrorKind::bad_format, "empty command group", {}};
  CommandGroup out;
  std::size_t i = 0;
  while (i < group.size()) {
    const std::size_t number = out.commands.size() + 1;
    const CommandSpec* spec = find_spec(group[i], dialect);
    if (spec == nullptr) {
      return GroupError{ErrorKind::unknown_code,
                        "unknown command id " + hex_literal(group[i]) + " at " + where(i) +
                            " (command " + std::to_string(number) + ")" +
                            other_id_hint(group[i], dialect),
                        hex_literal(group[i])};
    }
    const std::size_t left = group.size() - i - 1;
    if (left < spec->data_bytes) {
      return GroupError{ErrorKind::bad_format,
                        std::string(spec->name) + " at " + where(i) + " (command " +
                            std::to_string(number) + ") needs " + std::to_string(spec->data_bytes) +
                            " data byte(s), the group has only " + std::to_string(left) + " left",
                        std::string(spec->name)};
    }
    out.commands.push_back(*make_command(*spec, group.subspan(i + 1, spec->data_bytes)));
    i += 1 + spec->data_bytes;
  }
  return out;
}

Item decode_frame(ByteView raw, const DecoderOptions& options) {
  if (raw.size() < kMinFrameBytes ||
      !std::equal(kStartSequence.begin(), kStartSequence.end(), raw.begin())) {
    return error_item(raw, ErrorKind::bad_format,
                      "not a Leka frame (2A 2B 2C 2D, length, group, checksum; at least 7 bytes)");
  }
  const std::size_t length = raw[kStartSequence.size()];
  if (length == 0) {
    return error_item(raw, ErrorKind::bad_format,
                      "length byte is 0; a command group holds at least one command");
  }
  if (length + kOverheadBytes > options.max_frame_bytes) {
    return error_item(raw, ErrorKind::oversized,
                      "length byte announces a " + std::to_string(length) +
                          "-byte command group; frames are limited to " +
                          std::to_string(options.max_frame_bytes) + " bytes",
                      first_command_name(raw, options.dialect));
  }
  if (length + kOverheadBytes != raw.size()) {
    return error_item(raw, ErrorKind::bad_format,
                      "length byte announces a " + std::to_string(length) +
                          "-byte command group, the frame carries " +
                          std::to_string(raw.size() - kOverheadBytes),
                      first_command_name(raw, options.dialect));
  }
  if (checksum(raw.subspan(kHeaderBytes, length), options.dialect) != raw.back()) {
    return error_item(raw, ErrorKind::bad_checksum, checksum_detail(raw, options.dialect),
                      first_command_name(raw, options.dialect));
  }
  return decode_checked(raw, options);
}

Decoder::Decoder(DecoderOptions options) : options_(options), start_(kStartText) {
  if (options_.max_frame_bytes < kMinFrameBytes || options_.max_frame_bytes > kLargestFrameBytes) {
    throw std::invalid_argument("Leka decoder: max_frame_bytes must be 7..261");
  }
  buf_.reserve(options_.max_frame_bytes + 1);
}

void Decoder::emit_error(std::size_t count, ErrorKind kind, std::string detail, std::string context,
                         std::vector<Item>& out) {
  const auto end = buf_.begin() + static_cast<std::ptrdiff_t>(count);
  out.emplace_back(
      DecodeError{kind, Bytes(buf_.begin(), end), std::move(detail), std::move(context)});
  buf_.erase(buf_.begin(), end);
  scan_ -= std::min(scan_, count);
}

void Decoder::restart_hunting() {
  state_ = State::hunting;
  start_.reset();
  scan_ = 0;
  need_ = 0;
}

std::size_t Decoder::resync_point(std::size_t end) const {
  // The first place after the candidate's own start where a start sequence
  // begins, or could begin with the bytes not seen yet.
  for (std::size_t k = 1; k < end; ++k) {
    const std::size_t n = std::min(kStartSequence.size(), buf_.size() - k);
    if (std::equal(buf_.begin() + static_cast<std::ptrdiff_t>(k),
                   buf_.begin() + static_cast<std::ptrdiff_t>(k + n), kStartSequence.begin())) {
      return k;
    }
  }
  return end;
}

void Decoder::feed(ByteView bytes, std::vector<Item>& out) {
  // One byte at a time keeps the buffer within its bound whatever the
  // caller's chunk size.
  for (const std::uint8_t b : bytes) {
    buf_.push_back(b);
    advance(out);
  }
}

void Decoder::advance(std::vector<Item>& out) {
  while (scan_ < buf_.size()) {
    const std::uint8_t b = buf_[scan_++];
    switch (state_) {
      case State::hunting:
        if (start_.feed(b)) {
          const std::size_t before = scan_ - kStartSequence.size();
          if (before > 0) {
            emit_error(before, ErrorKind::garbage,
                       std::to_string(before) + " byte(s) before a start sequence discarded", {},
                       out);
          }
          start_.reset();
          state_ = State::length;
        } else if (scan_ >= options_.max_frame_bytes) {
          // Keep a possible start-sequence prefix; the rest cannot start a frame.
          const std::size_t count = scan_ - start_.matched();
          emit_error(count, ErrorKind::garbage,
                     std::to_string(count) + " byte(s) without a start sequence discarded", {},
                     out);
        }
        break;
      case State::length:
        if (b == 0) {
          emit_error(scan_, ErrorKind::bad_format,
                     "length byte is 0 after a start sequence; a command group holds at least one "
                     "command",
                     {}, out);
          restart_hunting();
        } else if (std::size_t{b} + kOverheadBytes > options_.max_frame_bytes) {
          emit_error(scan_, ErrorKind::oversized,
                     "length byte " + hex_literal(b) + " announces a " + std::to_string(b) +
                         "-byte command group; frames are limited to " +
                         std::to_string(options_.max_frame_bytes) +
                         " bytes (the robot's serial buffer), so only the start sequence and "
                         "length are dropped and the search for the next start sequence resumes "
                         "right after them",
                     {}, out);
          restart_hunting();
        } else {
          need_ = std::size_t{b} + kOverheadBytes;
          state_ = State::body;
        }
        break;
      case State::body:
        if (scan_ == need_) complete_candidate(out);
        break;
    }
  }
}

void Decoder::complete_candidate(std::vector<Item>& out) {
  const ByteView candidate(buf_.data(), need_);
  const ByteView group = candidate.subspan(kHeaderBytes, need_ - kOverheadBytes);
  if (checksum(group, options_.dialect) == candidate.back()) {
    out.push_back(decode_checked(candidate, options_));
    buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(need_));
    restart_hunting();
    return;
  }
  const std::size_t k = resync_point(need_);
  std::string detail = checksum_detail(candidate, options_.dialect);
  if (k < need_) {
    detail += "; reported up to frame byte " + std::to_string(k) +
              ", where a start sequence begins and decoding resumes";
  }
  emit_error(k, ErrorKind::bad_checksum, std::move(detail),
             first_command_name(candidate, options_.dialect), out);
  restart_hunting();
}

void Decoder::finish(std::vector<Item>& out) {
  while (!buf_.empty()) {
    if (state_ == State::hunting) {
      emit_error(buf_.size(), ErrorKind::garbage,
                 std::to_string(buf_.size()) + " byte(s) without a complete frame at end of stream",
                 {}, out);
      break;
    }
    // A frame cut off by the end of the stream; a start sequence inside it
    // may still begin a complete frame.
    const std::size_t held = buf_.size();
    const std::size_t k = resync_point(held);
    std::string detail;
    if (state_ == State::length) {
      detail = "stream ended after a start sequence, before the length byte";
    } else {
      detail = "stream ended " + std::to_string(held) + " byte(s) into a frame of " +
               std::to_string(need_) + " bytes";
    }
    if (k < held) {
      detail += "; reported up to frame byte " + std::to_string(k) +
                ", where a start sequence begins and decoding resumes";
    }
    std::string context = first_command_name(ByteView(buf_.data(), k), options_.dialect);
    emit_error(k, ErrorKind::truncated, std::move(detail), std::move(context), out);
    restart_hunting();
    advance(out);
  }
  restart_hunting();
}

}  // namespace hil::protocol::leka
