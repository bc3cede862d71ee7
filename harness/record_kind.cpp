#include "harness/record_kind.hpp"

#include <ostream>

#include "base/enum_names.hpp"

namespace hil::harness {
namespace {

constexpr auto kSourceNames = base::enum_names<Source>(
    {Source::wire, "wire"}, {Source::fault, "fault"}, {Source::client, "client"},
    {Source::sim, "sim"}, {Source::step, "step"}, {Source::car, "car"});
constexpr auto kWireKindNames = base::enum_names<WireKind>(
    {WireKind::frame, "frame"}, {WireKind::open, "open"}, {WireKind::close, "close"});
constexpr auto kClientKindNames = base::enum_names<ClientKind>(
    {ClientKind::connection, "connection"}, {ClientKind::command, "command"},
    {ClientKind::stale, "stale"}, {ClientKind::fresh, "fresh"}, {ClientKind::notice, "notice"},
    {ClientKind::action, "action"}, {ClientKind::login, "login"},
    {ClientKind::parse_error, "parse_error"}, {ClientKind::movement, "movement"},
    {ClientKind::output, "output"}, {ClientKind::exit, "exit"}, {ClientKind::start, "start"},
    {ClientKind::origin, "origin"});
constexpr auto kSimKindNames = base::enum_names<SimKind>(
    {SimKind::sample, "sample"}, {SimKind::station, "station"}, {SimKind::collision, "collision"},
    {SimKind::at_rest, "at_rest"}, {SimKind::moving, "moving"});
constexpr auto kStepKindNames =
    base::enum_names<StepKind>({StepKind::start, "start"}, {StepKind::end, "end"});
constexpr auto kCarEventKindNames = base::enum_names<CarEventKind>(
    {CarEventKind::behaviour, "behaviour"}, {CarEventKind::fault_state, "fault_state"});

}  // namespace

std::string_view to_string(Source source) {
  return kSourceNames.name(source);
}
std::optional<Source> parse_source(std::string_view text) {
  return kSourceNames.parse(text);
}
std::string_view to_string(WireKind kind) {
  return kWireKindNames.name(kind);
}
std::string_view to_string(ClientKind kind) {
  return kClientKindNames.name(kind);
}
std::string_view to_string(SimKind kind) {
  return kSimKindNames.name(kind);
}
std::string_view to_string(StepKind kind) {
  return kStepKindNames.name(kind);
}
std::string_view to_string(CarEventKind kind) {
  return kCarEventKindNames.name(kind);
}

std::string_view RecordKind::name() const {
  switch (source_) {
    case Source::wire:
      return to_string(static_cast<WireKind>(value_));
    case Source::fault:
      return link::to_string(static_cast<link::FaultKind>(value_));
    case Source::client:
      return to_string(static_cast<ClientKind>(value_));
    case Source::sim:
      return to_string(static_cast<SimKind>(value_));
    case Source::step:
      return to_string(static_cast<StepKind>(value_));
    case Source::car:
      return to_string(static_cast<CarEventKind>(value_));
  }
  return "?";
}

std::ostream& operator<<(std::ostream& out, RecordKind kind) {
  return out << to_string(kind.source()) << '/' << kind.name();
}

std::optional<RecordKind> parse_record_kind(Source source, std::string_view name) {
  const auto of = [](auto kind) -> std::optional<RecordKind> {
    if (!kind) return std::nullopt;
    return RecordKind(*kind);
  };
  switch (source) {
    case Source::wire:
      return of(kWireKindNames.parse(name));
    case Source::fault:
      return of(link::parse_fault_kind(name));
    case Source::client:
      return of(kClientKindNames.parse(name));
    case Source::sim:
      return of(kSimKindNames.parse(name));
    case Source::step:
      return of(kStepKindNames.parse(name));
    case Source::car:
      return of(kCarEventKindNames.parse(name));
  }
  return std::nullopt;
}

}  // namespace hil::harness
