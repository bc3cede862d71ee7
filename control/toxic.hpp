#pragma once
// Toxiproxy's toxics, as hil fault rules. A toxic is what a Toxiproxy client
// adds to a proxy (type, stream, toxicity, attributes); hil keeps it as
// given, for the API to show, and turns it into fault rules for each link.
// Toxiproxy's types (latency, bandwidth, slow_close, timeout, reset_peer,
// slicer, limit_data) map to the rule kinds docs/proxy-api.md lists; hil's
// own rule kinds are toxic types too, with their YAML keys as attributes.
//
// Toxiproxy's attributes are whole numbers, 0 or more, 0 when left out (as
// in Toxiproxy 2.x, toxics/*.go): latency {latency, jitter} ms; bandwidth
// {rate} KB/s, 1 KB = 1000 bytes; slow_close {delay} ms; timeout {timeout}
// ms; reset_peer {timeout} ms; slicer {average_size, size_variation} bytes,
// {delay} microseconds; limit_data {bytes}. The three types whose names are
// hil kinds too (bandwidth, slow_close, limit_data) take hil's keys as well:
// an attribute only hil's form has ("baud", "from", a duration "500ms" for
// slow_close's delay) makes it hil's rule, read as in a profile file.
// Either form, one at a time.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control/api_error.hpp"
#include "link/faults/profile.hpp"
#include "link/time.hpp"

namespace hil::control {

struct Toxic {
  std::string name;  ///< unique on its route; default "<type>_<stream>"
  std::string type;  ///< "latency", ..., or a hil rule kind ("corrupt", ...)
  /// Toxiproxy's "upstream" is the client's bytes to the car (to_car),
  /// "downstream" the car's bytes to the client (to_client, the default).
  link::Direction stream = link::Direction::to_client;
  double toxicity = 1.0;  ///< chance, drawn once per link, that it acts on that link
  /// Toxiproxy's form: every attribute, 0 filled in for those left out.
  /// hil's form: the keys as given (the rule's defaults apply).
  nlohmann::json attributes = nlohmann::json::object();
  link::Time added_at{0};  ///< when it was added (run time); timed toxics count from it
  friend bool operator==(const Toxic&, const Toxic&) = default;
};

/// Toxiproxy's types, then hil's rule kinds not named already, as the API
/// lists them (refuse is not one: it acts on the listener, not a link).
const std::vector<std::string>& toxic_types();

/// A toxic from a request body (POST /proxies/NAME/toxics). With `existing`
/// (POST /proxies/NAME/toxics/TOXIC) the body updates it: attributes given
/// replace theirs, the rest stay; type and name cannot change. Throws
/// ApiError 400 "FIELD: ..." naming the field ("type", "stream",
/// "toxicity", "name", "attributes.KEY"): an unknown type or attribute, a
/// wrong JSON type, a negative number, a toxicity outside [0, 1], a stream
/// other than "upstream" and "downstream", a name other than
/// [A-Za-z0-9_.-]+, a `direction` (a toxic's direction is its stream).
/// hil's form is checked by the fault profile reader, whose message follows
/// the attribute it is about. `now` becomes added_at for a new toxic.
Toxic parse_toxic(const nlohmann::json& body, link::Time now, const Toxic* existing = nullptr);

/// The toxic as Toxiproxy shows it: {name, type, stream, toxicity, attributes}.
nlohmann::json to_json(const Toxic& toxic);

/// Whether the toxic acts on the link whose fault seed is `link_seed`: a
/// uniform draw in [0, 1) from a hash of the seed and the toxic's name,
/// below toxicity (1: every link, 0: none). The same for the same seed and
/// name, independent between toxics.
bool acts_on_link(const Toxic& toxic, std::uint64_t link_seed);

/// The hil rules the toxic is on a link that opened at `link_opened_at`,
/// each named "toxic:<name>" with its stream's direction, active from
/// added_at. Timed toxics (timeout, reset_peer) fire their delay after the
/// later of that and added_at, as Toxiproxy's do on each connection:
///   latency    -> delay, base max(0, latency - jitter) plus [0, 2 jitter]
///                 ([0, latency + jitter] when jitter > latency)
///   bandwidth  -> bandwidth, rate * 1000 bytes per second
///   slow_close -> slow_close
///   timeout    -> drop every frame, and (timeout > 0) disconnect
///   reset_peer -> reset
///   slicer     -> fragment, pieces of [max(1, avg - var), avg + var]
///                 bytes, `delay` apart
///   limit_data -> limit_data (bytes 0: the first frame dropped and the
///                 link closed after it, as Toxiproxy closes at once)
/// A toxic that does nothing (latency and jitter 0, rate 0, slow_close
/// delay 0) has no rules. In hil's form, `from` and `to` count from
/// added_at and `at` from the toxic's start on the link.
link::FaultProfile toxic_rules(const Toxic& toxic, link::Time link_opened_at);

}  // namespace hil::control
