#pragma once
// The Arduino client's property bench: the session (with a planted bug if
// asked, tests/property/arduino_planted_bug.hpp) against the robot on
// mem:// (the behavioural mock, or hil's test sketch on the emulated
// ATmega328P: tests/client/arduino_board.hpp) under a random fault
// schedule, in virtual time, and a recorder of
// everything it reported (arduino_rig.cpp); the random operator session
// that drives it (arduino_rig.cpp); and one check per rule of
// docs/clients/arduino.md, read from the frame log, the events and the
// chassis (arduino_checks.cpp).

#include <rapidcheck.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "client/arduino/core.hpp"
#include "client/arduino/session.hpp"
#include "link/faults/profile.hpp"
#include "link/link.hpp"
#include "mocks/arduino.hpp"
#include "protocol/arduino/codec.hpp"
#include "tests/client/arduino_board.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/property/arduino_planted_bug.hpp"

namespace hil::client::arduino::prop {

namespace proto = protocol::arduino;

/// Faults that keep the oracle sound: whole frames dropped or duplicated,
/// one position corrupted (the XOR checksum always catches it), delays,
/// fragments, batches, harmless noise, stalls and link resets. Byte drops
/// and multi-position corruption are left out: they can turn a frame into
/// another valid one, which no client can tell.
rc::Gen<link::FaultProfile> gen_faults();

/// Any request the operator can make, including a V the protocol cannot
/// carry (refused at once, no SEQ used).
rc::Gen<proto::Body> gen_request();

/// Whether the protocol can carry `body` (V only takes 0..255).
bool is_valid_request(const proto::Body& body);

using test::Board;

/// The robot (`board`) on mem://arduino, a session to it (its core with
/// `bug` planted), and everything the session reported, stamped with the
/// virtual clock. The session opens the port at 0 s; on the emulated board
/// the rig then waits until the sketch listens after the reset that caused
/// (test::BoardCar::wait_until_listening()).
struct ArduinoRig {
  struct Done {
    Time at{0};
    RequestId id = 0;
    Result result;
    bool robot_moving = false;  ///< the mock's motion, or the emulated board's motor pins
    int left_pwm = 0;
    int right_pwm = 0;
  };

  /// Records when a link to the robot opened and closed, whoever closed it.
  struct Closes : link::LinkObserver {
    Closes(std::vector<Time>& closes, std::vector<Time>& opens) : out_(closes), opens_(opens) {}
    void on_open(Time at, const std::string&, const std::string&) override { opens_.push_back(at); }
    void on_close(Time at, const link::LinkClose&) override { out_.push_back(at); }
    std::vector<Time>& out_;
    std::vector<Time>& opens_;
  };

  explicit ArduinoRig(link::FaultProfile faults, PlantedBug bug = PlantedBug::none,
                      Board board = Board::mock);

  Time now() const { return car.executor.now(); }

  // The records come first: the car and the session report into them until
  // they are gone.
  std::vector<LinkChanged> links;
  std::vector<Done> done;
  std::map<RequestId, proto::Body> bodies;
  std::vector<RequestId> queued;  ///< requests that did not end at once, in order
  std::vector<Time> closes;       ///< when a link to the robot closed
  std::vector<Time> car_opens;    ///< when a link to the robot opened
  /// Connections the robot turned away (still busy with the last one), as
  /// counted at each link change.
  std::vector<std::uint64_t> turned_away;
  std::vector<Time> operator_opens{Time{0}};  ///< when the operator opened the port
  /// How many frames the session had logged when the operator opened the
  /// port, one per entry of operator_opens: orders that open against frames
  /// of the same instant.
  std::vector<std::size_t> logged_at_operator_open{0};
  test::BoardCar car;
  std::unique_ptr<ArduinoSession> session;
};

/// Lets the run play out for `limit`. The emulated board's minute costs
/// seconds of CPU, so on it the run ends as soon as it has settled
/// (nothing queued or in flight, the link OPEN, CLOSED or DOWN), within
/// `limit`: what happened until then is what the checks read, and the rest
/// would only add health checks.
void finish(ArduinoRig& rig, Duration limit);

/// One frame of the session's log.
struct WireFrame {
  Time at{0};
  bool tx = false;
  std::string raw;
  std::optional<proto::Message> message;  ///< when it decodes
};

/// The session's frame log, each frame decoded in the client's dialect.
std::vector<WireFrame> wire_of(const ArduinoRig& rig);

/// The run as text, shown with a failing case.
std::string dump(const ArduinoRig& rig, const std::vector<WireFrame>& wire);

// ---- the checks (arduino_checks.cpp); each fails the case by RC_ASSERT ----

/// One request's frames on the wire: the consecutive TX frames with one SEQ.
struct Exchange {
  std::uint8_t seq = 0;
  std::size_t first = 0;  ///< index in the wire of its first TX
  std::vector<std::size_t> sends;
  int retries = 0;
  int resends = 0;
  bool reconnect_check = false;
};

/// Rule: every frame of a request after its first goes out either the
/// instant a NACK BAD_CS with its SEQ came in (a resend: same attempt) or
/// exactly base x 2^attempt after the one before it (a retry); never more
/// retries than allowed, never more than 3 resends; a port the client
/// reopened carries only its proving PINGs until it is OPEN again. Returns
/// the exchanges it read.
std::vector<Exchange> check_attempt_times(const ArduinoRig& rig,
                                          const std::vector<WireFrame>& wire);

/// Which rules of a request's result check_results() holds it to.
enum class ResultRules : std::uint8_t {
  /// An answer is taken only for the request with its SEQ, and carries what
  /// the robot said to that very request.
  answers,
  /// The result counts the request's retries and resends as they went out,
  /// and a timeout ends exactly base x 2^(last attempt) after its last frame.
  attempts,
};

void check_results(const ArduinoRig& rig, const std::vector<WireFrame>& wire,
                   const std::vector<Exchange>& exchanges, ResultRules rules);

/// Rule: the link moves only along the documented edges, and each timed
/// edge at its time: RECONNECTING 0.5 s after DEGRADED, the next reopen
/// 1, 2, 4 s after each failure, OPEN again only on an ACK to the PING sent
/// on the reopened port, nothing but that PING while reconnecting.
void check_link_states(const ArduinoRig& rig, const std::vector<WireFrame>& wire);

/// Rule: requests are served one at a time, in the order they were made;
/// each ends exactly once.
void check_order(const ArduinoRig& rig);

// ---- the random session (arduino_rig.cpp) ----

/// What a session property checks of a whole run.
using SessionCheck = void (*)(const ArduinoRig&, const std::vector<WireFrame>&);

/// A random session with `bug` planted in the client, against `board`: a
/// random fault schedule, then random operator requests, waits, robot
/// misbehaviour, closes and opens (each command checks what the operator
/// sees at once), then a minute for every retry, reconnect and timeout to
/// play out; `check` reads the whole run. The emulated board misbehaves
/// only as the driver can make it (hanging up, resetting the connection):
/// scripted silence and refusals do not act on the sketch.
void after_a_random_session(SessionCheck check, PlantedBug bug = PlantedBug::none,
                            Board board = Board::mock);

}  // namespace hil::client::arduino::prop
