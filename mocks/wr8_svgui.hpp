#pragma once
// The WR8 vehicle as the real smart_vehicle_gui vehicle program plays it
// (profiles svgui-2019 and svgui-head; docs/mocks/wr8.md, "The real
// vehicle programs"): a length byte before every packet, the program's own
// way of reading its socket, the fixed AUTH-REPLY, no login state, and the
// version's packets, driving a simulated Ackermann chassis.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mocks/firmware.hpp"
#include "protocol/wr8/svgui.hpp"
#include "protocol/wr8/svgui_receiver.hpp"

namespace hil::mocks {

namespace svgui = protocol::wr8::svgui;

/// What the real vehicle program does that a mock has to choose, and the
/// figures of the simulated car behind it; defaults in docs/mocks/wr8.md.
struct SvguiConfig {
  /// The program version played; nullopt: the WR8 car plays the document
  /// (Wr8Firmware and its Wr8Config), not a real program.
  std::optional<svgui::Version> version;

  /// The text an AUTH packet must end with (both versions compare the text
  /// up to its first NUL, a trailing CR LF cut off).
  std::string auth_suffix = "konnichiwa";

  /// v2019: the vehicle's DATA period, on a grid since the program started,
  /// to whoever is connected. The program sends DATA when the car's code
  /// hands it some; the console test car of the repository never does.
  /// Zero: no DATA, as that test car.
  Duration v2019_data_period{link::milliseconds(100)};
  /// head: the console test car's two timers, running from program start
  /// and sending to every connection, logged in or not.
  Duration high_freq_period{link::milliseconds(50)};
  Duration low_freq_period{link::milliseconds(1000)};

  /// The local time of day when the run started: DATA timestamps are
  /// milliseconds since local midnight. Zero in virtual time (a run starts
  /// at midnight, so timestamps are the run's milliseconds); `hil mock`
  /// sets the wall clock's.
  Duration time_of_day_at_start{0};

  /// head CONTROL: a y axis of 1 drives at this speed (-1 backwards), an x
  /// axis of 1 steers fully right (-1 fully left) at the chassis' limit.
  double control_max_speed_mps = 0.5;
  /// head CONTROL: without a CONTROL this long the car stops (the GUI sends
  /// one every 100 ms while its control switch is on). Zero: the last
  /// CONTROL holds until the next one.
  Duration control_timeout{link::milliseconds(500)};

  /// v2019 forward task: its top speed.
  double forward_speed_mps = 0.5;
  /// v2019 forward task: a drive whose wheels cover less than 1 mm in this
  /// long is over, answered with code 0 (error).
  Duration stall_timeout{link::seconds(2)};
  /// v2019 turn-signal task: how long the signals flash before it is done.
  Duration signals_duration{link::seconds(2)};

  /// Servo position the wheels are straight at; a servo zero elsewhere
  /// turns every wheel angle by the difference (both versions set it).
  double servo_center_deg = 90;
  /// head: the twelve settings at power-on, in the order of svgui::kSetNames.
  std::array<double, 12> head_settings = {1.0, 0.0, 0.0, 90, 1.0, 0.1, 0.0, 10, 1.0, 0.1, 0.0, 10};
  /// v2019: p, i, d and servo zero at power-on.
  std::array<std::int32_t, 4> v2019_settings = {1, 0, 0, 90};

  /// head LOW-FREQ DATA: the computer's battery in percent and the
  /// temperature in degrees Celsius (the simulated car has neither).
  std::uint32_t computer_battery_percent = 100;
  double temperature_c = 35;

  /// One line per event a person may want to see (a login, a packet the
  /// program drops, a read the real program would get wrong). May be empty.
  std::function<void(const std::string&)> log;

  /// Returns a copy, or throws std::invalid_argument("SvguiConfig: ...")
  /// naming the field that cannot work.
  SvguiConfig checked() const;
};

/// The firmware's state, read-only for tests and the harness.
struct SvguiState {
  /// Logins the program answered (it keeps no login state: every packet is
  /// served from any connection).
  std::uint64_t logins = 0;
  /// AUTH packets it did not answer (a wrong text; v2019: a length byte
  /// other than 11).
  std::uint64_t refused_logins = 0;
  /// Read events whose bytes the program cannot use (a length byte of 0 or
  /// of 0x80 and above in head, an empty or unknown packet, a TASK shorter
  /// than its parameters); nothing is answered.
  std::uint64_t unusable_reads = 0;
  /// Read events whose length byte did not match the bytes read.
  std::uint64_t length_mismatches = 0;

  /// v2019: the COI of the task in progress, as the program keeps it; not 0
  /// means busy (every TASK and SETTINGS is dropped), 0 idle, so a task
  /// sent with COI 0 never makes the car busy.
  std::uint8_t current_coi = 0;
  /// v2019: TASK and SETTINGS packets dropped because the car was busy.
  std::uint64_t dropped_busy = 0;
  /// v2019: p, i, d and servo zero as the program read them (the GUI's
  /// SETTINGS are read at other offsets than it writes them).
  std::array<std::int32_t, 4> v2019_settings{};
  /// head: the twelve settings in force (svgui::kSetNames order).
  std::array<double, 12> head_settings{};

  enum class Task : std::uint8_t { none, forward, wheels, signals };
  Task task = Task::none;  ///< v2019: what the car is doing
  Time task_until{};       ///< signals: when they stop flashing
  Time last_progress{};    ///< forward: when the wheels last gained 1 mm
  double progress_mark_m = 0;

  /// head: the last CONTROL and when it came.
  std::optional<svgui::Control> control;
  Time control_at{};

  std::optional<Time> next_loop;       ///< tasks and the CONTROL watchdog
  std::optional<Time> next_data;       ///< v2019 DATA
  std::optional<Time> next_high_freq;  ///< head
  std::optional<Time> next_low_freq;   ///< head
  std::uint64_t data_sent = 0;         ///< DATA packets of any rate
  std::uint64_t maps_sent = 0;
};

std::string_view to_string(SvguiState::Task task);

/// The real vehicle program of one smart_vehicle_gui version.
class SvguiFirmware final : public FirmwareWith<SvguiConfig, SvguiState> {
 public:
  /// Throws std::invalid_argument when the vehicle has no Ackermann chassis
  /// or the config cannot work (SvguiConfig::checked()).
  SvguiFirmware(sim::World& world, sim::Vehicle& vehicle, SvguiConfig config);

  std::string summary() const override;

  svgui::Version version() const { return version_; }

  /// What the DATA packets would carry at `now`.
  svgui::Data data_at(Time now) const;
  svgui::HighFreqData high_freq_at(Time now) const;
  svgui::LowFreqData low_freq_at(Time now) const;
  /// The arena as the MAP packet describes it: a ring of wall cells around
  /// the floor when the arena has walls, and a cell 1 wherever an obstacle
  /// covers part of it; as many cells as fit one MAP packet.
  svgui::Map map() const;
  /// Milliseconds since local midnight at `now`.
  std::uint32_t timestamp_ms(Time now) const;

 protected:
  void on_connect(Time now) override;
  void on_disconnect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;
  void on_fault(Time now, bool entered) override;

 private:
  void handle_read(Time now, const svgui::ReadEvent& read);
  bool handle_auth(Time now, const svgui::ReadEvent& read);
  void handle_v2019(Time now, ByteView packet);
  void handle_head(Time now, ByteView packet);
  void handle_task(Time now, ByteView packet);
  void handle_settings(Time now, ByteView packet);
  /// v2019 TASK or SETTINGS `kind` with `coi`: dropped without a word while
  /// another COI is in progress; else, unless a behaviour rejects it (an
  /// ANSWER of code 0) or ignores it, the car is busy with `coi` from now on
  /// and `run` acts on it.
  template <class Run>
  void run_with_coi(Time now, std::string_view kind, std::uint8_t coi, Run run);
  void start_task(Time now, std::uint8_t type, const std::vector<std::int32_t>& params);
  void finish_task(std::uint8_t code);
  void task_step(Time now);
  void control_step(Time now);
  bool looping() const;
  void apply_steering(double wheel_deg);
  double servo_zero_deg() const;
  bool unusable(const std::string& why);
  void send_message(const svgui::Message& message);
  void say(const std::string& line) const;

  svgui::Version version_;
  sim::AckermannChassis& chassis_;
  svgui::ProgramReceiver receiver_;
  double commanded_wheel_deg_ = 0;
};

}  // namespace hil::mocks
