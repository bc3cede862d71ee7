#include "link/rfc2217.hpp"

#include <libtelnet.h>

#include <algorithm>
#include <string_view>
#include <utility>

namespace hil::link {

unsigned LineSettings::half_bits_per_char() const {
  const unsigned stop = stop_bits == StopBits::one ? 2 : stop_bits == StopBits::two ? 4 : 3;
  return 2 * (1 + data_bits + (parity == Parity::none ? 0 : 1)) + stop;
}

std::string LineSettings::describe() const {
  static constexpr std::string_view kParity = "?NOEMS";
  std::string text = std::to_string(baud) + " baud " + std::to_string(data_bits);
  text += kParity[static_cast<std::size_t>(parity)];
  text += stop_bits == StopBits::one ? "1" : stop_bits == StopBits::two ? "2" : "1.5";
  return text;
}

namespace {

// What hil offers and accepts: an 8-bit data path both ways, no go-ahead,
// and the COM port option. Anything else (ECHO, LINEMODE, ...) is refused.
const telnet_telopt_t kTelnetOptions[] = {
    {rfc2217::kBinary, TELNET_WILL, TELNET_DO},
    {rfc2217::kSuppressGoAhead, TELNET_WILL, TELNET_DO},
    {rfc2217::kComPortOption, TELNET_WILL, TELNET_DO},
    {-1, 0, 0},
};

constexpr std::uint8_t kTelnetNop = 241;
constexpr std::uint8_t kTelnetDataMark = 242;
constexpr std::uint8_t kTelnetGoAhead = 249;

/// A client's text for a log line: printable ASCII, at most 64 characters.
std::string printable_text(ByteView bytes) {
  std::string text;
  for (const std::uint8_t b : bytes) {
    if (text.size() == 64) {
      text += "...";
      break;
    }
    text += (b >= 0x20 && b < 0x7F) ? static_cast<char>(b) : '?';
  }
  return text;
}

std::string com_port_command_name(std::uint8_t command) {
  static constexpr std::string_view kNames[] = {
      "SIGNATURE",           "SET-BAUDRATE",       "SET-DATASIZE",       "SET-PARITY",
      "SET-STOPSIZE",        "SET-CONTROL",        "NOTIFY-LINESTATE",   "NOTIFY-MODEMSTATE",
      "FLOWCONTROL-SUSPEND", "FLOWCONTROL-RESUME", "SET-LINESTATE-MASK", "SET-MODEMSTATE-MASK",
      "PURGE-DATA"};
  if (command < std::size(kNames)) return std::string(kNames[command]);
  return "command " + std::to_string(command);
}

}  // namespace

struct Rfc2217Server::Telnet {
  explicit Telnet(Rfc2217Server& server)
      : state(telnet_init(kTelnetOptions, &Telnet::handle, 0, &server)) {}
  ~Telnet() {
    if (state != nullptr) telnet_free(state);
  }
  Telnet(const Telnet&) = delete;
  Telnet& operator=(const Telnet&) = delete;

  static void handle(telnet_t* /*telnet*/, telnet_event_t* ev, void* user) {
    auto& server = *static_cast<Rfc2217Server*>(user);
    switch (ev->type) {
      case TELNET_EV_DATA:
        server.on_telnet_data(
            ByteView(reinterpret_cast<const std::uint8_t*>(ev->data.buffer), ev->data.size));
        break;
      case TELNET_EV_SEND: {
        const auto* p = reinterpret_cast<const std::uint8_t*>(ev->data.buffer);
        server.to_client_.insert(server.to_client_.end(), p, p + ev->data.size);
        break;
      }
      case TELNET_EV_IAC:
        if (ev->iac.cmd == rfc2217::kSe && server.skipping_subnegotiation_) {
          server.skipping_subnegotiation_ = false;
        } else if (ev->iac.cmd != kTelnetNop && ev->iac.cmd != kTelnetDataMark &&
                   ev->iac.cmd != kTelnetGoAhead) {
          server.problem("Telnet command " + std::to_string(ev->iac.cmd) + " ignored");
        }
        break;
      case TELNET_EV_WILL:
        if (ev->neg.telopt == rfc2217::kComPortOption) {
          server.event(Rfc2217Event::Kind::com_port_on);
          // The modem lines as they are now, so a client that reads CTS or
          // DSR has a value without polling.
          server.answer(
              rfc2217::kNotifyModemState,
              static_cast<std::uint8_t>(server.config_.modem_state & server.modemstate_mask_));
        }
        break;
      case TELNET_EV_SUBNEGOTIATION:
        server.on_subnegotiation(
            ev->sub.telopt,
            ByteView(reinterpret_cast<const std::uint8_t*>(ev->sub.buffer), ev->sub.size));
        break;
      case TELNET_EV_WARNING:
      case TELNET_EV_ERROR: {
        const std::string_view message = ev->error.msg != nullptr ? ev->error.msg : "";
        if (message.find("buffer size limit") != std::string_view::npos)
          server.skipping_subnegotiation_ = true;
        server.problem("Telnet: " + std::string(message));
        break;
      }
      default:
        break;
    }
  }

  telnet_t* state;
};

Rfc2217Server::Rfc2217Server(Config config)
    : config_(std::move(config)), telnet_(std::make_unique<Telnet>(*this)) {}

Rfc2217Server::~Rfc2217Server() = default;

void Rfc2217Server::open() {
  telnet_negotiate(telnet_->state, TELNET_WILL, rfc2217::kBinary);
  telnet_negotiate(telnet_->state, TELNET_DO, rfc2217::kBinary);
  telnet_negotiate(telnet_->state, TELNET_WILL, rfc2217::kSuppressGoAhead);
  telnet_negotiate(telnet_->state, TELNET_DO, rfc2217::kComPortOption);
}

void Rfc2217Server::receive(ByteView from_client) {
  // A byte at a time: on input that breaks the Telnet grammar (an IAC and a
  // command byte inside a subnegotiation) libtelnet's recovery depends on
  // where a read ended, so the same bytes in other TCP segments could give
  // the device other data. Fed singly they give the same whatever the
  // segments; at serial rates the calls cost nothing that shows.
  for (const std::uint8_t byte : from_client) {
    const char c = static_cast<char>(byte);
    telnet_recv(telnet_->state, &c, 1);
  }
}

void Rfc2217Server::send_data(ByteView from_device) {
  if (from_device.empty()) return;
  telnet_send(telnet_->state, reinterpret_cast<const char*>(from_device.data()),
              from_device.size());
}

Bytes Rfc2217Server::take_to_device() {
  return std::exchange(to_device_, {});
}

Bytes Rfc2217Server::take_to_client() {
  return std::exchange(to_client_, {});
}

std::vector<Rfc2217Event> Rfc2217Server::take_events() {
  return std::exchange(events_, {});
}

void Rfc2217Server::on_telnet_data(ByteView bytes) {
  if (skipping_subnegotiation_) return;
  to_device_.insert(to_device_.end(), bytes.begin(), bytes.end());
}

void Rfc2217Server::on_subnegotiation(std::uint8_t option, ByteView payload) {
  if (option != rfc2217::kComPortOption) {
    problem("subnegotiation of Telnet option " + std::to_string(option) + " ignored");
    return;
  }
  if (payload.empty()) {
    problem("COM-PORT-OPTION subnegotiation without a command; ignored");
    return;
  }
  on_com_port(payload[0], payload.subspan(1));
}

void Rfc2217Server::on_com_port(std::uint8_t command, ByteView value) {
  switch (command) {
    case rfc2217::kSignature:
      if (value.empty()) {
        const Bytes text(config_.signature.begin(), config_.signature.end());
        answer(rfc2217::kSignature, text);
      } else {
        event(Rfc2217Event::Kind::signature, 0, printable_text(value));
      }
      return;
    case rfc2217::kSetBaudRate:
      set_baud(value);
      return;
    case rfc2217::kSetDataSize:
    case rfc2217::kSetParity:
    case rfc2217::kSetStopSize:
      set_byte_setting(command, value);
      return;
    case rfc2217::kSetControl:
      set_control(value);
      return;
    case rfc2217::kNotifyLineState:
      // A poll: the line has no errors to report.
      answer(rfc2217::kNotifyLineState, std::uint8_t{0});
      return;
    case rfc2217::kNotifyModemState:
      answer(rfc2217::kNotifyModemState, config_.modem_state);
      return;
    case rfc2217::kFlowControlSuspend:
      event(Rfc2217Event::Kind::suspend);
      return;
    case rfc2217::kFlowControlResume:
      event(Rfc2217Event::Kind::resume);
      return;
    default:
      break;
  }
  if (command == rfc2217::kSetLineStateMask || command == rfc2217::kSetModemStateMask ||
      command == rfc2217::kPurgeData) {
    if (value.size() != 1) {
      problem(com_port_command_name(command) + " with " + std::to_string(value.size()) +
              " value byte(s), expected 1; ignored");
      return;
    }
    const std::uint8_t v = value[0];
    if (command == rfc2217::kPurgeData) {
      if (v < 1 || v > 3) {
        problem("PURGE-DATA " + std::to_string(v) + " is not 1, 2 or 3; ignored");
        return;
      }
      event(Rfc2217Event::Kind::purge, v);
    } else {
      (command == rfc2217::kSetLineStateMask ? linestate_mask_ : modemstate_mask_) = v;
      event(Rfc2217Event::Kind::masks_changed,
            static_cast<std::uint32_t>(linestate_mask_) << 8 | modemstate_mask_);
    }
    answer(command, v);
    return;
  }
  problem("unknown COM-PORT-OPTION " + com_port_command_name(command) + " (" +
          std::to_string(value.size()) + " value byte(s)); ignored");
}

void Rfc2217Server::set_baud(ByteView value) {
  if (value.size() != 4) {
    problem("SET-BAUDRATE with " + std::to_string(value.size()) +
            " value byte(s), expected 4; ignored");
    return;
  }
  const std::uint32_t baud = static_cast<std::uint32_t>(value[0]) << 24 |
                             static_cast<std::uint32_t>(value[1]) << 16 |
                             static_cast<std::uint32_t>(value[2]) << 8 | value[3];
  if (baud > rfc2217::kMaxBaud) {
    problem("SET-BAUDRATE " + std::to_string(baud) + " refused (at most " +
            std::to_string(rfc2217::kMaxBaud) + "); the line keeps its rate" +
            (config_.line.baud != 0 ? " of " + std::to_string(config_.line.baud) + " baud" : ""));
  } else if (baud != 0 && baud != config_.line.baud) {
    // 0 asks for the rate in use.
    config_.line.baud = baud;
    event(Rfc2217Event::Kind::line_changed);
  }
  const std::uint32_t now = config_.line.baud;
  const Bytes answer_value = {static_cast<std::uint8_t>(now >> 24),
                              static_cast<std::uint8_t>(now >> 16),
                              static_cast<std::uint8_t>(now >> 8), static_cast<std::uint8_t>(now)};
  answer(rfc2217::kSetBaudRate, answer_value);
}

void Rfc2217Server::set_byte_setting(std::uint8_t command, ByteView value) {
  if (value.size() != 1) {
    problem(com_port_command_name(command) + " with " + std::to_string(value.size()) +
            " value byte(s), expected 1; ignored");
    return;
  }
  const std::uint8_t v = value[0];
  LineSettings& line = config_.line;
  const LineSettings before = line;
  // 0 asks for the setting in use.
  if (command == rfc2217::kSetDataSize) {
    if (v >= 5 && v <= 8) {
      line.data_bits = v;
    } else if (v != 0) {
      problem("SET-DATASIZE " + std::to_string(v) + " refused (5 to 8 bits)");
    }
    answer(command, line.data_bits);
  } else if (command == rfc2217::kSetParity) {
    if (v >= 1 && v <= 5) {
      line.parity = static_cast<Parity>(v);
    } else if (v != 0) {
      problem("SET-PARITY " + std::to_string(v) +
              " refused (1 none, 2 odd, 3 even, 4 mark, 5 space)");
    }
    answer(command, static_cast<std::uint8_t>(line.parity));
  } else {
    if (v >= 1 && v <= 3) {
      line.stop_bits = static_cast<StopBits>(v);
    } else if (v != 0) {
      problem("SET-STOPSIZE " + std::to_string(v) + " refused (1, 2, or 3 for 1.5 stop bits)");
    }
    answer(command, static_cast<std::uint8_t>(line.stop_bits));
  }
  if (line != before) event(Rfc2217Event::Kind::line_changed);
}

std::uint8_t Rfc2217Server::control_answer(std::uint8_t request) const {
  switch (request) {
    case 0:
      return outbound_flow_;
    case 4:
      return break_ ? 5 : 6;
    case 7:
      return dtr_ ? 8 : 9;
    case 10:
      return rts_ ? 11 : 12;
    default:  // 13
      return inbound_flow_;
  }
}

void Rfc2217Server::set_control(ByteView value) {
  if (value.size() != 1) {
    problem("SET-CONTROL with " + std::to_string(value.size()) +
            " value byte(s), expected 1; ignored");
    return;
  }
  const std::uint8_t v = value[0];
  using Kind = Rfc2217Event::Kind;
  switch (v) {
    case 0:
    case 4:
    case 7:
    case 10:
    case 13:
      answer(rfc2217::kSetControl, control_answer(v));
      return;
    case 1:
    case 2:
    case 3:
    case 17:
    case 19:
      outbound_flow_ = v;
      event(Kind::flow_control, v);
      break;
    case 14:
    case 15:
    case 16:
    case 18:
      inbound_flow_ = v;
      event(Kind::flow_control, v);
      break;
    case 5:
    case 6:
      break_ = v == 5;
      event(Kind::break_state, break_ ? 1 : 0);
      break;
    case 8:
    case 9:
      dtr_ = v == 8;
      event(Kind::dtr, dtr_ ? 1 : 0);
      break;
    case 11:
    case 12:
      rts_ = v == 11;
      event(Kind::rts, rts_ ? 1 : 0);
      break;
    default:
      problem("SET-CONTROL " + std::to_string(v) + " is not a known setting (0 to 19); ignored");
      return;
  }
  answer(rfc2217::kSetControl, v);
}

void Rfc2217Server::answer(std::uint8_t command, ByteView value) {
  Bytes payload;
  payload.reserve(value.size() + 1);
  payload.push_back(static_cast<std::uint8_t>(command + rfc2217::kServerOffset));
  payload.insert(payload.end(), value.begin(), value.end());
  telnet_subnegotiation(telnet_->state, rfc2217::kComPortOption,
                        reinterpret_cast<const char*>(payload.data()), payload.size());
}

void Rfc2217Server::answer(std::uint8_t command, std::uint8_t value) {
  const std::uint8_t one[1] = {value};
  answer(command, ByteView(one, 1));
}

void Rfc2217Server::event(Rfc2217Event::Kind kind, std::uint32_t value, std::string text) {
  events_.push_back(Rfc2217Event{kind, value, std::move(text)});
}

void Rfc2217Server::problem(std::string text) {
  event(Rfc2217Event::Kind::problem, 0, std::move(text));
}

}  // namespace hil::link
