#pragma once
// Opens listeners and connections for any endpoint URI under either driver.

#include <functional>
#include <memory>
#include <string>

#include "link/byte_pipe.hpp"
#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/mem_pipe.hpp"

namespace asio {
class io_context;
}

namespace hil::link {

/// What transports need from the driver that runs them.
struct TransportContext {
  Executor& executor;
  /// Present under the real-time driver only; tcp:// and pty:// need it.
  asio::io_context* io = nullptr;
  /// mem:// endpoints; made on first use when null.
  MemNetwork* mem = nullptr;
  /// Owns the MemNetwork made on first use (copies of the context share it).
  std::shared_ptr<MemNetwork> owned_mem = nullptr;
  /// Where listeners tell what their clients cannot see (an rfc2217://
  /// listener's refused connections and bad input); null: silent.
  std::function<void(const std::string&)> log = nullptr;
};

/// Listens on an endpoint. Throws EndpointError when the endpoint cannot be
/// used (tcp://, pty:// or rfc2217:// without the real-time driver) and
/// std::system_error when the operating system refuses (port in use, path
/// not writable).
std::unique_ptr<Listener> listen(TransportContext& context, const Endpoint& endpoint);

/// Connects to an endpoint; the handler runs on the executor. rfc2217://
/// is listen-only: the handler gets std::errc::protocol_not_supported.
void connect(TransportContext& context, const Endpoint& endpoint, ConnectHandler handler);

}  // namespace hil::link
