#include "link/transport.hpp"

#include "link/pty.hpp"
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
  return std::visit(protocol::Overloaded{[&](const TcpEndpoint& e) -> std::unique_ptr<Listener> {
                                           return std::make_unique<TcpListener>(
                                               real_time_io(context, "tcp"), e);
                                         },
                                         [&](const PtyEndpoint& e) -> std::unique_ptr<Listener> {
                                           return std::make_unique<PtyListener>(
                                               real_time_io(context, "pty"), context.executor, e);
                                         },
                                         [&](const MemEndpoint& e) -> std::unique_ptr<Listener> {
                                           return mem_network(context).listen(e.name, e.baud);
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
          [&](const MemEndpoint& e) { mem_network(context).connect(e.name, std::move(handler)); }},
      endpoint);
}

}  // namespace hil::link
