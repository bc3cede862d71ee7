#pragma once
// TCP transport for the real-time driver: a listener that accepts many
// connections and a client connect, both giving BytePipes.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <asio/io_context.hpp>

#include "link/byte_pipe.hpp"
#include "link/endpoint.hpp"

namespace hil::link {

/// Accepts TCP connections on one address. Every accepted connection is a
/// BytePipe with TCP_NODELAY set; its handlers run on the io_context thread.
class TcpListener final : public Listener {
 public:
  /// Binds and listens at once (SO_REUSEADDR). An empty host means
  /// 127.0.0.1; port 0 picks a free port (address() reports it). Throws
  /// std::system_error naming the address when the OS refuses.
  TcpListener(asio::io_context& io, const TcpEndpoint& endpoint);
  ~TcpListener() override;

  void start(std::function<void(BytePipePtr)> on_accept) override;
  /// Stops accepting; connections already accepted stay open.
  void close() override;
  std::string address() const override;
  std::uint16_t port() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

/// Resolves the host and connects; the handler runs on the io_context
/// thread with the pipe, or with the error (connection_refused,
/// host_not_found, ...) and a null pipe.
void tcp_connect(asio::io_context& io, const TcpEndpoint& endpoint, ConnectHandler handler);

}  // namespace hil::link
