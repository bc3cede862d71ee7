#pragma once
// The LOGI logistics car's firmware as a mock: LOGI:<payload>:<CS># commands
// answered with FB feedback, STAT telemetry on a fixed grid, manual mecanum
// motion, a line-following auto mode that stops on RFID stations, and an
// obstacle lock from the sonar (docs/mocks/logi.md).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mocks/firmware.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/logi/message.hpp"

namespace hil::mocks {

/// How the mock LOGI firmware behaves where real firmwares could differ.
/// The defaults work on the built-in warehouse with sim::logi_car().
struct LogiConfig {
  /// How the car reads its input: the guide's stream rule (guide, the
  /// default), or the STM32 parser, one hand-over (one delivery from the
  /// link) at a time (firmware); docs/protocols/logi.md, "Profiles".
  protocol::logi::Dialect dialect = protocol::logi::Dialect::guide;
  /// Stations GS accepts (the tags read "001", "002", ...); each 0..999.
  std::vector<int> stations = {1, 2};
  /// The SP setting after power-on, 0..100.
  int boot_speed_percent = 50;
  /// The mode after power-on.
  protocol::logi::Mode boot_mode = protocol::logi::Mode::automatic;
  /// STAT goes out at every multiple of this while a client is connected.
  Duration stat_period = link::milliseconds(500);
  /// The control loop (line follower, obstacle lock, station check) runs at
  /// every multiple of this while the car has something to do.
  Duration control_period = link::milliseconds(10);
  /// When the car was switched on: the STAT and control-loop grids are the
  /// multiples of their periods counted from this time, not from zero. Cars
  /// of a fleet switched on at different moments spread their telemetry and
  /// control work instead of all waking at once. 0..stat_period.
  Duration boot_offset = Duration::zero();
  /// The grids count from the first client's connection (plus boot_offset)
  /// instead of from time 0: a car switched on as its client connects; or
  /// from the run's origin when the harness gives one before that
  /// (set_clock_origin()). The harness sets it for an external client, so
  /// the STATs keep the same times from the origin as they have from time
  /// 0 with the reference client.
  bool grid_from_first_connection = false;
  /// The obstacle lock holds the car while the sonar reads below this.
  int obstacle_stop_cm = 20;
  /// ...and lets go when it reads at least obstacle_stop_cm + this again.
  int obstacle_clear_hysteresis_cm = 5;
  /// An auto run ends (RUN 0) when no tracker sensor has seen tape for this
  /// long while the car drives.
  Duration line_lost_timeout = link::milliseconds(500);
  /// Follower turn rate: rad/s per unit of DEV per m/s of forward speed.
  double steer_gain_radps_per_mps = 5.0;
  /// Follower sideways correction: m/s of strafe per unit of DEV per m/s of
  /// forward speed (the mecanum wheels can slide the car back over the tape).
  double strafe_gain = 0.1;
  /// false (the source's firmware has no watchdog): motion goes on when the
  /// client goes away. true: losing the client stops manual motion and ends
  /// an auto run.
  bool stop_on_disconnect = false;
  /// false: a frame whose checksum is right but written in lowercase hex is
  /// dropped like a bad checksum.
  bool accept_lowercase_checksum = false;
};

/// Why the last auto run ended.
enum class LogiRunEnd : std::uint8_t {
  none,         ///< no run has ended yet
  arrived,      ///< the target station's tag was read
  stopped,      ///< ST:STOP
  line_lost,    ///< no tape for LogiConfig::line_lost_timeout
  mode_change,  ///< MD:MAN during the run
  fault,        ///< the fault state was entered
  disconnect,   ///< the client left and stop_on_disconnect is set
};
std::string_view to_string(LogiRunEnd end);

/// The firmware's state, read-only for tests, the harness and the status
/// line. Sensor fields hold what the firmware last read (a control tick, a
/// command or a STAT).
struct LogiState {
  int speed_percent = 50;  ///< SP
  int station = 0;         ///< STA: the last station GS accepted (0: none yet)
  /// A GS has been accepted since the last arrival, so ST:RUN may start.
  bool station_armed = false;
  bool running = false;  ///< RUN
  protocol::logi::Mode mode = protocol::logi::Mode::automatic;
  protocol::logi::Direction manual = protocol::logi::Direction::stop;  ///< MAN
  bool obstacle = false;  ///< OBS: the obstacle lock holds the car
  int distance_cm = 0;    ///< DIS
  std::uint8_t track_mask = 0;
  int deviation = 0;
  /// The deviation the follower steers by (the last seen while on tape).
  int steer_deviation = 0;
  /// Since when the tracker has seen no tape during the run.
  std::optional<Time> line_lost_since;
  /// The RFID tag under the reader at the last look.
  std::optional<std::string> tag;
  std::uint64_t arrivals = 0;  ///< runs that ended on their station
  LogiRunEnd last_run_end = LogiRunEnd::none;
};

class LogiFirmware final : public FirmwareWith<LogiConfig, LogiState> {
 public:
  /// Throws std::invalid_argument when the vehicle has no mecanum chassis
  /// or a config value is out of its range.
  LogiFirmware(sim::World& world, sim::Vehicle& vehicle, LogiConfig config = {});

  std::string summary() const override;
  void set_clock_origin(Time at) override;

  /// The STAT message the car would send now, from the last sensor reads.
  protocol::logi::Status status() const;

 protected:
  void on_connect(Time now) override;
  void on_disconnect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;
  void on_fault(Time now, bool entered) override;

 private:
  using Message = protocol::logi::Message;
  using Command = protocol::logi::Command;

  void handle_frame(Time now, const protocol::Frame<Message>& frame);
  void handle_error(Time now, const protocol::DecodeError& error);
  /// Acts on one command; returns whether it was accepted.
  bool execute(Time now, const Message& command);
  bool set_station(int station);
  bool start_run(Time now);
  bool set_mode(protocol::logi::Mode mode);
  bool move(protocol::logi::Direction direction);
  void end_run(LogiRunEnd why);
  void answer(Command command, bool accepted);

  void control(Time now);
  void read_sensors();
  /// Whether the commanded motion has a forward part the sonar guards.
  bool lock_applies() const;
  void update_obstacle();
  /// Sets the chassis target from the state: manual direction, auto follow,
  /// obstacle lock, fault.
  void apply_motion();
  /// Whether the control loop has work: a run, a manual move, wheels still turning.
  bool active() const;
  Time grid_after(Time now, Duration period) const;

  sim::MecanumChassis& chassis_;
  protocol::logi::Decoder decoder_;
  std::vector<protocol::logi::Item> items_;
  Time next_stat_{0};
  /// Where the grids count from: 0, or the run's origin or first connection
  /// (LogiConfig::grid_from_first_connection).
  std::optional<Time> grid_start_;
  Time next_control_{0};
  bool control_scheduled_ = false;      // next_control_ was handed out by next_tick()
  std::optional<std::string> run_tag_;  // the tag the station check saw last
};

}  // namespace hil::mocks
