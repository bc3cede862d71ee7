#pragma once
// Transport endpoints chosen by URI:
//   tcp://127.0.0.1:9000
//   pty:///tmp/hil-arduino0?baud=9600&reset_ms=200
//   mem://car0?baud=9600
//   rfc2217://127.0.0.1:4000?baud=9600&reset_ms=200

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>

#include "link/time.hpp"

namespace hil::link {

struct TcpEndpoint {
  std::string host;  ///< numeric address or name; "127.0.0.1" by default for listeners
  std::uint16_t port = 0;
  friend bool operator==(const TcpEndpoint&, const TcpEndpoint&) = default;
};

struct PtyEndpoint {
  std::string path;  ///< stable symlink to the pty, e.g. /tmp/hil-arduino0
  /// Serial pacing in both directions (8N1: 10 bits per byte); 0 = unpaced.
  unsigned baud = 0;
  /// Bytes the client writes in this long after opening the port are lost
  /// (an Arduino resets when the port opens); 0 = off.
  Duration reset_on_open{0};
  friend bool operator==(const PtyEndpoint&, const PtyEndpoint&) = default;
};

struct MemEndpoint {
  std::string name;
  /// Serial pacing in both directions, as on a pty (8N1: 10 bits per byte),
  /// in the executor's time; 0 = unpaced. A listener's rate is the line's:
  /// a client connecting to it is paced at it whatever its own URI says.
  unsigned baud = 0;
  friend bool operator==(const MemEndpoint&, const MemEndpoint&) = default;
};

/// A serial car behind an RFC 2217 (Telnet COM-PORT-OPTION) server on TCP,
/// the way a serial port is shared over a network (ser2net, a COM port
/// redirector on Windows). Listen-only.
struct Rfc2217Endpoint {
  std::string host = "127.0.0.1";  ///< numeric address or name to listen on
  std::uint16_t port = 0;          ///< 0: a free port (the listener's address() tells)
  /// The car's line rate (8N1): what paces the line until the client sets
  /// another; 0 = unpaced whatever the client sets.
  unsigned baud = 0;
  /// Data bytes the client sends this long after connecting are lost, as
  /// on a pty (an Arduino resets when the port opens); 0 = off.
  Duration reset_on_open{0};
  friend bool operator==(const Rfc2217Endpoint&, const Rfc2217Endpoint&) = default;
};

using Endpoint = std::variant<TcpEndpoint, PtyEndpoint, MemEndpoint, Rfc2217Endpoint>;

/// A URI that cannot be used; what() says what was wrong and what was expected.
class EndpointError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Parses a URI. Throws EndpointError.
Endpoint parse_endpoint(std::string_view uri);
/// The URI form again (parse_endpoint(to_uri(e)) == e).
std::string to_uri(const Endpoint& endpoint);

}  // namespace hil::link
