#pragma once
// A battery that drains with motor load and sags under current: a linear
// open-circuit voltage over the charge, minus the internal resistance drop.

#include "sim/random.hpp"

namespace hil::sim {

struct BatteryDef {
  double capacity_mah = 2200;
  double full_v = 8.4;               ///< open-circuit voltage at 100 % (a 2S lithium pack)
  double empty_v = 6.6;              ///< open-circuit voltage at 0 %
  double idle_current_a = 0.15;      ///< electronics alone
  double full_load_current_a = 3.0;  ///< added with every motor at full speed
  double internal_resistance_ohm = 0.15;
  double initial_charge = 1.0;  ///< 0..1
};

struct BatteryReading {
  double charge = 1.0;  ///< 0..1
  double voltage_v = 0;
  double current_a = 0;
  /// Whole percent 0..100, as telemetry reports it.
  int percent() const { return static_cast<int>(charge * 100 + 0.5); }
};

class Battery {
 public:
  explicit Battery(const BatteryDef& def);
  /// Draws current for `dt_s` at motor `load` (0..1); `sag_v` is an extra
  /// drop from a battery-sag fault.
  void update(double load, double dt_s, double sag_v);
  BatteryReading reading() const { return reading_; }
  void hash_state(StateHasher& hasher) const { hasher.add(reading_); }

 private:
  BatteryDef def_;
  BatteryReading reading_;
};

}  // namespace hil::sim
