#include "sim/battery.hpp"

#include <algorithm>
#include <cassert>

namespace hil::sim {

Battery::Battery(const BatteryDef& def) : def_(def) {
  assert(def.capacity_mah > 0 && def.full_v > def.empty_v);
  reading_.charge = std::clamp(def.initial_charge, 0.0, 1.0);
  update(0, 0, 0);
}

void Battery::update(double load, double dt_s, double sag_v) {
  const double current_a =
      def_.idle_current_a + std::clamp(load, 0.0, 1.0) * def_.full_load_current_a;
  const double used = current_a * dt_s / 3600.0 / (def_.capacity_mah / 1000.0);
  reading_.charge = std::max(0.0, reading_.charge - used);
  reading_.current_a = current_a;
  const double open_circuit = def_.empty_v + (def_.full_v - def_.empty_v) * reading_.charge;
  reading_.voltage_v =
      std::max(0.0, open_circuit - current_a * def_.internal_resistance_ohm - std::max(0.0, sag_v));
}

}  // namespace hil::sim
