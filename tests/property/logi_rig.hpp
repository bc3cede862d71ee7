#pragma once
// The LOGI client's stateful property test bench: the client (with a
// planted bug if asked, tests/property/planted_bug.hpp) against the mock
// LOGI car (physics included) over mem:// with fault rules, in virtual time
// (logi_rig.cpp); rapidcheck commands for operator actions, car-side events
// and time (logi_commands.cpp); a recorder of everything the client, the
// wire and the car did; and one named check per rule of the LOGI
// documentation's sections 5, 9 and 10 (logi_checks.cpp).

#include <rapidcheck.h>
#include <rapidcheck/state.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "client/logi/session.hpp"
#include "link/link.hpp"
#include "mocks/logi.hpp"
#include "tests/property/planted_bug.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::logi::prop {

using link::Duration;
using link::milliseconds;
using link::seconds;
using link::Time;

/// A direction as the LOGI command table spells it ("FWD", "CCW").
std::string dir_word(protocol::logi::Direction d);
/// A duration in milliseconds, as the checks print it.
std::string ms(Duration d);
/// A frame's bytes as text (LOGI frames are ASCII).
std::string text_of(const protocol::Bytes& b);

/// Every session runs this long in virtual time.
inline constexpr Duration kSessionLength = seconds(60);

/// The braking bound of the simulated chassis, from sim/mecanum.hpp: top
/// speed 0.5 m/s at 100 % braked at 1 m/s^2 takes 500 ms (the fastest turn,
/// 2.78 rad/s at 8 rad/s^2, takes 350 ms); a stop can land inside a 1/120 s
/// physics step and the last step can round up, so two steps (16.7 ms) more:
/// the chassis is at rest 520 ms after a stop reaches the car.
inline constexpr Duration kBrakeBound = milliseconds(520);
/// A stop that must wait for feedback is sent at most three times, 800 ms
/// apart (first send, two retries), so the last attempt leaves 1600 ms after
/// the first.
inline constexpr Duration kLastStopAttempt = milliseconds(1600);
/// End to end: the chassis rests within 1600 + 520 = 2120 ms of a stop that
/// is written at once (emergency stop, release on an idle line) whenever at
/// least one of its attempts that the car acts on in its mode reaches it (in
/// AUTO only ST:STOP: the car refuses MV:STOP there).
inline constexpr Duration kStopToRest = kLastStopAttempt + kBrakeBound;

/// The named properties; each has one check over a recorded session.
enum class Prop : std::uint8_t {
  backoff_delays,
  single_outbound_queue,
  feedback_timeout_800ms,
  retry_rules,
  stop_on_release,
  stale_after_2s,
  emergency_stop_order,
  mode_conflict,
  safe_state_and_reconfirm,
  bad_checksum_dropped,
  stream_gives_every_frame,
  chassis_rests_after_stop,
  connect_disconnect,
  status_and_feedback_parsed,
  buttons_send_exact_frames,
  manual_directions,
  auto_flow,
  reconnects_automatically,
  log_has_tx_rx_errors,
  telemetry_visible,
  mode_and_direction_shown,
  emergency_stop_accessible,
  checksums_built_right,
  count_
};
const char* name_of(Prop p);

/// Which kinds of command a session favours (weights; 0 leaves one out).
struct Focus {
  int connect = 4, disconnect = 1, speed = 4, mode = 4, press = 8, release = 6, station = 2,
      run = 2, stop = 2, estop = 3, advance = 14;
  int drop_link = 1, reject = 2, ignore = 2, mute = 1, faults = 2;
};
Focus focus_for(Prop p);

/// One frame that reached the car intact, with the car's state as it arrived.
struct CarFrame {
  Time at{0};
  std::size_t link = 0;
  protocol::logi::Message message;
  protocol::logi::Mode car_mode = protocol::logi::Mode::automatic;
};

/// One connection as the wire saw it.
struct LinkRecord {
  Time opened{0};
  std::optional<Time> closed;
  link::LinkClose::By closed_by = link::LinkClose::By::hil;
  protocol::Bytes to_car_sent;             ///< what the client wrote, before faults
  protocol::Bytes to_client_delivered;     ///< what reached the client, after faults
  protocol::logi::Decoder to_car_decoder;  // frames delivered to the car, as they complete
};

/// An operator action and what the client answered.
struct OpRecord {
  enum class Kind : std::uint8_t {
    connect,
    disconnect,
    speed,
    mode,
    press,
    release,
    station,
    run,
    stop,
    estop
  };
  Kind kind = Kind::connect;
  Time at{0};
  int value = 0;  ///< percent, station, mode (0 auto, 1 man) or direction
  SubmitResult result;
  ConnectionState state_before = ConnectionState::disconnected;
  bool line_idle = false;  ///< nothing in flight or queued before the call
  std::optional<protocol::logi::Mode> known_mode_before;
  bool car_running = false;                                         ///< the car was in an auto run
  protocol::logi::Mode car_mode = protocol::logi::Mode::automatic;  ///< the car's own mode
  std::size_t links_before = 0;   ///< connections the wire had seen before the call
  std::size_t events_before = 0;  ///< index into events of the first event of the call
  std::size_t events_after = 0;   ///< one past the last
  ConnectionState state_after = ConnectionState::disconnected;  ///< once settled
};

/// A command the car accepted, and whether its state then showed it done.
struct CarAccepted {
  Time at{0};
  protocol::logi::Message command;
  bool ok = true;
  std::string why;
};

/// The client, the car and the wire in virtual time, with everything recorded.
class Rig {
 public:
  explicit Rig(PlantedBug bug = PlantedBug::none, std::uint64_t link_seed = 1);
  ~Rig();

  PlantedBugSession& session() { return *session_; }
  const LogiClientCore& core() const { return session_->core(); }
  mocks::LogiFirmware& firmware() { return *car_.firmware; }
  mocks::MockServer& server() { return *car_.server; }
  sim::Vehicle& vehicle() { return car_.world->vehicle(0); }
  Time now() const { return car_.executor.now(); }

  /// Runs the executor to `until`, stopping at each chassis check on the way.
  void advance_to(Time until);
  /// Runs what is due now (a connection, answers at this instant).
  void settle() { advance_to(now()); }

  /// Operator actions, recorded.
  void op_connect();
  void op_disconnect();
  void op_submit(OpRecord::Kind kind, const protocol::logi::Message& m, int value);
  void op_press(protocol::logi::Direction d);
  void op_release();
  void op_estop();

  /// Car-side events.
  void car_drop_link(bool reset);
  void car_arm(mocks::Behaviour b);
  void car_faults(link::FaultProfile profile);

  /// Every event and operator action with its time, for a failure message.
  std::string timeline() const;

  /// A failure of property `p` seen during the run.
  void fail(Prop p, std::string why);
  const std::vector<std::string>& failures(Prop p) const { return failures_[static_cast<int>(p)]; }

  // ---- the record ----
  std::vector<std::pair<Time, Event>> events;
  std::vector<OpRecord> ops;
  std::vector<LinkRecord> links;
  std::vector<CarFrame> car_frames;  ///< every frame delivered intact to the car
  std::vector<link::FaultEvent> faults;
  /// Shadow of what the operator confirmed on the current connection.
  bool md_on_connection = false;
  bool sp_on_connection = false;
  std::optional<protocol::logi::Direction> held;   ///< what the operator holds, for the client
  std::optional<protocol::logi::Mode> shown_mode;  ///< last STAT's or accepted MD's mode
  std::optional<protocol::logi::Status> last_status;
  std::vector<CarAccepted> car_accepted;
  /// Chassis checks that made a claim (not voided by later motion or loss).
  std::size_t stop_claims = 0;

 private:
  class Observer;
  friend class Observer;
  void on_event(Time now, const Event& e);
  void check_chassis(Time due, std::size_t frame_index);
  void check_rest(Time due, std::size_t op_index);
  bool at_rest();
  void on_car_accepted(Time at, const protocol::logi::Feedback& fb);
  OpRecord begin_op(OpRecord::Kind kind, int value);
  void end_op(OpRecord r);

  test::VirtualCar<mocks::LogiFirmware> car_;
  std::unique_ptr<PlantedBugSession> session_;
  std::shared_ptr<Observer> observer_;
  std::multimap<Time, std::size_t> chassis_checks_;  // due -> index of the stop in car_frames
  std::multimap<Time, std::size_t> rest_checks_;     // due -> index of the release/stop in ops
  std::vector<std::string> failures_[static_cast<int>(Prop::count_)];
};

// ---- rapidcheck stateful model and commands ----

/// What the operator has done, for generating sensible next actions.
struct Model {
  bool want_connected = false;
  bool pressed = false;
  Duration elapsed{0};
};
using Command = rc::state::Command<Model, Rig>;
using CommandPtr = std::shared_ptr<const Command>;

/// The command generator for a session that favours `focus`.
std::function<rc::Gen<CommandPtr>(const Model&)> gen_command(Focus focus);

/// The check of property `p` over a finished session; empty when it holds.
std::string check(Prop p, Rig& rig);

/// Whether the session reached the situation property `p` is about (for
/// the distribution rapidcheck prints: how often each rule was tested).
bool exercised(Prop p, const Rig& rig);

/// One random session of 60 s under `bug`, then property `p` checked.
/// This is the body of every named property (RC_ASSERT inside).
void run_property(Prop p, PlantedBug bug = PlantedBug::none);

}  // namespace hil::client::logi::prop
