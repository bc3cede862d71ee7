#include "conform/probe.hpp"

#include <stdexcept>

#include "protocol/common/car_profile.hpp"

namespace hil::conform {

Duration Probe::duration() const {
  Duration total{0};
  for (const auto& exchange : exchanges) {
    if (exchange.kind == ExchangeKind::connect) total += settle;
    for (const auto& write : exchange.writes)
      total += write.after;
    total += exchange.listen;
  }
  return total;
}

Probe make_probe(mocks::CarKind car, std::string_view profile) {
  const auto& found = protocol::find_car_profile(mocks::to_string(car), profile);
  Probe probe;
  switch (car) {
    case mocks::CarKind::logi:
      probe = make_logi_probe(found.name);
      break;
    case mocks::CarKind::wr8:
      probe = make_wr8_probe(found.name);
      break;
    case mocks::CarKind::arduino:
      probe = make_arduino_probe(found.name);
      break;
    case mocks::CarKind::leka:
      probe = make_leka_probe(found.name);
      break;
  }
  probe.car = car;
  probe.profile = std::string(found.name);
  if (probe.exchanges.empty() || probe.exchanges.front().kind != ExchangeKind::connect)
    throw std::logic_error("a probe starts with a connect exchange");
  return probe;
}

std::string probe_version(mocks::CarKind car) {
  return make_probe(car, {}).version;
}

}  // namespace hil::conform
