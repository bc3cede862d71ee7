#pragma once
// The LOGI client's stateful property test bench: the client (with a
// planted bug if asked, tests/property/planted_bug.hpp) against the mock
// LOGI car (physics included) over mem:// with fault rules, in virtual time
// (logi_rig.cpp); rapidcheck commands for operator actions, car-side events
// and time (logi_commands.cpp); a recorder of everything the client, the
// wire and the car did; and one named check per rule of the LOGI
// documentation's sections 5, 9 and 10 (logi_checks.cpp; those of the
// safety guard, logi_safety_checks.cpp).

#include <rapidcheck.h>
#include <rapidcheck/state.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "client/logi/session.hpp"
#include "link/link.hpp"
#include "mocks/logi.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/property/planted_bug.hpp"

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
/// Whether `m` asks the car to move: MV with a direction, or ST:RUN.
bool is_movement(const protocol::logi::Message& m);

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
  estop_st_stop_resent,
  car_rests_after_estop,
  move_timeout_stops,
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

/// The car at an instant when an emergency stop's ST:STOP attempt, had it
/// got through, must have stopped it: an attempt's time plus kBrakeBound.
struct EstopSample {
  std::size_t op = 0;  ///< index into Rig::ops of the emergency stop
  Time at{0};
  bool running = false;  ///< the car was in an auto run
  bool at_rest = false;  ///< the chassis's wheels were still
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
  std::vector<EstopSample> estop_samples;

 private:
  class Observer;
  friend class Observer;
  void on_event(Time now, const Event& e);
  void check_chassis(Time due, std::size_t frame_index);
  void check_rest(Time due, std::size_t op_index);
  void sample_estop(Time due, std::size_t op_index);
  bool at_rest();
  void on_car_accepted(Time at, const protocol::logi::Feedback& fb);
  OpRecord begin_op(OpRecord::Kind kind, int value);
  void end_op(OpRecord r);

  test::VirtualCar<mocks::LogiFirmware> car_;
  std::unique_ptr<PlantedBugSession> session_;
  std::shared_ptr<Observer> observer_;
  std::multimap<Time, std::size_t> chassis_checks_;  // due -> index of the stop in car_frames
  std::multimap<Time, std::size_t> rest_checks_;     // due -> index of the release/stop in ops
  std::multimap<Time, std::size_t> estop_samples_;   // due -> index of the emergency stop in ops
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

// ---- what the checks share ----

/// One event of a request: its index in Rig::events, its time, the event.
struct Step {
  std::size_t index;
  Time at;
  const Event* e;
};
/// Every event of each request, in order (its CommandEvents and
/// FeedbackEvents; logi_checks.cpp).
std::map<RequestId, std::vector<Step>> by_request(const Rig& rig);

// ---- the safety guard's checks (logi_safety_checks.cpp) ----

/// Requests written by an emergency stop (exempt from the single queue).
std::set<RequestId> estop_requests(const Rig& rig);
/// The request of the ST:STOP emergency stop `op` wrote, if it wrote one.
std::optional<RequestId> estop_st_stop(const Rig& rig, const OpRecord& op);
/// The MV:STOPs the client wrote on its own after a move timed out.
std::set<RequestId> fail_safe_stops(const Rig& rig);
/// Whether the faults destroyed (dropped or corrupted) a frame to the car
/// holding `text` at exactly `at`.
bool destroyed_at(const Rig& rig, Time at, const std::string& text);
/// Each release of a held direction writes MV:STOP (at once on an idle line).
std::string check_stop_on_release(const Rig& rig);
/// The stale warning rises 2 s and 1 ns after the last STAT (or connect),
/// and only a STAT clears it.
std::string check_stale(const Rig& rig);
/// An emergency stop writes MV:STOP, then ST:STOP unless the car is known in MAN.
std::string check_estop_order(const Rig& rig);
/// FB:MV:0 for an operator's move: the notice, MD:MAN, one retry.
std::string check_mode_conflict(const Rig& rig);
/// The safe state on a lost link; nothing written before the operator acts.
std::string check_safe_state(Rig& rig);
/// The emergency stop is never refused while connected and writes MV:STOP at once.
std::string check_estop_accessible(const Rig& rig);
/// Every emergency stop's ST:STOP is written at its press and again every
/// 800 ms until the car answers it or it is cancelled; never uncertain.
std::string check_estop_st_stop_resent(const Rig& rig);
/// At the first 800 ms attempt slot of an emergency stop whose ST:STOP the
/// faults did not destroy, the car stops: 520 ms on it runs no more and rests.
std::string check_car_rests_after_estop(const Rig& rig);
/// A timed-out MV:<dir> is not resent, and MV:STOP is the next command
/// written (at the same instant when nothing else awaits feedback).
std::string check_move_timeout_stops(const Rig& rig);

/// Whether the session reached the situation property `p` is about (for
/// the distribution rapidcheck prints: how often each rule was tested).
bool exercised(Prop p, const Rig& rig);

/// One random session of 60 s under `bug`, then property `p` checked.
/// This is the body of every named property (RC_ASSERT inside).
void run_property(Prop p, PlantedBug bug = PlantedBug::none);

}  // namespace hil::client::logi::prop
