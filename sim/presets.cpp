#include "sim/presets.hpp"

namespace hil::sim {

VehicleDef logi_car() {
  VehicleDef def;
  def.name = "logi";
  MecanumDef chassis;
  def.chassis = chassis;
  def.sonar.mount_m = {chassis.length_m / 2, 0};
  def.line_tracker.ahead_m = 0.12;
  def.rfid.mount_m = {0, 0};
  def.ir.left_mount_m = {chassis.length_m / 2, chassis.width_m / 4};
  def.ir.right_mount_m = {chassis.length_m / 2, -chassis.width_m / 4};
  return def;
}

VehicleDef wr8_vehicle() {
  VehicleDef def;
  def.name = "wr8";
  AckermannDef chassis;
  def.chassis = chassis;
  const double front_m = chassis.length_m - chassis.rear_overhang_m;
  def.sonar.mount_m = {front_m, 0};
  def.line_tracker.ahead_m = front_m - 0.04;
  def.rfid.mount_m = {chassis.wheelbase_m / 2, 0};
  def.ir.left_mount_m = {front_m, chassis.width_m / 4};
  def.ir.right_mount_m = {front_m, -chassis.width_m / 4};
  def.battery.capacity_mah = 5000;
  def.battery.full_load_current_a = 6.0;
  return def;
}

VehicleDef arduino_robot() {
  VehicleDef def;
  def.name = "arduino";
  DifferentialDef chassis;  // calibrated to the firmware's 18 ms/cm and 6 ms/degree at PWM 140
  def.chassis = chassis;
  def.sonar.mount_m = {chassis.length_m / 2, 0};
  def.line_tracker.ahead_m = chassis.length_m / 2 - 0.02;
  def.ir.left_mount_m = {chassis.length_m / 2 - 0.01, chassis.width_m / 2 - 0.02};
  def.ir.right_mount_m = {chassis.length_m / 2 - 0.01, -(chassis.width_m / 2 - 0.02)};
  def.battery.capacity_mah = 2000;
  def.battery.full_v = 9.0;  // a 6 x AA holder
  def.battery.empty_v = 6.0;
  def.battery.full_load_current_a = 1.5;
  return def;
}

VehicleDef leka_robot() {
  VehicleDef def;
  def.name = "leka";
  DifferentialDef chassis;
  chassis.speed_per_pwm_mps = 0.4 / 255;  // 0.4 m/s at full speed byte
  chassis.effective_track_m = 0.17;       // two wheels, little scrub
  chassis.max_accel_mps2 = 1.0;
  chassis.length_m = 0.22;
  chassis.width_m = 0.22;
  chassis.mass_kg = 1.5;
  def.chassis = chassis;
  def.sonar.mount_m = {0.11, 0};
  def.line_tracker.ahead_m = 0.08;
  def.ir.left_mount_m = {0.10, 0.05};
  def.ir.right_mount_m = {0.10, -0.05};
  def.battery.capacity_mah = 3000;
  def.battery.full_v = 4.2;  // one lithium cell
  def.battery.empty_v = 3.3;
  def.battery.full_load_current_a = 1.2;
  def.battery.internal_resistance_ohm = 0.08;
  return def;
}

}  // namespace hil::sim
