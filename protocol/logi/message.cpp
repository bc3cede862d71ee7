#include "protocol/logi/message.hpp"

#include <sstream>

#include "protocol/common/overloaded.hpp"

namespace hil::protocol::logi {
namespace {

constexpr std::array<std::string_view, 11> kDirectionNames = {
    "STOP", "FWD", "BWD", "LEFT", "RIGHT", "LF", "RF", "LB", "RB", "CW", "CCW"};
constexpr std::array<std::string_view, 5> kCommandNames = {"SP", "ST", "GS", "MD", "MV"};

}  // namespace

std::string_view to_string(Direction d) {
  return kDirectionNames.at(static_cast<std::size_t>(d));
}

std::string_view to_string(Mode m) {
  return m == Mode::manual ? "MAN" : "AUTO";
}

std::string_view to_string(Command c) {
  return kCommandNames.at(static_cast<std::size_t>(c));
}

std::optional<Direction> parse_direction(std::string_view text) {
  for (std::size_t i = 0; i < kDirectionNames.size(); ++i) {
    if (kDirectionNames[i] == text) return static_cast<Direction>(i);
  }
  return std::nullopt;
}

std::optional<Mode> parse_mode(std::string_view text) {
  if (text == "MAN") return Mode::manual;
  if (text == "AUTO") return Mode::automatic;
  return std::nullopt;
}

std::optional<Command> parse_command(std::string_view text) {
  for (std::size_t i = 0; i < kCommandNames.size(); ++i) {
    if (kCommandNames[i] == text) return static_cast<Command>(i);
  }
  return std::nullopt;
}

std::optional<Command> command_of(const Message& m) {
  return std::visit(
      Overloaded{[](const SetSpeed&) -> std::optional<Command> { return Command::sp; },
                 [](const SetRun&) -> std::optional<Command> { return Command::st; },
                 [](const SetStation&) -> std::optional<Command> { return Command::gs; },
                 [](const SetMode&) -> std::optional<Command> { return Command::md; },
                 [](const Move&) -> std::optional<Command> { return Command::mv; },
                 [](const Status&) -> std::optional<Command> { return std::nullopt; },
                 [](const Feedback&) -> std::optional<Command> { return std::nullopt; }},
      m);
}

std::string kind_of(const Message& m) {
  return std::visit(Overloaded{
                        [](const SetSpeed&) -> std::string { return "SP"; },
                        [](const SetRun& v) -> std::string { return v.run ? "ST:RUN" : "ST:STOP"; },
                        [](const SetStation&) -> std::string { return "GS"; },
                        [](const SetMode& v) { return "MD:" + std::string(to_string(v.mode)); },
                        [](const Move& v) { return "MV:" + std::string(to_string(v.direction)); },
                        [](const Status&) -> std::string { return "STAT"; },
                        [](const Feedback& v) { return "FB:" + std::string(to_string(v.command)); },
                    },
                    m);
}

std::string describe(const Message& m) {
  std::ostringstream os;
  std::visit(Overloaded{[&](const SetSpeed& v) { os << "SetSpeed percent=" << v.percent; },
                        [&](const SetRun& v) { os << "SetRun " << (v.run ? "RUN" : "STOP"); },
                        [&](const SetStation& v) { os << "SetStation station=" << v.station; },
                        [&](const SetMode& v) { os << "SetMode " << to_string(v.mode); },
                        [&](const Move& v) { os << "Move " << to_string(v.direction); },
                        [&](const Status& v) {
                          os << "Status speed_percent=" << v.speed_percent
                             << " station=" << v.station << " running=" << v.running
                             << " mode=" << to_string(v.mode) << " manual=" << to_string(v.manual)
                             << " distance_cm=" << v.distance_cm << " track=";
                          for (int bit = 3; bit >= 0; --bit)
                            os << ((v.track_mask >> bit) & 1);
                          os << " deviation=" << v.deviation << " obstacle=" << v.obstacle
                             << " rpm=" << v.rpm[0] << ':' << v.rpm[1] << ':' << v.rpm[2] << ':'
                             << v.rpm[3];
                          for (const auto& [key, value] : v.extra)
                            os << " +" << key << '=' << value;
                        },
                        [&](const Feedback& v) {
                          os << "Feedback " << to_string(v.command) << ' '
                             << (v.accepted ? "accepted" : "rejected");
                        }},
             m);
  return os.str();
}

}  // namespace hil::protocol::logi
