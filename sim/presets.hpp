#pragma once
// The four cars hil emulates, as vehicle definitions with their sensors
// mounted where the real cars carry them. Figures in docs/simulation.md.

#include "sim/vehicle.hpp"

namespace hil::sim {

/// LOGI logistics car: mecanum wheels, sonar, 4-channel line tracker, RFID
/// reader under the centre.
VehicleDef logi_car();
/// WR8 vehicle: Ackermann steering, reference point on the rear axle.
VehicleDef wr8_vehicle();
/// Arduino robot: skid-steer, PWM per side, sonar and two IR sensors.
VehicleDef arduino_robot();
/// Leka robot: two-wheel differential drive, speed byte per motor.
VehicleDef leka_robot();

}  // namespace hil::sim
