#include "link/transport.hpp"

#include "link/pty.hpp"
#include "link/rfc2217_listener.hpp"
#include "link/tcp.hpp"
#include "protocol/common/overloaded.hpp"

namespace hil::link {
namespace {

asio::io_context& real_time_io(const TransportContext& context, const char* scheme) {
  if (context.io == nullptr) {
    throw EndpointError(
        std::string(scheme) +
        ":// needs the real-time driver (TransportContext::io is not set); use mem:// "
        "under the virtual-time driver");
  }
  return *context.io;
}

MemNetwork& mem_network(TransportContext& context) {
  if (context.mem == nullptr) {
    context.owned_mem = std::make_shared<MemNetwork>(context.executor);
    context.mem = context.owned_mem.get();
  }
  return *context.mem;
}

}  // namespace

std::unique_ptr<Listener> listen(TransportContext& context, const Endpoint& endpoint) {
  return std::visit(
      protocol::Overloaded{[&](const TcpEndpoint& e) -> std::unique_ptr<Listener> {
                             return std::make_unique<TcpListener>(real_time_io(context, "tcp"), e);
                           },
                           [&](const PtyEndpoint& e) -> std::unique_ptr<Listener> {
                             return std::make_unique<PtyListener>(real_time_io(context, "pty"),
                                                                  context.executor, e);
                           },
                           [&](const MemEndpoint& e) -> std::unique_ptr<Listener> {
                             return mem_network(context).listen(e.name, e.baud);
                           },
                           [&](const Rfc2217Endpoint& e) -> std::unique_ptr<Listener> {
                             auto tcp = std::make_unique<TcpListener>(
                                 real_time_io(context, "rfc2217"), TcpEndpoint{e.host, e.port});
                             return std::make_unique<Rfc2217Listener>(
                                 context.executor, std::move(tcp),
                                 Rfc2217Options{e.baud, e.reset_on_open, context.log});
                           }},
      endpoint);
}

void connect(TransportContext& context, const Endpoint& endpoint, ConnectHandler handler) {
  std::visit(
      protocol::Overloaded{
          [&](const TcpEndpoint& e) {
            tcp_connect(real_time_io(context, "tcp"), e, std::move(handler));
          },
          [&](const PtyEndpoint& e) {
            pty_connect(real_time_io(context, "pty"), context.executor, e, std::move(handler));
          },
          [&](const MemEndpoint& e) { mem_network(context).connect(e.name, std::move(handler)); },
          [&](const Rfc2217Endpoint&) {
            // hil serves RFC 2217 but has no client for it.
            context.executor.post([handler = std::move(handler)] {
              handler(std::make_error_code(std::errc::protocol_not_supported), nullptr);
            });
          }},
      endpoint);
}

}  // namespace hil::link
