#pragma once
// A mock firmware: a sans-I/O state machine that takes the client's bytes
// and the time, drives one simulated vehicle, and hands back the bytes to
// send and the next time it wants to run. The same object runs under the
// virtual-time driver and the real-time driver (mocks/server.hpp).

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "link/byte_pipe.hpp"
#include "link/protocol_adapter.hpp"
#include "link/time.hpp"
#include "mocks/behaviour.hpp"
#include "protocol/common/bytes.hpp"
#include "sim/vehicle.hpp"
#include "sim/world.hpp"

namespace hil::mocks {

using protocol::Bytes;
using protocol::ByteView;

/// Throws std::invalid_argument("<config>: <what>") unless `ok`: how every
/// firmware's `*Config::checked()` refuses a field.
void require_config(std::string_view config, bool ok, const std::string& what);

/// The vehicle's differential chassis, or std::invalid_argument naming the
/// firmware, the vehicle and `hint` (how to get a fitting vehicle).
sim::DifferentialChassis& differential_chassis_of(sim::Vehicle& vehicle, std::string_view firmware,
                                                  std::string_view hint = {});

/// The vehicle's Ackermann chassis, or std::invalid_argument naming the
/// firmware, the vehicle and `hint`.
sim::AckermannChassis& ackermann_chassis_of(sim::Vehicle& vehicle, std::string_view firmware,
                                            std::string_view hint = {});

/// The vehicle's mecanum chassis, or std::invalid_argument naming the
/// firmware, the vehicle and `hint`.
sim::MecanumChassis& mecanum_chassis_of(sim::Vehicle& vehicle, std::string_view firmware,
                                        std::string_view hint = {});

/// The first whole multiple of `period` after `now`: the next tick of a
/// timer that has run on that period since the vehicle started.
Time next_grid_point(Time now, Duration period);

struct FirmwareStats {
  std::uint64_t connections = 0;  ///< clients served so far
  std::uint64_t bytes_in = 0;
  std::uint64_t bytes_out = 0;
  std::uint64_t frames_in = 0;   ///< client frames that decoded
  std::uint64_t frames_out = 0;  ///< frames sent (answers, telemetry, scripted)
  std::uint64_t bad_frames = 0;  ///< checksum errors, garbage, malformed or oversized input
  std::uint64_t rejected = 0;    ///< commands a behaviour made the car refuse
  std::uint64_t ignored = 0;     ///< commands a behaviour swallowed
};

class Firmware {
 public:
  /// The vehicle must live in `world`; both must outlive the firmware.
  /// `protocol` and `profile` name what it plays (protocol(), profile());
  /// both are static strings.
  Firmware(sim::World& world, sim::Vehicle& vehicle, std::string_view protocol,
           std::string_view profile = {});
  virtual ~Firmware();
  Firmware(const Firmware&) = delete;
  Firmware& operator=(const Firmware&) = delete;

  /// "logi", "wr8", "arduino" or "leka".
  std::string_view protocol() const { return protocol_; }
  /// The car profile it plays (protocol/common/car_profile.hpp); empty: the
  /// car's default.
  std::string_view profile() const { return profile_; }
  /// How a link in front of this firmware frames its bytes (fault rules,
  /// captures): protocol_adapter(protocol(), profile()) unless the
  /// firmware's own settings change the framing (a WR8 byte layout).
  virtual std::shared_ptr<const link::ProtocolAdapter> adapter() const;

  // ---- driver side: every call first advances the world to `now` ----

  /// A client connected (TCP accept, the serial port opened).
  void connect(Time now);
  /// The client went away (or the driver closed it).
  void disconnect(Time now);
  /// Bytes from the client, in whatever pieces they arrived.
  void receive(Time now, ByteView bytes);
  /// The time asked for by next_wakeup() has come (or passed).
  void wake(Time now);
  /// When the firmware next wants wake(); nullopt: only on input.
  std::optional<Time> next_wakeup() const;

  /// Bytes to send to the client since the last call: what the firmware
  /// sent at least reply_latency() before the driver's latest call.
  Bytes take_output();
  /// Set when the firmware (or a behaviour) wants the connection closed;
  /// the driver closes it after sending what take_output() returned (a
  /// close waits for the bytes sent before it that are still delayed).
  std::optional<link::CloseMode> take_close();

  /// The firmware's processing time: every byte it sends leaves this long
  /// after the input or tick that made it, in order (a client may send
  /// its next command before the answer to the last one). Zero: in the
  /// same instant. The line's own time per byte (a serial car's baud) is
  /// the link's, not this.
  void set_reply_latency(Duration latency) { reply_latency_ = latency; }
  Duration reply_latency() const { return reply_latency_; }

  // ---- harness side ----

  /// The run's origin is `at` (an external client's first contact with the
  /// car, harness/origin.hpp): a firmware whose clocks count from its first
  /// connection (LogiConfig::grid_from_first_connection) counts them from
  /// here, so its periodic frames keep their times from the origin whether
  /// the client's first contact was its connection or a line it printed
  /// before connecting.
  virtual void set_clock_origin(Time /*at*/) {}

  /// Arms a scripted behaviour; a timed one fires on time (the driver is
  /// told that the next wakeup may have moved).
  void arm(Behaviour behaviour);
  void clear_behaviours();
  /// Called when next_wakeup() may have changed outside a driver call (a
  /// behaviour armed by the harness); the server reschedules on it.
  void set_wakeup_changed(std::function<void()> callback) { wakeup_changed_ = std::move(callback); }
  const Script& script() const { return script_; }

  bool connected() const { return connected_; }
  bool in_fault() const { return fault_; }
  const FirmwareStats& stats() const { return stats_; }
  sim::World& world() { return world_; }
  sim::Vehicle& vehicle() { return vehicle_; }
  const sim::Vehicle& vehicle() const { return vehicle_; }

  /// A short state summary for the terminal status line, e.g. "MAN FWD SP 50".
  virtual std::string summary() const = 0;

 protected:
  // ---- what each firmware implements ----
  virtual void on_connect(Time /*now*/) {}
  virtual void on_disconnect(Time /*now*/) {}
  /// Decode and handle client bytes. Each command goes through
  /// take_command() (or dispose() with its kind first, frame_handled() after).
  virtual void on_bytes(Time now, ByteView bytes) = 0;
  /// Control loop and telemetry; called on every wake and after input.
  virtual void on_tick(Time now) = 0;
  /// The firmware's own next wakeup (control loop, telemetry, a move ending).
  virtual std::optional<Time> next_tick() const = 0;
  /// Entering (true) or leaving (false) the fault state: stop the motors,
  /// show the state where the protocol can.
  virtual void on_fault(Time /*now*/, bool /*entered*/) {}

  // ---- helpers for firmwares ----

  /// Queues one frame for the client (counts it).
  void send(ByteView frame);
  void send(std::string_view frame);
  /// Queues bytes that are not one whole frame (a real firmware's UART
  /// output, as it comes); count_frame_out() counts the frames in them.
  void send_bytes(ByteView bytes);
  void count_frame_out() { ++stats_.frames_out; }
  /// What the armed behaviours say about a command of `kind`; counts
  /// rejects and ignores.
  Disposition dispose(Time now, std::string_view kind);
  /// A client frame of `kind` was handled (fires after-frame behaviours).
  void frame_handled(Time now, std::string_view kind);
  /// A client command of `kind` through the armed behaviours: `handle()`
  /// unless one rejects it (`reject()` sends the protocol's refusal) or
  /// ignores it; then the behaviours waiting for a frame of `kind` fire.
  template <class Handle, class Reject>
  void take_command(Time now, std::string_view kind, Handle handle, Reject reject) {
    switch (dispose(now, kind)) {
      case Disposition::handle:
        handle();
        break;
      case Disposition::reject:
        reject();
        break;
      case Disposition::ignore:
        break;
    }
    frame_handled(now, kind);
  }
  /// take_command() for a command whose rejection goes unanswered.
  template <class Handle>
  void take_command(Time now, std::string_view kind, Handle handle) {
    take_command(now, kind, handle, [] {});
  }
  /// A client frame (or run of bytes) was bad and dropped or refused.
  void count_bad_frame() { ++stats_.bad_frames; }
  void count_frame_in() { ++stats_.frames_in; }
  /// Whether periodic telemetry is muted by a behaviour at `now`.
  bool telemetry_muted(Time now) const { return muted_until_ && now < *muted_until_; }
  /// Asks the driver to close the client's connection.
  void request_close(link::CloseMode mode = link::CloseMode::graceful) { close_ = mode; }

  sim::World& world_;
  sim::Vehicle& vehicle_;

 private:
  void advance(Time now);
  void run_actions(Time now, const std::vector<Behaviour>& fired);
  void enter_fault(Time now, bool entered);

  struct Delayed {
    Time due{0};
    Bytes bytes;
  };
  void release_delayed(Time now);
  void queue_output(ByteView bytes);

  std::string_view protocol_;
  std::string_view profile_;
  Script script_;
  std::function<void()> wakeup_changed_;
  FirmwareStats stats_;
  Bytes output_;
  std::deque<Delayed> delayed_;  // sent, not due yet (due times never decrease)
  Duration reply_latency_{0};
  Time now_{0};
  std::optional<link::CloseMode> close_;
  std::optional<Time> muted_until_;
  bool connected_ = false;
  bool fault_ = false;
};

/// A firmware with its settings (`Config`, fixed when it is made) and the
/// state it keeps (`State`), and their accessors.
template <class Config, class State>
class FirmwareWith : public Firmware {
 public:
  const Config& config() const { return config_; }
  const State& state() const { return state_; }

 protected:
  /// `config` is already checked.
  FirmwareWith(sim::World& world, sim::Vehicle& vehicle, std::string_view protocol,
               std::string_view profile, Config config)
      : Firmware(world, vehicle, protocol, profile), config_(std::move(config)) {}

  Config config_;
  State state_;
};

}  // namespace hil::mocks
