#pragma once
// One end of a bidirectional byte stream: a TCP connection, a pty, or an
// in-memory pipe. Everything above the transports talks to this interface.

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include "protocol/common/bytes.hpp"

namespace hil::link {

using protocol::Bytes;
using protocol::ByteView;

/// The send backlog hil's mock cars and proxy allow each peer (bytes
/// written but not yet taken by the operating system): see
/// BytePipe::set_send_limit. Every frame of every protocol is under 300
/// bytes, so a peer that reads at all never comes near it.
inline constexpr std::size_t kMaxSendBacklogBytes = std::size_t{1} << 20;

enum class CloseMode : std::uint8_t {
  graceful,  ///< flush what is queued, then close (TCP: FIN)
  reset,     ///< drop what is queued and abort (TCP: RST)
};

class BytePipe {
 public:
  struct Handlers {
    Handlers() = default;
    /// Most users take bytes and the close only: `{on_data, on_close}`.
    Handlers(std::function<void(ByteView)> data, std::function<void(std::error_code)> close = {},
             std::function<void()> end = {})
        : on_data(std::move(data)), on_close(std::move(close)), on_end(std::move(end)) {}

    /// Bytes from the peer, in order, in whatever pieces they arrived.
    std::function<void(ByteView)> on_data;
    /// The stream ended: peer closed (error_code is eof or a reset), or
    /// close() was called here (operation_aborted). Called once.
    std::function<void(std::error_code)> on_close;
    /// The peer finished sending (TCP FIN) and may still read: this end
    /// stays open for writing until shutdown_send() or close(). Called at
    /// most once, and only when set and the transport can half-close (TCP,
    /// mem pipes); otherwise the peer's end is on_close(eof) as usual.
    /// Once the peer has ended and shutdown_send() was called here, the
    /// pipe closes itself: on_close(eof), after on_end.
    std::function<void()> on_end;
  };

  virtual ~BytePipe() = default;

  /// Starts delivering. Handlers run on the pipe's executor, never inside
  /// write() or start() themselves.
  virtual void start(Handlers handlers) = 0;
  /// Queues bytes for the peer; never blocks. Ignored once closed.
  virtual void write(ByteView bytes) = 0;
  virtual void close(CloseMode mode = CloseMode::graceful) = 0;
  /// Half-close: sends the end of the stream after what is queued (TCP:
  /// FIN once the queue is flushed) and keeps reading; later writes are
  /// ignored. Transports that cannot half-close (a pty, RFC 2217), and mem
  /// pipes whose peer does not take on_end, close(graceful) instead:
  /// is_open() is false at once when that happened.
  virtual void shutdown_send() { close(CloseMode::graceful); }
  virtual bool is_open() const = 0;
  /// Caps the send backlog at `bytes` (0: no cap, the default): a write
  /// that would queue more aborts the pipe and on_close gets
  /// std::errc::no_buffer_space, so a peer that never reads costs at most
  /// this much memory. In-memory pipes have no backlog and ignore it.
  virtual void set_send_limit(std::size_t /*bytes*/) {}
  /// Bytes written but not yet handed to the operating system / the peer.
  virtual std::size_t queued_bytes() const = 0;
  /// Flow control for a relay (a link between two pipes): pause_reading()
  /// stops taking bytes from the peer, so the operating system's buffers
  /// fill and the peer's sends slow down as they would on a direct
  /// connection, until resume_reading(). While paused the end of the
  /// stream is seen only once reading resumes. Pipes that take nothing
  /// from an operating system (in-memory ones) ignore both.
  virtual void pause_reading() {}
  virtual void resume_reading() {}
  /// Calls `callback` once, on the pipe's executor, when queued_bytes()
  /// has fallen to `bytes` or below; a later call replaces a waiting one,
  /// and a closed pipe never calls it. Pipes without a backlog of their
  /// own call it at once.
  virtual void when_drained_to(std::size_t /*bytes*/, std::function<void()> callback) {
    if (callback) callback();
  }
  /// For logs: "tcp 127.0.0.1:9000 <- 127.0.0.1:53422", "mem car0", ...
  virtual std::string describe() const = 0;
};

using BytePipePtr = std::shared_ptr<BytePipe>;

/// What a pipe with a backlog of its own keeps for when_drained_to(): the
/// level, and whom to tell once the backlog is down to it.
class DrainWatch {
 public:
  /// Keeps `callback` for `level`, replacing a waiting one; when the
  /// backlog, `queued`, is that low already, hands it to `post` instead.
  template <class Post>
  void watch(std::size_t level, std::size_t queued, std::function<void()> callback, Post post) {
    if (queued <= level) {
      post(std::move(callback));
      return;
    }
    level_ = level;
    callback_ = std::move(callback);
  }
  /// The backlog is `queued` now: a waiting callback runs, once, at its level.
  void update(std::size_t queued) {
    if (callback_ && queued <= level_) std::exchange(callback_, nullptr)();
  }
  /// The pipe is closed: a waiting callback never runs.
  void cancel() { callback_ = nullptr; }

 private:
  std::size_t level_ = 0;
  std::function<void()> callback_;
};

/// Accepts connections on an endpoint (a TCP port, a pty path, a mem name).
class Listener {
 public:
  virtual ~Listener() = default;
  virtual void start(std::function<void(BytePipePtr)> on_accept) = 0;
  virtual void close() = 0;
  /// What a peer connects to, as a URI: "tcp://127.0.0.1:9000".
  virtual std::string address() const = 0;
};

using ConnectHandler = std::function<void(std::error_code, BytePipePtr)>;

/// The code on_close receives when the peer closed its end normally: Asio's
/// eof, for every transport (mem pipes included), so callers test one value.
std::error_code end_of_stream();

/// The code on_close receives when close() was called on this end.
std::error_code closed_here();

/// Asio reports OS errors in its own category, which std::errc conditions do
/// not match; transports pass them through this so that
/// `ec == std::errc::connection_reset` works for every transport.
std::error_code portable_error(std::error_code ec);

}  // namespace hil::link
