#pragma once
// The fault-injecting proxy: listens where a client expects its car, and
// joins each client to a new connection to the real car (or a mock) through
// a Link with faults and capture. `hil proxy` is a thin main around it.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "link/endpoint.hpp"
#include "link/faults/profile.hpp"
#include "link/link.hpp"
#include "link/transport.hpp"

namespace hil::link {

struct ProxyOptions {
  Endpoint listen;    ///< where clients connect (tcp:// or pty://)
  Endpoint upstream;  ///< the car: tcp://, pty:// (a device path) or mem://
  std::shared_ptr<const ProtocolAdapter> protocol;  ///< null: raw
  FaultProfile faults;     ///< rules for both directions (each rule's direction filter applies)
  std::uint64_t seed = 0;  ///< link N uses seed + N - 1, so links differ and replay
  /// NDJSON wire log shared by every link (records carry "link": "link<N>"); empty: none.
  std::string wire_log_path;
  /// pcap of the first link; link N > 1 writes "<stem>-<N><ext>"; empty: none.
  std::string pcap_path;
  /// One line per event for the terminal (connections, faults, errors); may be empty.
  std::function<void(const std::string&)> log;
};

class Proxy {
 public:
  /// `context` must outlive the proxy.
  Proxy(TransportContext& context, ProxyOptions options);
  ~Proxy();
  Proxy(const Proxy&) = delete;
  Proxy& operator=(const Proxy&) = delete;

  /// Starts listening. Throws (EndpointError, std::system_error, or
  /// std::runtime_error for a capture file that cannot be opened).
  void start();
  /// Stops listening and closes every link.
  void close();
  /// Where clients connect (the listener's URI, with the real port).
  std::string address() const;

  /// Replaces the fault rules of every open link and of links to come.
  void set_faults(const FaultProfile& faults);

  std::size_t links_opened() const { return links_opened_; }
  std::size_t connections_refused() const { return refused_; }
  std::size_t open_links() const;

 private:
  void on_accept(BytePipePtr client);
  void join(BytePipePtr client, BytePipePtr car, std::size_t number);
  void say(const std::string& line) const;

  TransportContext& context_;
  ProxyOptions options_;
  std::unique_ptr<Listener> listener_;
  std::unique_ptr<FaultInjector> gate_;       // answers refuse_connection()
  std::vector<std::shared_ptr<Link>> links_;  // owned; closed ones are pruned on accept
  std::size_t links_opened_ = 0;
  std::size_t accepted_ = 0;
  std::size_t refused_ = 0;
  bool closed_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::link
