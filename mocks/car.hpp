#pragma once
// A standalone mock car: its own world, the car's preset vehicle and its
// firmware, built from one options struct (what `hil mock` runs, once per
// --count).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "base/enum_names.hpp"
#include "link/endpoint.hpp"
#include "mocks/arduino.hpp"
#include "mocks/avr/avr_firmware.hpp"
#include "mocks/firmware.hpp"
#include "mocks/leka.hpp"
#include "mocks/logi.hpp"
#include "mocks/replay.hpp"
#include "mocks/wr8.hpp"
#include "mocks/wr8_svgui.hpp"
#include "sim/arena.hpp"
#include "sim/world.hpp"

namespace hil::mocks {

enum class CarKind : std::uint8_t { logi, wr8, arduino, leka };

/// "logi", "wr8", "arduino", "leka".
std::string_view to_string(CarKind kind);
std::optional<CarKind> parse_car_kind(std::string_view text);
/// The same words, for listing the cars.
extern const base::EnumNames<CarKind, 4> kCarKindNames;

/// The car's vehicle preset (sim/presets.hpp).
sim::VehicleDef vehicle_preset(CarKind kind);

/// Firmware settings for every kind; only the car's own is used.
struct FirmwareConfigs {
  LogiConfig logi;
  Wr8Config wr8;
  /// The WR8 car as a real smart_vehicle_gui vehicle program; used instead
  /// of `wr8` when its version is set (profiles svgui-2019, svgui-head).
  SvguiConfig svgui;
  ArduinoConfig arduino;
  /// The Arduino car as a real firmware image on the emulated ATmega328P
  /// (mocks/avr/avr_firmware.hpp); used instead of `arduino` when set. Its
  /// answers take the chip's own time: `reply_latency` is not added.
  std::optional<AvrConfig> avr;
  LekaConfig leka;
  /// The firmware's processing time before each answer (Firmware::
  /// set_reply_latency); nullopt: the default profile's. Zero: in the same
  /// instant, only when asked for.
  std::optional<Duration> reply_latency;
};

/// Sets the car's firmware config to play profile `profile` of `kind`
/// (protocol/common/car_profile.hpp; empty: the default), its reply latency
/// included. Throws protocol::ProfileError, with the valid names, for
/// another name.
void apply_profile(FirmwareConfigs& configs, CarKind kind, std::string_view profile);

/// The firmware of `kind` for a vehicle already in `world` (a scenario's
/// shared world, or a MockCar's own).
std::unique_ptr<Firmware> make_firmware(CarKind kind, sim::World& world, sim::Vehicle& vehicle,
                                        const FirmwareConfigs& configs = {});

struct CarOptions {
  CarKind kind = CarKind::logi;
  sim::Arena arena = sim::default_warehouse_arena();
  std::uint64_t seed = 1;  ///< sensor noise and sensor faults
  std::string name = "car0";
  FirmwareConfigs configs;
  /// Play a recorded car (mocks/replay.hpp) instead of the mock firmware;
  /// the capture must be of `kind` (std::invalid_argument otherwise), and
  /// is read from its path when not given (link::CaptureError when it
  /// cannot be). `configs` then set the mock that answers what the capture
  /// has no recording for, in the capture's profile.
  std::optional<ReplaySpec> replay;
};

class MockCar {
 public:
  explicit MockCar(CarOptions options);
  ~MockCar();
  MockCar(const MockCar&) = delete;
  MockCar& operator=(const MockCar&) = delete;

  CarKind kind() const { return kind_; }
  const std::string& name() const { return name_; }
  sim::World& world() { return *world_; }
  sim::Vehicle& vehicle() { return *vehicle_; }
  Firmware& firmware() { return *firmware_; }

 private:
  CarKind kind_;
  std::string name_;
  std::unique_ptr<sim::World> world_;
  sim::Vehicle* vehicle_ = nullptr;
  std::unique_ptr<Firmware> firmware_;
};

/// The seed of car number `index` in a run seeded `run_seed`: car 0 uses the
/// run seed itself (so one car replays with the seed printed), the others
/// independent streams mixed from it.
std::uint64_t car_seed(std::uint64_t run_seed, std::size_t index);

/// Where car number `index` (0-based) of a kind listens by default:
/// tcp://127.0.0.1:9000+index (LOGI), tcp://127.0.0.1:9100+index (WR8),
/// pty:///tmp/hil-arduino<index>?baud=9600, pty:///tmp/hil-leka<index>?baud=115200
/// (the baud of the car's profiles). A profile with the real car's own TCP
/// port (WR8 svgui-2019 and svgui-head: 5556) listens there plus `index`.
/// Throws protocol::ProfileError for a profile the car does not have.
link::Endpoint default_endpoint(CarKind kind, std::size_t index, std::string_view profile = {});

}  // namespace hil::mocks
