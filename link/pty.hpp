#pragma once
// Pseudo-terminal transport for the real-time driver: hil plays the serial
// device behind a pty whose slave side a client opens through a stable
// symlink (e.g. /tmp/hil-arduino0), with serial pacing and the Arduino
// "reset on open" quirk.

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>

#include <asio/io_context.hpp>

#include "link/byte_pipe.hpp"
#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/serial_pacer.hpp"

namespace hil::link {

/// Serial behaviour of a pty, from the endpoint's options.
struct PtyOptions {
  unsigned baud = 0;                       ///< 0: bytes pass as fast as the pty takes them
  Duration reset_on_open{0};               ///< client bytes within this long after open are lost
  Duration poll_period{milliseconds(10)};  ///< how often the slave's open/close is checked
  /// Told about what the client cannot see (bytes lost to reset_on_open);
  /// null means silent.
  std::function<void(const std::string&)> log;
};

/// The device side of a pty. "Listening" creates the pty, puts it in raw
/// mode and points the symlink at its slave; each time a client opens the
/// slave, on_accept gets a BytePipe for that session, and the pipe closes
/// with eof when the client closes the port. One session at a time.
///
/// Linux tells the master nothing when the slave is opened: the master sees
/// POLLHUP while no process holds the slave open, so the listener polls
/// every poll_period. A client's open is noticed up to one poll_period late
/// (its bytes wait in the pty meanwhile; the reset_on_open window counts
/// from the moment the open is noticed); a close is noticed at once while
/// a session reads.
class PtyListener final : public Listener {
 public:
  /// Creates the pty and the symlink at once. Throws std::system_error
  /// naming the path when the pty cannot be made or the path is taken by
  /// something other than a symlink.
  PtyListener(asio::io_context& io, Executor& executor, const std::string& path,
              PtyOptions options = {});
  PtyListener(asio::io_context& io, Executor& executor, const PtyEndpoint& endpoint);
  ~PtyListener() override;

  void start(std::function<void(BytePipePtr)> on_accept) override;
  /// Ends the session (the client sees a hang-up), closes the pty and
  /// removes the symlink.
  void close() override;
  std::string address() const override;

  /// The pty's slave device, e.g. /dev/pts/3.
  std::string slave_path() const;
  /// Bytes the client wrote inside a reset_on_open window, over all sessions.
  std::uint64_t bytes_lost_to_reset() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

/// Opens a serial port or pty slave as a client would (O_NOCTTY, raw mode,
/// the endpoint's baud set on the line when it is a standard rate). No
/// software pacing on this side: a real port is paced by its hardware and
/// a hil pty by the listener. The handler runs as a task on `executor`.
void pty_connect(asio::io_context& io, Executor& executor, const PtyEndpoint& endpoint,
                 ConnectHandler handler);

}  // namespace hil::link
