#pragma once
// WR8 packets: encode and incremental decode. A packet has no length prefix
// and no checksum; its length follows from its code and its size byte.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/wr8/message.hpp"
#include "protocol/wr8/profile.hpp"

namespace hil::protocol::wr8 {

/// Which side's packets a decoder expects.
enum class Sender : std::uint8_t {
  any,      ///< both directions (a wire tap, a test)
  gui,      ///< what a GUI sends: EMPTY, AUTH, TASK, SETTINGS (the vehicle side decodes these)
  vehicle,  ///< what a vehicle sends: EMPTY, AUTH-REPLY, SETTINGS, RESPONSE, DATA
};

/// Whether `sender` ever sends a packet starting with `code` (a code >= 7
/// is no packet at all).
bool sends(Sender sender, std::uint8_t code);

/// The packet for a message under a profile. Throws std::invalid_argument
/// when the packet could not be decoded back under the same profile: a
/// block that overflows its size byte, a DATA value wider than its
/// parameter, a DATA code the profile cannot size, an enum value outside its
/// table, a task with another parameter count than the profile's, or
/// `unparsed` bytes when sizes count entries.
Bytes encode(const Message& m, const Profile& profile = default_profile());

/// Like encode(), but only refuses what the bytes cannot hold (a block
/// past 255, a value wider than its parameter, a DATA code it cannot size):
/// task parameter counts and codes outside the tables go out as given, for
/// fault injection.
Bytes encode_unchecked(const Message& m, const Profile& profile = default_profile());

/// A packet byte for byte: `code` then `body`, no checks at all (wrong
/// size bytes, short bodies, unknown codes).
Bytes raw_packet(std::uint8_t code, ByteView body);

struct DecoderOptions {
  Profile profile;
  Sender sender = Sender::any;
  /// Longest packet accepted, and the most the decoder ever holds. 0 means
  /// the longest packet the profile can declare (longest_packet_bytes():
  /// 262 with the default profile), so nothing is oversized. Smaller values
  /// (at least kMinPacketLimit) turn longer packets into ErrorKind::oversized.
  std::size_t max_packet_bytes = 0;
};

/// AUTH is 11 bytes and the largest fixed header 7; a limit below this
/// would cut headers, so the decoder refuses it.
inline constexpr std::size_t kMinPacketLimit = 16;

using Item = DecodeItem<Message>;

/// Checks and parses one complete packet (code byte through last value
/// byte). Never throws.
Item decode_packet(ByteView raw, const DecoderOptions& options = {});

/// The stream decoder (its contract: protocol/common/decode.hpp). Holds at
/// most max_buffered() bytes: one packet up to the limit, or one run of
/// bytes that start no packet (such runs are reported in pieces of at most
/// that size).
class Decoder {
 public:
  /// Throws std::invalid_argument for an invalid profile or a limit below
  /// kMinPacketLimit (configuration errors, never input).
  explicit Decoder(DecoderOptions options = {});

  void feed(ByteView bytes, std::vector<Item>& out);
  void finish(std::vector<Item>& out);
  std::size_t buffered() const { return buf_.size(); }
  std::size_t max_buffered() const { return limit_; }

 private:
  enum class Mode : std::uint8_t { idle, run, packet };

  void start_packet(std::uint8_t code, std::vector<Item>& out);
  void packet_byte(std::uint8_t b, std::vector<Item>& out);
  void complete_packet(std::vector<Item>& out);
  void flush_run(std::vector<Item>& out);
  void emit_oversized_piece(std::vector<Item>& out);
  void reset_packet();

  DecoderOptions options_;
  std::size_t limit_;
  std::array<std::uint8_t, 256> data_size_{};  ///< value bytes per DATA code; 0 = unknown
  Bytes buf_;
  Mode mode_ = Mode::idle;
  ErrorKind run_kind_ = ErrorKind::garbage;

  // The packet being read.
  std::uint8_t code_ = 0;
  std::size_t pos_ = 0;           ///< bytes of the packet seen so far
  std::size_t total_ = 0;         ///< its length once known, else 0
  std::size_t size_at_ = 0;       ///< offset of its size byte (0: none)
  std::size_t entries_left_ = 0;  ///< DATA entries still to walk (entries mode)
  std::size_t next_code_at_ = 0;  ///< offset of the next DATA code byte (entries mode)
  bool cut_ = false;              ///< ended at a DATA code the profile cannot size
  bool oversized_ = false;        ///< longer than the limit: passed on in pieces
  std::size_t piece_start_ = 0;   ///< packet offset of buf_[0] while oversized
};

}  // namespace hil::protocol::wr8
