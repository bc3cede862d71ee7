#pragma once
// The server side of RFC 2217 (Telnet COM-PORT-OPTION, option 44), without
// I/O: bytes from a client's TCP connection go in; data bytes for the
// serial device, the bytes to send back and the client's serial-port
// requests come out. libtelnet does the Telnet layer (option negotiation,
// subnegotiation framing, IAC escaping); the COM-PORT commands are hil's.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "protocol/common/bytes.hpp"

namespace hil::link {

using protocol::Bytes;
using protocol::ByteView;

/// Telnet option codes and COM-PORT-OPTION command codes (RFC 2217). The
/// server answers command N with N + 100.
namespace rfc2217 {
inline constexpr std::uint8_t kIac = 255;
inline constexpr std::uint8_t kDont = 254;
inline constexpr std::uint8_t kDo = 253;
inline constexpr std::uint8_t kWont = 252;
inline constexpr std::uint8_t kWill = 251;
inline constexpr std::uint8_t kSb = 250;
inline constexpr std::uint8_t kSe = 240;
inline constexpr std::uint8_t kBinary = 0;
inline constexpr std::uint8_t kEcho = 1;
inline constexpr std::uint8_t kSuppressGoAhead = 3;
inline constexpr std::uint8_t kComPortOption = 44;

inline constexpr std::uint8_t kSignature = 0;
inline constexpr std::uint8_t kSetBaudRate = 1;
inline constexpr std::uint8_t kSetDataSize = 2;
inline constexpr std::uint8_t kSetParity = 3;
inline constexpr std::uint8_t kSetStopSize = 4;
inline constexpr std::uint8_t kSetControl = 5;
inline constexpr std::uint8_t kNotifyLineState = 6;
inline constexpr std::uint8_t kNotifyModemState = 7;
inline constexpr std::uint8_t kFlowControlSuspend = 8;
inline constexpr std::uint8_t kFlowControlResume = 9;
inline constexpr std::uint8_t kSetLineStateMask = 10;
inline constexpr std::uint8_t kSetModemStateMask = 11;
inline constexpr std::uint8_t kPurgeData = 12;
inline constexpr std::uint8_t kServerOffset = 100;

/// The highest rate a client may set; above it the request is refused.
inline constexpr std::uint32_t kMaxBaud = 4'000'000;
}  // namespace rfc2217

enum class Parity : std::uint8_t { none = 1, odd = 2, even = 3, mark = 4, space = 5 };
/// RFC 2217's codes: 1 stop bit, 2 stop bits, 1.5 stop bits.
enum class StopBits : std::uint8_t { one = 1, two = 2, one_and_half = 3 };

/// The serial line as the client set it.
struct LineSettings {
  std::uint32_t baud = 0;
  std::uint8_t data_bits = 8;
  Parity parity = Parity::none;
  StopBits stop_bits = StopBits::one;
  friend bool operator==(const LineSettings&, const LineSettings&) = default;

  /// Bits on the line per character, doubled (1.5 stop bits stays whole):
  /// start + data + parity + stop. 8N1 is 20.
  unsigned half_bits_per_char() const;
  /// "9600 baud 8N1", "19200 baud 7E1.5".
  std::string describe() const;
};

/// What a client asked for, besides data.
struct Rfc2217Event {
  enum class Kind : std::uint8_t {
    line_changed,   ///< settings() hold a new rate or framing
    dtr,            ///< value 1: on, 0: off
    rts,            ///< value 1: on, 0: off
    break_state,    ///< value 1: on, 0: off
    flow_control,   ///< value: the SET-CONTROL code taken (1-3, 14-19)
    purge,          ///< value 1: data from the device, 2: data to it, 3: both
    suspend,        ///< hold the data to the client (FLOWCONTROL-SUSPEND)
    resume,         ///< send it again (FLOWCONTROL-RESUME)
    signature,      ///< text: the client's signature
    masks_changed,  ///< value: line-state mask << 8 | modem-state mask
    com_port_on,    ///< the client agreed to COM-PORT-OPTION
    problem,        ///< text: bad input, for the log; nothing else came of it
  };
  Kind kind;
  std::uint32_t value = 0;
  std::string text;
};

/// One client connection's Telnet/RFC 2217 state. Not thread-safe; one
/// per connection.
class Rfc2217Server {
 public:
  struct Config {
    /// The line before the client sets anything.
    LineSettings line;
    /// Sent when the client asks for the server's signature.
    std::string signature = "hil";
    /// The modem lines the server reports (CD, DSR and CTS on: a
    /// device that is present and ready).
    std::uint8_t modem_state = 0xB0;
  };

  explicit Rfc2217Server(Config config);
  ~Rfc2217Server();
  Rfc2217Server(const Rfc2217Server&) = delete;
  Rfc2217Server& operator=(const Rfc2217Server&) = delete;

  /// The server's opening: WILL/DO BINARY, WILL SUPPRESS-GO-AHEAD, DO
  /// COM-PORT-OPTION, into take_to_client().
  void open();
  /// Bytes from the client's connection, in any pieces.
  void receive(ByteView from_client);
  /// Data from the device for the client (0xFF doubled).
  void send_data(ByteView from_device);

  /// Data bytes for the device since the last call.
  Bytes take_to_device();
  /// Bytes for the client's connection since the last call.
  Bytes take_to_client();
  /// Events since the last call, in order.
  std::vector<Rfc2217Event> take_events();

  const LineSettings& settings() const { return config_.line; }
  bool dtr() const { return dtr_; }
  bool rts() const { return rts_; }

 private:
  struct Telnet;
  void on_telnet_data(ByteView bytes);
  void on_subnegotiation(std::uint8_t option, ByteView payload);
  void on_com_port(std::uint8_t command, ByteView value);
  void set_baud(ByteView value);
  void set_byte_setting(std::uint8_t command, ByteView value);
  void set_control(ByteView value);
  std::uint8_t control_answer(std::uint8_t request) const;
  void answer(std::uint8_t command, ByteView value);
  void answer(std::uint8_t command, std::uint8_t value);
  void event(Rfc2217Event::Kind kind, std::uint32_t value = 0, std::string text = {});
  void problem(std::string text);

  Config config_;
  std::unique_ptr<Telnet> telnet_;
  Bytes to_device_;
  Bytes to_client_;
  std::vector<Rfc2217Event> events_;
  bool dtr_ = true;
  bool rts_ = true;
  bool break_ = false;
  std::uint8_t outbound_flow_ = 1;  // no flow control
  std::uint8_t inbound_flow_ = 14;  // no flow control
  std::uint8_t linestate_mask_ = 0;
  std::uint8_t modemstate_mask_ = 255;
  // An overlong subnegotiation made libtelnet give up on it: what follows
  // up to its IAC SE is still part of it, not data.
  bool skipping_subnegotiation_ = false;
};

}  // namespace hil::link
