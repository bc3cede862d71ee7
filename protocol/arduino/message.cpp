#include "protocol/arduino/message.hpp"

#include <cstdio>
#include <sstream>

#include "protocol/common/overloaded.hpp"

namespace hil::protocol::arduino {
namespace {

constexpr std::array<std::string_view, 5> kNackCodeNames = {"BAD_CS", "BAD_FMT", "BAD_SEQ",
                                                            "BAD_CMD", "BAD_V"};

std::string seq_text(std::uint8_t seq) {
  char buf[4];
  std::snprintf(buf, sizeof buf, "%02X", static_cast<unsigned>(seq));
  return buf;
}

}  // namespace

std::string_view to_string(NackCode code) {
  return kNackCodeNames.at(static_cast<std::size_t>(code));
}

std::optional<NackCode> parse_nack_code(std::string_view text) {
  for (std::size_t i = 0; i < kNackCodeNames.size(); ++i) {
    if (kNackCodeNames[i] == text) return static_cast<NackCode>(i);
  }
  return std::nullopt;
}

Nack nack_from_text(std::string_view text) {
  if (const auto code = parse_nack_code(text)) return Nack{*code};
  return Nack{std::string(text)};
}

std::string_view command_of(const Body& body) {
  return std::visit(Overloaded{[](const Ping&) { return std::string_view("PING"); },
                               [](const StatusRequest&) { return std::string_view("STATUS"); },
                               [](const SetSpeed&) { return std::string_view("V"); },
                               [](const Move&) { return std::string_view("M"); },
                               [](const Rotate&) { return std::string_view("R"); },
                               [](const Stop&) { return std::string_view("S"); },
                               [](const SonarRead&) { return std::string_view("B"); },
                               [](const IrRead&) { return std::string_view("I"); },
                               [](const Help&) { return std::string_view("HELP"); },
                               [](const Ack&) { return std::string_view("ACK"); },
                               [](const Nack&) { return std::string_view("NACK"); }},
                    body);
}

bool is_request(const Body& body) {
  return !std::holds_alternative<Ack>(body) && !std::holds_alternative<Nack>(body);
}

std::string describe(const Message& m) {
  std::ostringstream os;
  const std::string seq = " seq=" + seq_text(m.seq);
  std::visit(
      Overloaded{[&](const Ping&) { os << "Ping" << seq; },
                 [&](const StatusRequest&) { os << "StatusRequest" << seq; },
                 [&](const SetSpeed& v) { os << "SetSpeed" << seq << " pwm=" << v.pwm; },
                 [&](const Move& v) { os << "Move" << seq << " distance_cm=" << v.distance_cm; },
                 [&](const Rotate& v) { os << "Rotate" << seq << " angle_deg=" << v.angle_deg; },
                 [&](const Stop&) { os << "Stop" << seq; },
                 [&](const SonarRead&) { os << "SonarRead" << seq; },
                 [&](const IrRead&) { os << "IrRead" << seq; },
                 [&](const Help&) { os << "Help" << seq; },
                 [&](const Ack& v) { os << "Ack" << seq << " info=\"" << v.info << '"'; },
                 [&](const Nack& v) {
                   os << "Nack" << seq;
                   if (const auto* code = std::get_if<NackCode>(&v.error)) {
                     os << " code=" << to_string(*code);
                   } else {
                     os << " text=\"" << std::get<std::string>(v.error) << '"';
                   }
                 }},
      m.body);
  return os.str();
}

}  // namespace hil::protocol::arduino
