#pragma once
// The fleet load driver's clients, all on one io_context: one LOGI client
// per car, and a ping against a plain echo server on the same loopback (the
// physical baseline the cars' figures are compared with).

#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "protocol/logi/codec.hpp"

namespace hil::bench::fleet {

using Clock = std::chrono::steady_clock;
namespace logi = hil::protocol::logi;

/// The mock's STAT period.
inline constexpr double kStatPeriodMs = 500;

inline double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// What the clients measured inside the window.
struct Measurements {
  std::vector<double> stat_jitter_ms;  ///< |period - 500 ms|
  std::vector<double> feedback_ms;     ///< command written -> its FB read
  std::vector<double> echo_ms;         ///< echo round trip
  std::uint64_t stats = 0;
  std::uint64_t commands = 0;
  std::uint64_t feedback_missing = 0;  ///< a command whose FB had not come by the next one
  std::uint64_t rejected = 0;          ///< FB:...:0
  std::uint64_t bad_frames = 0;
  std::uint64_t connect_failures = 0;
  std::uint64_t disconnects = 0;
};

/// The measured stretch of a run.
struct Window {
  Clock::time_point start;
  Clock::time_point end;
  bool contains(Clock::time_point t) const { return t >= start && t < end; }
};

/// The physical baseline: a plain echo server on its own thread, blocking
/// sockets, one connection.
class EchoServer {
 public:
  EchoServer();
  ~EchoServer();
  unsigned short port() const { return port_; }

 private:
  asio::io_context io_;
  asio::ip::tcp::acceptor acceptor_{io_};
  unsigned short port_ = 0;
  std::thread thread_;
};

/// What every client of the run has: a connection, a timer, and the
/// measurements it adds to while the window is open.
class LoopbackClient {
 public:
  LoopbackClient(asio::io_context& io, Measurements& m, const Window& w)
      : socket_(io), timer_(io), m_(m), window_(w) {}

  /// Cancels the timer and closes the connection.
  void stop() {
    std::error_code ec;
    timer_.cancel();
    socket_.close(ec);
  }

 protected:
  asio::ip::tcp::socket socket_;
  asio::steady_timer timer_;
  Measurements& m_;
  const Window& window_;
};

/// One car's client: MD:MAN at connect, then a command every 1/rate s at
/// its own phase, alternately MV:CW and MV:CCW, so every car spins in place
/// and its control loop runs all the time (the car's dearest state). Parked
/// (--parked), the commands are SP:040 and SP:060 instead: the car stands,
/// and what is left is the protocol, the link and the STAT.
class CarClient : public LoopbackClient, public std::enable_shared_from_this<CarClient> {
 public:
  CarClient(asio::io_context& io, Measurements& m, const Window& w, bool parked)
      : LoopbackClient(io, m, w), parked_(parked) {}

  void start(unsigned port, Clock::time_point first_command, Clock::duration period);

 private:
  void schedule();
  void send(const logi::Message& message, bool counted = false);
  void write();
  void read();
  void on_bytes(std::size_t n);

  char buf_[1024];
  logi::Decoder decoder_;
  std::vector<logi::Item> items_;
  std::deque<std::string> out_;
  Clock::time_point next_command_;
  Clock::duration period_{};
  std::optional<logi::Command> pending_;
  bool pending_counted_ = false;
  Clock::time_point sent_at_;
  std::optional<Clock::time_point> last_stat_;
  bool parked_;
  bool cw_ = false;
};

/// Pings the echo server every 5 ms from the same io_context as the cars'
/// clients, one ping in flight, so both see the same machine.
class EchoClient : public LoopbackClient, public std::enable_shared_from_this<EchoClient> {
 public:
  using LoopbackClient::LoopbackClient;
  void start(unsigned short port);

 private:
  void ping();
  void read(std::size_t have);

  /// As long as a STAT frame, so both paths carry the same bytes per write.
  static constexpr char kPing[] =
      "LOGI:STAT:SP=050,STA=000,RUN=0,MODE=MAN,MAN=CW,DIS=123,TRK=0000,DEV=0:00#";
  char buf_[256];
  Clock::time_point sent_at_;
};

}  // namespace hil::bench::fleet
