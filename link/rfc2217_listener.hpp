#pragma once
// A serial car behind an RFC 2217 server: each connection to an inner
// listener (TCP under the real-time driver, mem:// in tests) speaks
// Telnet/COM-PORT-OPTION, and the car gets a BytePipe that carries only the
// data bytes, paced at the rate and framing the client set, with the
// "reset on open" quirk of a pty. One client at a time, as on a serial port.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "link/byte_pipe.hpp"
#include "link/executor.hpp"
#include "link/rfc2217.hpp"

namespace hil::link {

struct Rfc2217Options {
  /// The car's line (8N1); it paces both directions until the client sets
  /// another rate or framing. 0: unpaced, whatever the client sets.
  unsigned baud = 0;
  /// Data bytes the client sends this long after connecting are lost.
  Duration reset_on_open{0};
  /// Told what the client cannot see: refused connections, bad input,
  /// a line set unlike the car's, bytes lost to reset_on_open. Null: silent.
  std::function<void(const std::string&)> log;
  /// The answer to a client asking for the server's SIGNATURE.
  std::string signature = "hil";
};

/// Accepts connections on `inner` and serves RFC 2217 on each. A connection
/// while a session is open is closed at once (and logged): the port is in
/// use, as a serial port opened by another program is. A new connection
/// is a new session: the car sees it as the port opening (its reset).
class Rfc2217Listener final : public Listener {
 public:
  Rfc2217Listener(Executor& executor, std::unique_ptr<Listener> inner, Rfc2217Options options);
  ~Rfc2217Listener() override;

  void start(std::function<void(BytePipePtr)> on_accept) override;
  /// Stops accepting; an open session stays open until its owner closes it.
  void close() override;
  /// rfc2217://HOST:PORT?baud=N&reset_ms=N (the real port), or the inner
  /// listener's address when it is not TCP.
  std::string address() const override;

  /// Data bytes lost inside a reset_on_open window, over all sessions.
  std::uint64_t bytes_lost_to_reset() const;
  /// Connections closed because a session was open.
  std::uint64_t connections_refused() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace hil::link
