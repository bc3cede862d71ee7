#pragma once
// The HTTP side of the control API: cpp-httplib on threads of its own,
// each request handed to the proxies' io_context and answered from there,
// with a cap on request size and on request rate.

#include <asio/io_context.hpp>

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "control/proxy_api.hpp"
#include "control/proxy_hub.hpp"

namespace hil::control {

/// Requests per second the API answers, with bursts of kApiBurst; more get 429.
inline constexpr int kApiRequestsPerSecond = 200;
inline constexpr int kApiBurst = 100;
/// Connections the API serves at once.
inline constexpr int kApiThreads = 32;

struct ApiServerOptions {
  std::string host = "127.0.0.1";  ///< loopback by default: the API has no login
  std::uint16_t port = 8474;       ///< Toxiproxy's port; 0: any free port
  ApiInfo info;                    ///< what GET /version tells
  int requests_per_second = kApiRequestsPerSecond;
  int burst = kApiBurst;
};

/// A token bucket: `burst` requests at once, then `per_second` a second.
/// The caller gives the time, so it can be tested in virtual time.
class RequestRateLimit {
 public:
  RequestRateLimit(int per_second, int burst);
  /// Whether a request arriving at `now` (any monotonic origin) is
  /// answered; takes a token when it is.
  bool allow(std::chrono::nanoseconds now);

 private:
  double per_second_;
  double burst_;
  double tokens_;
  std::optional<std::chrono::nanoseconds> last_;
};

/// Whether `host` is a loopback address (127.0.0.0/8, ::1, localhost);
/// hil proxy warns when the API listens anywhere else.
bool is_loopback_host(const std::string& host);

class ApiServer {
 public:
  /// `hub` is touched only on `io`'s thread. Both must outlive the server.
  ApiServer(asio::io_context& io, ProxyHub& hub, ApiServerOptions options);
  ~ApiServer();
  ApiServer(const ApiServer&) = delete;
  ApiServer& operator=(const ApiServer&) = delete;

  /// Binds and serves. Throws std::runtime_error naming the address when it
  /// cannot bind.
  void start();
  /// Stops serving and waits for the HTTP threads.
  void stop();
  std::uint16_t port() const;
  std::string url() const;  ///< "http://127.0.0.1:8474"

 private:
  struct State;
  asio::io_context& io_;
  ProxyHub& hub_;
  ApiServerOptions options_;
  std::shared_ptr<State> state_;
};

}  // namespace hil::control
