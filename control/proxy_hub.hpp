#pragma once
// Several proxy routes in one process, by name, as the control API and a
// routes file (`hil proxy --config routes.yaml`) see them. Toxiproxy calls
// a route a proxy; each here is a link::Proxy with its protocol, profile,
// listen and upstream endpoints, a hil fault profile and Toxiproxy toxics.
// Used only on the thread that runs the proxies' executor.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "control/api_error.hpp"
#include "control/toxic.hpp"
#include "link/faults/profile.hpp"
#include "link/proxy.hpp"
#include "link/transport.hpp"

namespace hil::control {

/// What a route is declared as, by the API or a routes file.
struct RouteSpec {
  std::string name;
  /// As given: Toxiproxy's "HOST:PORT" (TCP) or a hil URI (tcp://, pty://,
  /// rfc2217://). Empty listen: 127.0.0.1 on a free port.
  std::string listen;
  std::string upstream;          ///< "HOST:PORT", tcp://HOST:PORT or pty:///dev/ttyUSB0
  std::string protocol = "raw";  ///< logi, wr8, arduino, leka, raw
  std::string profile;           ///< the car's profile; empty: the protocol's default
  bool enabled = true;
  link::FaultProfile faults;  ///< hil rules, active from the start
  std::vector<Toxic> toxics;  ///< in the order they were added
};

struct ProxyHubOptions {
  std::uint64_t seed = 0;  ///< route R's links draw from seed + R's own offset (stable by name)
  /// NDJSON wire log shared by every route ("link" reads "<route>/link<N>"); empty: none.
  std::string wire_log_path;
  /// Folder for pcaps, one per link ("<route>-link<N>.pcap"); empty: none.
  std::string pcap_dir;
  std::function<void(const std::string&)> log;  ///< terminal lines; may be empty
};

class ProxyHub {
 public:
  /// One route: its declaration and the proxy that serves it.
  struct Route {
    RouteSpec spec;      ///< current state (toxics and faults as changed since)
    RouteSpec declared;  ///< as first declared; reset() returns to it
    std::unique_ptr<link::Proxy> proxy;
  };

  /// `context` must outlive the hub.
  ProxyHub(link::TransportContext& context, ProxyHubOptions options);
  ~ProxyHub();
  ProxyHub(const ProxyHub&) = delete;
  ProxyHub& operator=(const ProxyHub&) = delete;

  /// Adds a route and starts it (listening unless disabled). Throws
  /// ApiError: 400 for a field that cannot be used (naming it: "upstream:
  /// ..."), 409 for a name taken or a listen address in use.
  const Route& create(RouteSpec spec);
  /// Toxiproxy's populate: routes named alike and declared alike are kept
  /// (with their toxics and links), the others created or replaced. All or
  /// nothing: on an error the hub is as it was. Returns them in body order.
  std::vector<const Route*> populate(std::vector<RouteSpec> specs);
  /// Throws ApiError 404 "proxy not found: NAME".
  const Route& get(const std::string& name) const;
  /// Every route, by name.
  std::vector<const Route*> routes() const;
  /// Changes listen, upstream or enabled (a new listen or upstream restarts
  /// the route, closing its links). Throws as create().
  const Route& update(const std::string& name, std::optional<std::string> listen,
                      std::optional<std::string> upstream, std::optional<bool> enabled);
  /// Closes the route and its links. Throws ApiError 404.
  void remove(const std::string& name);
  /// Toxiproxy's reset: every route enabled, with the faults and toxics it
  /// was declared with (none for routes made through the API).
  void reset();

  /// Adds a toxic (409 when the name is taken on that route).
  const Toxic& add_toxic(const std::string& route, const nlohmann::json& body);
  const Toxic& update_toxic(const std::string& route, const std::string& toxic,
                            const nlohmann::json& body);
  void remove_toxic(const std::string& route, const std::string& toxic);
  const Toxic& get_toxic(const std::string& route, const std::string& toxic) const;

  /// Replaces a route's hil fault profile (its toxics stay).
  void set_faults(const std::string& route, link::FaultProfile faults);
  /// Stalls or resets one link now; ApiError 404 for no such open link.
  void stall_link(const std::string& route, std::size_t link, link::Duration duration,
                  link::DirectionFilter which);
  void reset_link(const std::string& route, std::size_t link);

  link::Time now() const;
  /// Closes every route.
  void close();

 private:
  struct Prepared;
  /// Checks a declaration: ApiError 400 naming the field.
  static Prepared prepare(RouteSpec spec);
  friend void check_route_spec(const RouteSpec& spec);
  /// The route and its proxy, not started yet.
  std::unique_ptr<Route> build(const Prepared& prepared) const;
  /// Throws ApiError 409 when the address to listen on again is taken.
  void set_enabled(Route& route, bool enabled);
  /// The same, logging a failure instead (undoing a change that failed).
  void set_enabled_quietly(Route& route, bool enabled);
  Route& find(const std::string& name);
  link::TransportContext& context_;
  ProxyHubOptions options_;
  std::map<std::string, std::unique_ptr<Route>> routes_;
};

/// The route as Toxiproxy shows a proxy: {name, listen, upstream, enabled,
/// toxics}, plus hil's {protocol, profile}. listen is the address clients
/// connect to ("127.0.0.1:PORT" for TCP, the URI otherwise).
nlohmann::json to_json(const ProxyHub::Route& route);

/// Throws ApiError 400 naming the field when a declaration cannot be made
/// into a route (an endpoint, the protocol, the profile, a fault rule); the
/// routes file loader checks each route with it. A listen address in use
/// shows only when the route starts.
void check_route_spec(const RouteSpec& spec);

/// A RouteSpec from a request body (POST /proxies, /populate entries) or a
/// routes file entry in JSON form. Throws ApiError 400 naming the field.
RouteSpec parse_route_spec(const nlohmann::json& body);

}  // namespace hil::control
