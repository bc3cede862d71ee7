#include "protocol/common/car_profile.hpp"

#include <algorithm>
#include <array>

namespace hil::protocol {
namespace {

// Sources are named by repository and commit; the facts are described in
// docs/protocols/<car>.md.
using std::chrono::microseconds;

constexpr std::string_view kLogiLatency =
    "accepted commands wait in a FreeRTOS queue for the task that serves it, and every byte "
    "crosses the ESP-12F's UART both ways; the excerpts of the firmware give no task period, "
    "so 5 ms is an estimate";
constexpr std::string_view kWr8Latency =
    "the vehicle program answers from its Qt event loop on a Linux computer; an estimate";
constexpr std::string_view kSvguiLatency =
    "the vehicle program answers from its Qt event loop on a Linux computer; an estimate (the "
    "real programs run on one machine, over loopback)";
constexpr std::string_view kArduinoLatency =
    "the sketch answers in the loop pass that reads the closing '$' (microseconds at 16 MHz); "
    "the time is the line's, 1.04 ms a byte at 9600 baud";
constexpr std::string_view kLekaLatency =
    "no processing time is documented; the time is the line's, 87 us a byte at 115200 baud";

constexpr std::array kProfiles{
    CarProfile{"logi", "firmware",
               "car_stm32f103vet6 firmware: docs/upper_computer_ai_guide.md and the frame parser "
               "of Core/Bsp/protocol.c",
               "the STM32 parser: each hand-over from the Wi-Fi module is one message of 10 bytes "
               "or more ending in '#', its checksum field after the last ':'",
               false, 0, microseconds(5000), kLogiLatency},
    CarProfile{"logi", "guide",
               "car_stm32f103vet6 docs/upper_computer_ai_guide.md, section 8 (the stream rule)",
               "the guide's stream rule on the car's input: a frame from the first LOGI: to the "
               "first '#', wherever the writes and reads cut the stream",
               true, 0, microseconds(5000), kLogiLatency},
    CarProfile{"wr8", "document", "the WR8 protocol document of 2019-01-06 (smart_vehicle_gui)",
               "packets exactly as the document gives them: no length byte before a packet", true,
               0, microseconds(1000), kWr8Latency},
    CarProfile{"wr8", "svgui-2019",
               "lsd-maddrive/smart_vehicle_gui at 8d80e92 (2019-02-18): common/svserver.cpp, "
               "common/datapackage.cpp and the SVGUI_qml client",
               "the real programs of the document's time: a length byte before every packet, "
               "TASK and SETTINGS little-endian, big-endian DATA of 42 bytes, the fixed "
               "AUTH-REPLY 1 2 WAIT, tasks and settings dropped while a task runs",
               false, 0, microseconds(1000), kSvguiLatency, 5556},
    CarProfile{"wr8", "svgui-head",
               "lsd-maddrive/smart_vehicle_gui at 431e8d4 (protocol of 2019-05-18): "
               "common/svserver.cpp, common/datapackage.cpp, SVServer_console_test and SVGUI_qml",
               "the maintained real programs: a length byte before every packet, one packet read "
               "per arrival, SET of 12 doubles, SET-REQUEST, MAP, HIGH-FREQ DATA every 50 ms and "
               "LOW-FREQ every 1000 ms to every connection, CONTROL axes; no TASK",
               false, 0, microseconds(1000), kSvguiLatency, 5556},
    CarProfile{
        "arduino", "firmware",
        "andrii-mazurchuk/arduino_robot_steering- at 8dcfab0: arduino.ino and robot_client.py",
        "the real sketch: the payload field may not be empty (the real client sends one "
        "space), replies PONG, STATUS:V=..,DIR=..,MOT:.., ACCEPTED, STOPPED, B:<cm>, "
        "I:AL=..; malformed frames dropped without an answer",
        true, 9600, microseconds(0), kArduinoLatency},
    CarProfile{"arduino", "readme",
               "the README of andrii-mazurchuk/arduino_robot_steering- (hil's protocol document)",
               "the README's examples: argument-less commands with an empty payload, replies OK, "
               "IDLE PWM=.., the bare sonar distance",
               false, 9600, microseconds(0), kArduinoLatency},
    CarProfile{"leka", "readme", "the README of leka/LKAlphaComSpecs v3.0.0 (381046f)",
               "the README's command ids (belt single 0x15) and its worked examples' checksum: "
               "the low byte of a 16-bit BSD sum over the command group",
               true, 115200, microseconds(0), kLekaLatency},
    CarProfile{"leka", "comspecs-v3",
               "leka/LKAlphaComSpecs v3.0.0 (381046f): Specs/LKAlphaComSpecs.yml and its Swift "
               "and C++ tables; MMyster/Leka-Command-Generator's checksum",
               "the YAML's command ids (led.ear.range 0x12, then ear single 0x13 .. belt single "
               "0x16) and an 8-bit BSD checksum over the length byte and the group",
               false, 115200, microseconds(0), kLekaLatency},
};

std::string spoken_list(const std::vector<std::string_view>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? " and " : ", ";
    text += names[i];
  }
  return text;
}

void require_car(std::string_view car) {
  const auto cars = car_profile_cars();
  if (std::find(cars.begin(), cars.end(), car) == cars.end()) {
    throw ProfileError("unknown car '" + std::string(car) + "'; the cars are " + spoken_list(cars));
  }
}

}  // namespace

std::span<const CarProfile> car_profiles() {
  return kProfiles;
}

std::vector<std::string_view> car_profile_cars() {
  std::vector<std::string_view> cars;
  for (const CarProfile& p : kProfiles) {
    if (std::find(cars.begin(), cars.end(), p.car) == cars.end()) cars.push_back(p.car);
  }
  return cars;
}

std::vector<CarProfile> car_profiles_of(std::string_view car) {
  require_car(car);
  std::vector<CarProfile> out;
  for (const CarProfile& p : kProfiles) {
    if (p.car == car) out.push_back(p);
  }
  std::stable_partition(out.begin(), out.end(), [](const CarProfile& p) { return p.is_default; });
  return out;
}

const CarProfile& default_car_profile(std::string_view car) {
  require_car(car);
  for (const CarProfile& p : kProfiles) {
    if (p.car == car && p.is_default) return p;
  }
  throw ProfileError("car '" + std::string(car) + "' has no default profile");
}

const CarProfile& find_car_profile(std::string_view car, std::string_view name) {
  if (name.empty()) return default_car_profile(car);
  require_car(car);
  for (const CarProfile& p : kProfiles) {
    if (p.car == car && p.name == name) return p;
  }
  throw ProfileError(std::string(car) + " has no profile '" + std::string(name) +
                     "'; its profiles are " + car_profile_names(car));
}

std::string car_profile_problem(std::string_view car, std::string_view name) {
  try {
    (void)find_car_profile(car, name);
    return {};
  } catch (const ProfileError& e) {
    return e.what();
  }
}

std::string car_profile_names(std::string_view car) {
  std::vector<std::string> names;
  for (const CarProfile& p : car_profiles_of(car)) {
    names.push_back(std::string(p.name) + (p.is_default ? " (the default)" : ""));
  }
  std::vector<std::string_view> views(names.begin(), names.end());
  return spoken_list(views);
}

}  // namespace hil::protocol
