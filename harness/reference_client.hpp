#pragma once
// The built-in reference client of each car as a scenario drives it: the
// car's session on an endpoint, its events written to the timeline as
// client records, and operator actions carried out one at a time through
// the car's operator runner. Uses only the executor and transports of the
// context it is given, so the same object serves virtual and real time.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/reference_settings.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"
#include "mocks/car.hpp"

namespace hil::harness {

class ReferenceSession {
 public:
  /// How an action ended; `reason` says why it failed (or what came back).
  using Done = std::function<void(bool ok, const std::string& reason)>;

  virtual ~ReferenceSession() = default;

  /// Opens the port for cars whose vocabulary has no `connect` (Arduino,
  /// Leka); nothing for the others.
  virtual void start() {}
  /// Carries out one operator action; `done` runs once when it ends, on a
  /// later executor turn or at once.
  virtual void execute(const std::string& text, Done done) = 0;
  /// Whether execute() may be called again before an earlier action
  /// ended (a scheduled action beside the sequence's); otherwise the
  /// runner hands actions over one at a time.
  virtual bool concurrent() const { return false; }
  /// Abandons the actions under way; their `done` is not called.
  virtual void cancel() = 0;
  /// Closes the connection at the end of the run (no reconnect).
  virtual void stop() = 0;
  /// State that only shows by looking (the Leka port being open), checked
  /// on every simulation tick.
  virtual void poll() {}
  /// After stop(): whether the client is gone for good (an external
  /// program has exited). The runner waits for this a while.
  virtual bool finished() const { return true; }
  /// After stop(), when finished() did not come in time: end it by force
  /// (`hard`: no more chances).
  virtual void terminate(bool hard) { (void)hard; }
};

/// The car's reference client on `endpoint`, writing client records to
/// `timeline`, its library's defaults changed by `settings` (names to values
/// that reference_setting_problem() accepts; a bad one is a programmer
/// error and throws std::invalid_argument), speaking the car's profile
/// `profile` (empty: the default; an unknown one throws
/// protocol::ProfileError). `context` and `timeline` must outlive it.
std::unique_ptr<ReferenceSession> make_reference_session(
    mocks::CarKind car, link::TransportContext& context, link::Endpoint endpoint,
    RunTimeline& timeline, const nlohmann::json& settings = nlohmann::json::object(),
    std::string_view profile = {});

/// Why `text` is not an operator action of the car's vocabulary, or nullopt
/// when it is one ("1:7: unknown direction 'UP'").
std::optional<std::string> action_problem(mocks::CarKind car, std::string_view text);

}  // namespace hil::harness
