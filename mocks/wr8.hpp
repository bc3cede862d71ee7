#pragma once
// The WR8 vehicle's firmware as a mock: authentication, the DATA stream, tasks
// and settings over the WR8 protocol, driving a simulated Ackermann chassis
// (docs/mocks/wr8.md).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mocks/firmware.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/message.hpp"
#include "protocol/wr8/profile.hpp"

namespace hil::mocks {

/// Everything a WR8 firmware could plausibly do differently; defaults in
/// docs/mocks/wr8.md.
struct Wr8Config {
  /// Byte-level choices; `profile.auth_text` is the string AUTH must carry.
  protocol::wr8::Profile profile;
  /// Longest client packet accepted (0: the longest the profile can declare).
  std::size_t max_packet_bytes = 0;

  std::uint8_t device_code = 8;  ///< in AUTH-REPLY
  std::uint8_t device_id = 1;    ///< in AUTH-REPLY

  /// After a wrong authentication string the connection is closed this much
  /// later; nothing is answered in between. Each further failure in a row
  /// (across connections, until a right login) doubles it, up to
  /// wrong_auth_max_delay: with a cap above the delay (e.g. 30 s), guessing
  /// the string gets slower and slower. The default cap equals the delay
  /// (a constant 1 s, as the shipped scenarios and clients expect).
  Duration wrong_auth_close_delay{link::seconds(1)};
  Duration wrong_auth_max_delay{link::seconds(1)};
  /// DATA period once authenticated, on a grid of whole periods since the
  /// vehicle started (100 ms: 10 Hz).
  Duration data_period{link::milliseconds(100)};
  /// Control loop period, on a grid of whole periods since the vehicle started.
  Duration control_period{link::milliseconds(10)};

  /// Settings in force at power-on. The drive controller's speed command is
  /// p * e + i * integral(e dt) + d * de/dt with e the distance still to go
  /// (metres in, metres per second out).
  double p = 1.5;
  double i = 0.25;
  double d = 0.05;
  /// Servo position, in servo degrees, the firmware treats as straight ahead.
  double servo_zero_deg = 90;
  /// Servo position at which the wheels really are straight (the mechanics);
  /// servo_zero_deg - servo_center_deg turns every wheel angle by that much.
  double servo_center_deg = 90;
  /// Servo zero values a SETTINGS may set (the servo's travel).
  double servo_min_deg = 0;
  double servo_max_deg = 180;
  /// Largest P, I or D a SETTINGS may set; negative gains are refused too.
  double max_gain = 100;

  /// The drive task's speed command is clamped to this.
  double drive_max_speed_mps = 0.5;
  /// A positive command below this is raised to it (the motor's dead band),
  /// so the car creeps onto the distance instead of stalling short of it.
  double drive_min_speed_mps = 0.05;
  /// Longest distance one drive task accepts.
  double max_drive_cm = 1000;
  /// A drive task whose wheels cover less than stall_progress_m in this long
  /// answers error and stops.
  Duration stall_timeout{link::seconds(2)};
  double stall_progress_m = 0.001;

  /// How long the blink task flashes the turn signals before it completes.
  Duration blink_duration{link::seconds(2)};

  /// true: a client that goes away stops the car and ends every task (no
  /// answer). false: tasks run on to their end unwatched.
  bool stop_on_disconnect = true;

  /// One line per authentication event for a person (a failed login with
  /// its count, packets dropped before login); never holds the string that
  /// was tried or the real one. May be empty.
  std::function<void(const std::string&)> log;
};

/// Where the authentication of the current connection stands.
enum class Wr8Session : std::uint8_t {
  unauthenticated,  ///< waiting for AUTH; everything else is dropped
  authenticated,    ///< DATA flows, tasks and settings are served
  refused,          ///< a wrong string came; closing after the delay, nothing answered
};

std::string_view to_string(Wr8Session session);

/// The firmware's state, read-only for tests and the harness.
struct Wr8State {
  Wr8Session session = Wr8Session::unauthenticated;
  std::optional<Time> close_at;  ///< when a refused connection will be closed

  /// Settings in force, exactly as the last SETTINGS (or the config) gave
  /// their bits, and as numbers.
  std::vector<protocol::wr8::Setting> settings;
  double p = 0;
  double i = 0;
  double d = 0;
  double servo_zero_deg = 0;
  /// The wheel angle the last turn task asked for, before the servo offset.
  double commanded_wheel_angle_deg = 0;

  struct Drive {
    std::uint8_t coi = 0;
    double target_m = 0;
    double start_odometer_m = 0;  ///< vehicle odometry when the task began
    double covered_m = 0;         ///< at the last control step
    Time started{};
    Time last_progress{};        ///< when the wheels last gained stall_progress_m
    double progress_mark_m = 0;  ///< covered_m at that moment
    double integral_m_s = 0;
    double last_error_m = 0;
    bool has_last_error = false;
    double speed_command_mps = 0;
  };
  struct Turn {
    std::uint8_t coi = 0;
    double angle_deg = 0;
  };
  struct Blink {
    std::uint8_t coi = 0;
    Time until{};
  };
  std::optional<Drive> drive;  ///< a running drive task
  std::optional<Turn> turn;    ///< a running turn task
  std::optional<Blink> blink;  ///< turn signals flashing

  std::optional<Time> next_data;     ///< the next DATA packet is due then
  std::optional<Time> next_control;  ///< the next control step (only while needed)

  std::uint64_t dropped_unauthenticated = 0;  ///< packets dropped before AUTH or while refused
  std::uint64_t auth_failures = 0;
  /// Failed logins since the last right one (sets the next close delay).
  std::uint64_t auth_failures_in_a_row = 0;
  /// Packets dropped before AUTH or while refused on this connection.
  std::uint64_t dropped_this_connection = 0;
  std::uint64_t data_sent = 0;
  std::uint64_t tasks_completed = 0;
  std::uint64_t tasks_failed = 0;  ///< RESPONSE error for a task, whatever the reason
};

/// The WR8 vehicle: a TCP server that authenticates its GUI, streams DATA and
/// runs tasks on an Ackermann chassis under a PID distance controller.
class Wr8Firmware final : public FirmwareWith<Wr8Config, Wr8State> {
 public:
  /// Throws std::invalid_argument when the vehicle has no Ackermann chassis
  /// or the config cannot work (a period not positive, an invalid profile).
  Wr8Firmware(sim::World& world, sim::Vehicle& vehicle, Wr8Config config = {});

  /// Frames the link by this vehicle's profile (byte order, block sizes, DATA table).
  std::shared_ptr<const link::ProtocolAdapter> adapter() const override {
    return link::wr8_adapter(config_.profile);
  }
  std::string summary() const override;

  /// The state code DATA and AUTH-REPLY would carry now.
  protocol::wr8::State state_code() const;
  /// The DATA packet the vehicle would send at `now` (what on_tick sends).
  protocol::wr8::Data data_at(Time now) const;
  /// The wheel angle the servo offset adds to every commanded one.
  double servo_offset_deg() const { return state_.servo_zero_deg - config_.servo_center_deg; }

 protected:
  void on_connect(Time now) override;
  void on_disconnect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;
  void on_fault(Time now, bool entered) override;

 private:
  using Message = protocol::wr8::Message;

  void handle_item(Time now, const protocol::wr8::Item& item);
  void handle_bad(Time now, const protocol::DecodeError& error);
  void handle(Time now, const Message& message);
  void reject(Time now, const Message& message);
  void handle_auth(Time now, const protocol::wr8::Auth& auth);
  void refuse(Time now);
  void handle_task(Time now, const protocol::wr8::Task& task);
  void handle_settings(Time now, const protocol::wr8::Settings& settings);
  void control_step(Time now);
  void drive_step(Time now);
  void apply_steering();
  void stop_motion();
  void abort_tasks(bool answer);
  bool control_needed() const;
  void say(const std::string& line) const;

  /// Sends to an authenticated client only (nothing is answered otherwise).
  void answer(const Message& message);
  void respond(std::uint8_t coi, protocol::wr8::ResponseCode code);
  void task_failed(std::uint8_t coi);
  void task_completed(std::uint8_t coi);

  sim::AckermannChassis& chassis_;
  protocol::wr8::Decoder decoder_;
  std::vector<protocol::wr8::Item> items_;
};

/// The close delay after the `failures_in_a_row`-th failed login in a row
/// (1: the first): wrong_auth_close_delay doubled per earlier failure,
/// capped at wrong_auth_max_delay.
Duration wrong_auth_delay(const Wr8Config& config, std::uint64_t failures_in_a_row);

}  // namespace hil::mocks
