#pragma once
// The live view's web server: serves the page, streams snapshots of the
// cars as server-sent events, runs the panel's API on the cars' own thread,
// and serves the cars' counters to a Prometheus scraper (GET /metrics).
// HTTP runs on threads of its own; the cars are touched only from the
// io_context that runs them.

#include <cstdint>
#include <memory>
#include <string>

#include <asio/io_context.hpp>

#include "link/executor.hpp"
#include "view/live_model.hpp"

namespace hil::view {

struct ViewOptions {
  std::string host = "127.0.0.1";  ///< loopback only: the panel has no login
  std::uint16_t port = 8080;       ///< 0: any free port
  int updates_per_s = 20;          ///< snapshot refresh and event rate
};

class LiveViewServer {
 public:
  /// `model` is used only on `io`'s thread; `executor` schedules on `io`.
  /// Both must outlive the server.
  LiveViewServer(asio::io_context& io, link::Executor& executor, LiveModel& model,
                 ViewOptions options);
  ~LiveViewServer();
  LiveViewServer(const LiveViewServer&) = delete;
  LiveViewServer& operator=(const LiveViewServer&) = delete;

  /// Binds and starts serving; call on the io thread or before it runs.
  /// Throws std::runtime_error when the port cannot be bound.
  void start();
  /// Stops serving and ends every event stream; waits for the HTTP threads.
  void stop();
  /// The bound port (after start()).
  std::uint16_t port() const { return port_; }
  std::string url() const;

 private:
  struct Shared;
  void refresh();

  asio::io_context& io_;
  link::Executor& executor_;
  LiveModel& model_;
  ViewOptions options_;
  std::shared_ptr<Shared> shared_;
  std::uint16_t port_ = 0;
  link::Executor::TimerId timer_ = 0;
  bool running_ = false;
};

}  // namespace hil::view
