#include "harness/record_kind.hpp"

#include <array>
#include <ostream>

namespace hil::harness {
namespace {

constexpr std::array kSources = {"wire", "fault", "client", "sim", "step", "car"};
constexpr std::array kWire = {"frame", "open", "close"};
constexpr std::array kClient = {"connection", "command", "stale", "fresh",
                                "notice",     "action",  "login", "parse_error",
                                "movement",   "output",  "exit",  "start"};
constexpr std::array kSim = {"sample", "station", "collision", "at_rest", "moving"};
constexpr std::array kStep = {"start", "end"};
constexpr std::array kCar = {"behaviour", "fault_state"};

template <typename Names, typename E>
std::string_view name_of(const Names& names, E e) {
  const auto i = static_cast<std::size_t>(e);
  return i < names.size() ? names[i] : "?";
}

template <typename E, typename Names>
std::optional<E> find(const Names& names, std::string_view word) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == word) return static_cast<E>(i);
  }
  return std::nullopt;
}

}  // namespace

std::string_view to_string(Source source) {
  return name_of(kSources, source);
}
std::optional<Source> parse_source(std::string_view text) {
  return find<Source>(kSources, text);
}
std::string_view to_string(WireKind kind) {
  return name_of(kWire, kind);
}
std::string_view to_string(ClientKind kind) {
  return name_of(kClient, kind);
}
std::string_view to_string(SimKind kind) {
  return name_of(kSim, kind);
}
std::string_view to_string(StepKind kind) {
  return name_of(kStep, kind);
}
std::string_view to_string(CarEventKind kind) {
  return name_of(kCar, kind);
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
      return of(find<WireKind>(kWire, name));
    case Source::fault:
      return of(link::parse_fault_kind(name));
    case Source::client:
      return of(find<ClientKind>(kClient, name));
    case Source::sim:
      return of(find<SimKind>(kSim, name));
    case Source::step:
      return of(find<StepKind>(kStep, name));
    case Source::car:
      return of(find<CarEventKind>(kCar, name));
  }
  return std::nullopt;
}

}  // namespace hil::harness
