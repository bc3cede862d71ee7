#include "mocks/car.hpp"

#include "base/enum_names.hpp"
#include "protocol/common/car_profile.hpp"

#include <stdexcept>

#include "sim/presets.hpp"
#include "sim/random.hpp"

namespace hil::mocks {

constexpr base::EnumNames<CarKind, 4> kCarKindNames =
    base::enum_names<CarKind>({CarKind::logi, "logi"}, {CarKind::wr8, "wr8"},
                              {CarKind::arduino, "arduino"}, {CarKind::leka, "leka"});

std::string_view to_string(CarKind kind) {
  return kCarKindNames.name(kind);
}

std::optional<CarKind> parse_car_kind(std::string_view text) {
  return kCarKindNames.parse(text);
}

sim::VehicleDef vehicle_preset(CarKind kind) {
  switch (kind) {
    case CarKind::logi:
      return sim::logi_car();
    case CarKind::wr8:
      return sim::wr8_vehicle();
    case CarKind::arduino:
      return sim::arduino_robot();
    case CarKind::leka:
      return sim::leka_robot();
  }
  throw std::invalid_argument("unknown car kind");
}

namespace {
Duration latency_of(const protocol::CarProfile& profile) {
  return std::chrono::duration_cast<Duration>(profile.reply_latency);
}
}  // namespace

void apply_profile(FirmwareConfigs& configs, CarKind kind, std::string_view profile) {
  const protocol::CarProfile& p = protocol::find_car_profile(to_string(kind), profile);
  configs.reply_latency = latency_of(p);
  switch (kind) {
    case CarKind::arduino:
      configs.arduino.dialect = protocol::arduino::dialect_named(p.name);
      if (configs.avr) configs.avr->profile = std::string(p.name);
      break;
    case CarKind::leka:
      configs.leka.dialect = protocol::leka::dialect_named(p.name);
      break;
    case CarKind::logi:
      configs.logi.dialect = protocol::logi::dialect_named(p.name);
      break;
    case CarKind::wr8:
      configs.svgui.version = protocol::wr8::svgui::version_of_profile(p.name);
      break;
  }
}

namespace {

std::unique_ptr<Firmware> make_firmware_of_kind(CarKind kind, sim::World& world,
                                                sim::Vehicle& vehicle,
                                                const FirmwareConfigs& configs) {
  switch (kind) {
    case CarKind::logi:
      return std::make_unique<LogiFirmware>(world, vehicle, configs.logi);
    case CarKind::wr8:
      if (configs.svgui.version)
        return std::make_unique<SvguiFirmware>(world, vehicle, configs.svgui);
      return std::make_unique<Wr8Firmware>(world, vehicle, configs.wr8);
    case CarKind::arduino:
      if (configs.avr) return std::make_unique<AvrFirmware>(world, vehicle, *configs.avr);
      return std::make_unique<ArduinoFirmware>(world, vehicle, configs.arduino);
    case CarKind::leka:
      return std::make_unique<LekaFirmware>(world, vehicle, configs.leka);
  }
  throw std::invalid_argument("unknown car kind");
}

}  // namespace

std::unique_ptr<Firmware> make_firmware(CarKind kind, sim::World& world, sim::Vehicle& vehicle,
                                        const FirmwareConfigs& configs) {
  auto firmware = make_firmware_of_kind(kind, world, vehicle, configs);
  // A real firmware's answers take the emulated chip's own time.
  const bool emulated = kind == CarKind::arduino && configs.avr;
  firmware->set_reply_latency(emulated ? Duration{0}
                                       : configs.reply_latency.value_or(latency_of(
                                             protocol::default_car_profile(to_string(kind)))));
  return firmware;
}

MockCar::MockCar(CarOptions options) : kind_(options.kind), name_(options.name) {
  world_ = std::make_unique<sim::World>(sim::WorldDef{std::move(options.arena), options.seed});
  sim::VehicleDef def = vehicle_preset(kind_);
  def.name = name_;
  vehicle_ = &world_->add_vehicle(std::move(def));
  if (!options.replay) {
    firmware_ = make_firmware(kind_, *world_, *vehicle_, options.configs);
    return;
  }
  ReplaySpec& replay = *options.replay;
  if (!replay.capture)
    replay.capture = std::make_shared<const link::Capture>(link::read_capture(replay.path));
  if (replay.capture->header.car != to_string(kind_)) {
    throw std::invalid_argument((replay.path.empty() ? std::string("the capture") : replay.path) +
                                " is a capture of a " + replay.capture->header.car +
                                " car, not of a " + std::string(to_string(kind_)) + " car");
  }
  firmware_ =
      std::make_unique<ReplayFirmware>(*world_, *vehicle_, kind_, replay.capture, replay.unmatched,
                                       options.configs, std::move(replay.log));
}

MockCar::~MockCar() = default;

std::uint64_t car_seed(std::uint64_t run_seed, std::size_t index) {
  return index == 0 ? run_seed : sim::mix_seed(run_seed, index);
}

namespace {
unsigned profile_baud(CarKind kind) {
  return protocol::default_car_profile(to_string(kind)).baud;
}
}  // namespace

link::Endpoint default_endpoint(CarKind kind, std::size_t index, std::string_view profile) {
  const auto n = static_cast<std::uint16_t>(index);
  const protocol::CarProfile& p = protocol::find_car_profile(to_string(kind), profile);
  if (p.tcp_port != 0)
    return link::TcpEndpoint{"127.0.0.1", static_cast<std::uint16_t>(p.tcp_port + n)};
  switch (kind) {
    case CarKind::logi:
      return link::TcpEndpoint{"127.0.0.1", static_cast<std::uint16_t>(9000 + n)};
    case CarKind::wr8:
      return link::TcpEndpoint{"127.0.0.1", static_cast<std::uint16_t>(9100 + n)};
    case CarKind::arduino:
      return link::PtyEndpoint{"/tmp/hil-arduino" + std::to_string(index), profile_baud(kind), {}};
    case CarKind::leka:
      return link::PtyEndpoint{"/tmp/hil-leka" + std::to_string(index), profile_baud(kind), {}};
  }
  throw std::invalid_argument("unknown car kind");
}

}  // namespace hil::mocks
