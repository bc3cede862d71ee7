#include "control/proxy_hub.hpp"

#include <algorithm>
#include <cctype>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "protocol/common/car_profile.hpp"

namespace hil::control {
namespace {

/// A route's own offset of the hub's seed: FNV-1a of its name, so a route
/// draws the same faults whichever routes stand beside it.
std::uint64_t seed_offset(const std::string& name) {
  std::uint64_t hash = 14695981039346656037ULL;
  for (const char c : name) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  return hash;
}

bool valid_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_' || c == '.' || c == '-';
  });
}

/// Toxiproxy's "HOST:PORT" as a hil URI; a hil URI as it is; "" a free port
/// on this machine only.
std::string as_uri(const std::string& address) {
  if (address.empty()) return "tcp://127.0.0.1:0";
  if (address.find("://") != std::string::npos) return address;
  return "tcp://" + address;
}

link::Endpoint endpoint_of(const std::string& field, const std::string& address) {
  try {
    return link::parse_endpoint(as_uri(address));
  } catch (const link::EndpointError& e) {
    throw ApiError(400, field + ": " + e.what());
  }
}

/// Whether two listen endpoints name one address, so one must stop
/// listening before the other can start (a port 0 never clashes).
bool same_address(const link::Endpoint& a, const link::Endpoint& b) {
  if (a.index() != b.index()) return false;
  if (const auto* x = std::get_if<link::TcpEndpoint>(&a)) {
    const auto& y = std::get<link::TcpEndpoint>(b);
    return x->port != 0 && x->port == y.port;
  }
  if (const auto* x = std::get_if<link::Rfc2217Endpoint>(&a)) {
    const auto& y = std::get<link::Rfc2217Endpoint>(b);
    return x->port != 0 && x->port == y.port;
  }
  if (const auto* x = std::get_if<link::PtyEndpoint>(&a))
    return x->path == std::get<link::PtyEndpoint>(b).path;
  return std::get<link::MemEndpoint>(a).name == std::get<link::MemEndpoint>(b).name;
}

/// Toxics alike but for when they were added.
bool same_toxics(const std::vector<Toxic>& a, const std::vector<Toxic>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](Toxic x, const Toxic& y) {
    x.added_at = y.added_at;
    return x == y;
  });
}

/// What makes a route the route it is: populate keeps a route declared so again.
bool declared_alike(const RouteSpec& a, const RouteSpec& b) {
  return a.name == b.name && as_uri(a.listen) == as_uri(b.listen) &&
         as_uri(a.upstream) == as_uri(b.upstream) && a.protocol == b.protocol &&
         a.profile == b.profile && a.faults == b.faults && same_toxics(a.toxics, b.toxics);
}

/// Starts a route's proxy, or leaves it disabled; what the system refuses
/// becomes an ApiError naming the listen address.
void start_proxy(link::Proxy& proxy, const RouteSpec& spec) {
  const std::string listen = spec.listen.empty() ? as_uri(spec.listen) : spec.listen;
  try {
    if (spec.enabled) {
      proxy.start();
    } else {
      proxy.set_enabled(false);
    }
  } catch (const std::system_error& e) {
    if (e.code() == std::errc::address_in_use)
      throw ApiError(409, "listen: " + listen + " is in use");
    throw ApiError(400, "listen: " + std::string(e.what()));
  } catch (const link::EndpointError& e) {
    const std::string what = e.what();
    if (what.find("already listened on") != std::string::npos)
      throw ApiError(409, "listen: " + listen + " is in use");
    throw ApiError(400, "listen: " + what);
  }
}

}  // namespace

/// A route checked and ready to be made: its endpoints and protocol.
struct ProxyHub::Prepared {
  RouteSpec spec;
  link::Endpoint listen;
  link::Endpoint upstream;
  std::shared_ptr<const link::ProtocolAdapter> protocol;
};

ProxyHub::ProxyHub(link::TransportContext& context, ProxyHubOptions options)
    : context_(context), options_(std::move(options)) {}

ProxyHub::~ProxyHub() {
  close();
}

link::Time ProxyHub::now() const {
  return context_.executor.now();
}

ProxyHub::Prepared ProxyHub::prepare(RouteSpec spec) {
  if (!valid_name(spec.name)) {
    throw ApiError(400, "name: '" + spec.name +
                            "' is not a route name (expected letters, digits, '_', '.' or '-')");
  }
  if (spec.upstream.empty())
    throw ApiError(400, "upstream: missing (expected HOST:PORT or a URI such as tcp://HOST:PORT)");
  Prepared p;
  p.listen = endpoint_of("listen", spec.listen);
  p.upstream = endpoint_of("upstream", spec.upstream);
  if (std::holds_alternative<link::Rfc2217Endpoint>(p.upstream)) {
    throw ApiError(400, "upstream: " + spec.upstream +
                            ": hil serves RFC 2217 (listen rfc2217://...) but cannot connect to an "
                            "RFC 2217 server (expected the car's serial port, pty:///dev/ttyUSB0, "
                            "or HOST:PORT)");
  }
  if (spec.protocol.empty()) spec.protocol = "raw";
  try {
    link::protocol_adapter(spec.protocol);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, std::string("protocol: ") + e.what());
  }
  try {
    p.protocol = link::protocol_adapter(spec.protocol, spec.profile);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, std::string("profile: ") + e.what());
  }
  try {
    link::validate(spec.faults);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, std::string("faults: ") + e.what());
  }
  p.spec = std::move(spec);
  return p;
}

void check_route_spec(const RouteSpec& spec) {
  ProxyHub::prepare(spec);
}

std::unique_ptr<ProxyHub::Route> ProxyHub::build(const Prepared& prepared) const {
  auto route = std::make_unique<Route>();
  route->spec = prepared.spec;
  route->declared = prepared.spec;
  const Route* self = route.get();
  link::ProxyOptions o;
  o.name = prepared.spec.name;
  o.listen = prepared.listen;
  o.upstream = prepared.upstream;
  o.protocol = prepared.protocol;
  o.faults = prepared.spec.faults;
  // The route's toxics, each drawn once per link by its toxicity.
  o.link_faults = [self](const link::ProxyLinkInfo& info) {
    link::FaultProfile rules;
    for (const auto& toxic : self->spec.toxics) {
      if (!acts_on_link(toxic, info.seed)) continue;
      auto more = toxic_rules(toxic, info.opened_at);
      rules.rules.insert(rules.rules.end(), std::make_move_iterator(more.rules.begin()),
                         std::make_move_iterator(more.rules.end()));
    }
    return rules;
  };
  o.seed = options_.seed + seed_offset(prepared.spec.name);
  o.wire_log_path = options_.wire_log_path;
  o.pcap_dir = options_.pcap_dir;
  o.link_id_prefix = prepared.spec.name + "/";
  o.log = options_.log;
  route->proxy = std::make_unique<link::Proxy>(context_, std::move(o));
  return route;
}

const ProxyHub::Route& ProxyHub::create(RouteSpec spec) {
  if (routes_.count(spec.name) != 0)
    throw ApiError(409, "name: a proxy named " + spec.name + " already exists");
  const Prepared prepared = prepare(std::move(spec));
  auto route = build(prepared);
  start_proxy(*route->proxy, route->spec);
  auto& placed = routes_[prepared.spec.name];
  placed = std::move(route);
  return *placed;
}

std::vector<const ProxyHub::Route*> ProxyHub::populate(std::vector<RouteSpec> specs) {
  // Every declaration is checked before any route is touched.
  std::vector<Prepared> prepared;
  std::set<std::string> names;
  for (auto& spec : specs) {
    if (!names.insert(spec.name).second)
      throw ApiError(400, "name: " + spec.name + " is given twice");
    prepared.push_back(prepare(std::move(spec)));
  }
  std::vector<std::unique_ptr<Route>> made(prepared.size());
  std::vector<Route*> paused;                          // old routes stopped to free their address
  std::vector<std::pair<Route*, bool>> kept_switched;  // kept routes whose enabled flag changed
  try {
    for (std::size_t i = 0; i < prepared.size(); ++i) {
      auto& p = prepared[i];
      const auto old = routes_.find(p.spec.name);
      Route* existing = old == routes_.end() ? nullptr : old->second.get();
      if (existing != nullptr && declared_alike(existing->declared, p.spec)) {
        if (existing->spec.enabled != p.spec.enabled) {
          kept_switched.emplace_back(existing, existing->spec.enabled);
          set_enabled(*existing, p.spec.enabled);
        }
        continue;
      }
      if (existing != nullptr) {
        // Declared on the same address as before: it listens where it did.
        if (as_uri(existing->spec.listen) == as_uri(p.spec.listen))
          p.listen = existing->proxy->listening_on();
        if (existing->proxy->enabled() && p.spec.enabled &&
            (same_address(existing->proxy->listening_on(), p.listen) ||
             same_address(existing->proxy->options().listen, p.listen))) {
          existing->proxy->set_enabled(false);
          paused.push_back(existing);
        }
      }
      auto route = build(p);
      start_proxy(*route->proxy, route->spec);
      made[i] = std::move(route);
    }
  } catch (...) {
    made.clear();
    for (Route* route : paused)
      set_enabled_quietly(*route, true);
    for (auto& [route, was] : kept_switched)
      set_enabled_quietly(*route, was);
    throw;
  }
  std::vector<const Route*> result;
  for (std::size_t i = 0; i < prepared.size(); ++i) {
    auto& slot = routes_[prepared[i].spec.name];
    if (made[i]) slot = std::move(made[i]);
    result.push_back(slot.get());
  }
  return result;
}

const ProxyHub::Route& ProxyHub::get(const std::string& name) const {
  const auto it = routes_.find(name);
  if (it == routes_.end()) throw ApiError(404, "proxy not found: " + name);
  return *it->second;
}

ProxyHub::Route& ProxyHub::find(const std::string& name) {
  return const_cast<Route&>(std::as_const(*this).get(name));
}

std::vector<const ProxyHub::Route*> ProxyHub::routes() const {
  std::vector<const Route*> all;
  for (const auto& [name, route] : routes_)
    all.push_back(route.get());
  return all;
}

void ProxyHub::set_enabled(Route& route, bool enabled) {
  try {
    route.proxy->set_enabled(enabled);
  } catch (const std::system_error& e) {
    if (e.code() == std::errc::address_in_use) {
      throw ApiError(409, "listen: " + link::to_uri(route.proxy->listening_on()) + " is in use");
    }
    throw ApiError(400, "listen: " + std::string(e.what()));
  } catch (const link::EndpointError& e) {
    throw ApiError(409, "listen: " + std::string(e.what()));
  }
  route.spec.enabled = enabled;
}

void ProxyHub::set_enabled_quietly(Route& route, bool enabled) {
  try {
    set_enabled(route, enabled);
  } catch (const ApiError& e) {
    if (options_.log) options_.log(route.spec.name + ": " + e.what());
  }
}

const ProxyHub::Route& ProxyHub::update(const std::string& name, std::optional<std::string> listen,
                                        std::optional<std::string> upstream,
                                        std::optional<bool> enabled) {
  Route& route = find(name);
  RouteSpec spec = route.spec;
  if (listen) spec.listen = *listen;
  if (upstream) spec.upstream = *upstream;
  if (enabled) spec.enabled = *enabled;
  const bool moved = as_uri(spec.listen) != as_uri(route.spec.listen) ||
                     as_uri(spec.upstream) != as_uri(route.spec.upstream);
  if (!moved) {
    if (enabled) set_enabled(route, *enabled);
    return route;
  }
  Prepared prepared = prepare(spec);
  if (as_uri(spec.listen) == as_uri(route.spec.listen))
    prepared.listen = route.proxy->listening_on();
  const bool was_enabled = route.proxy->enabled();
  if (was_enabled && (same_address(route.proxy->listening_on(), prepared.listen) ||
                      same_address(route.proxy->options().listen, prepared.listen))) {
    route.proxy->set_enabled(false);
  }
  std::unique_ptr<Route> fresh;
  try {
    fresh = build(prepared);
    start_proxy(*fresh->proxy, fresh->spec);
  } catch (...) {
    fresh.reset();
    if (was_enabled) set_enabled_quietly(route, true);
    throw;
  }
  // The new proxy replaces the old; the route keeps its declaration and toxics.
  fresh->declared = route.declared;
  fresh->declared.listen = spec.listen;
  fresh->declared.upstream = spec.upstream;
  auto& slot = routes_[name];
  slot = std::move(fresh);
  return *slot;
}

void ProxyHub::remove(const std::string& name) {
  find(name);
  auto node = routes_.extract(name);
  node.mapped()->proxy->close();
}

void ProxyHub::reset() {
  std::optional<ApiError> first_error;
  for (auto& [name, route] : routes_) {
    route->spec.faults = route->declared.faults;
    route->spec.toxics = route->declared.toxics;
    // The declared toxics start again now, as if just added.
    for (auto& toxic : route->spec.toxics)
      toxic.added_at = now();
    route->proxy->set_faults(route->spec.faults);
    try {
      set_enabled(*route, true);
    } catch (const ApiError& e) {
      if (!first_error) first_error = e;
    }
  }
  if (first_error) throw *first_error;
}

const Toxic& ProxyHub::add_toxic(const std::string& route_name, const nlohmann::json& body) {
  Route& route = find(route_name);
  Toxic toxic = parse_toxic(body, now());
  for (const auto& t : route.spec.toxics) {
    if (t.name == toxic.name) throw ApiError(409, "name: toxic already exists: " + toxic.name);
  }
  route.spec.toxics.push_back(std::move(toxic));
  route.proxy->refresh_faults();
  return route.spec.toxics.back();
}

const Toxic& ProxyHub::update_toxic(const std::string& route_name, const std::string& toxic_name,
                                    const nlohmann::json& body) {
  Route& route = find(route_name);
  auto& toxics = route.spec.toxics;
  const auto it = std::find_if(toxics.begin(), toxics.end(),
                               [&](const Toxic& t) { return t.name == toxic_name; });
  if (it == toxics.end()) throw ApiError(404, "toxic not found: " + toxic_name);
  Toxic updated = parse_toxic(body, now(), &*it);
  updated.name = it->name;  // the path names it
  *it = std::move(updated);
  route.proxy->refresh_faults();
  return *it;
}

void ProxyHub::remove_toxic(const std::string& route_name, const std::string& toxic_name) {
  Route& route = find(route_name);
  const auto removed =
      std::erase_if(route.spec.toxics, [&](const Toxic& t) { return t.name == toxic_name; });
  if (removed == 0) throw ApiError(404, "toxic not found: " + toxic_name);
  route.proxy->refresh_faults();
}

const Toxic& ProxyHub::get_toxic(const std::string& route_name,
                                 const std::string& toxic_name) const {
  const Route& route = get(route_name);
  for (const auto& t : route.spec.toxics) {
    if (t.name == toxic_name) return t;
  }
  throw ApiError(404, "toxic not found: " + toxic_name);
}

void ProxyHub::set_faults(const std::string& route_name, link::FaultProfile faults) {
  Route& route = find(route_name);
  try {
    link::validate(faults);
  } catch (const std::invalid_argument& e) {
    throw ApiError(400, std::string("rules: ") + e.what());
  }
  route.spec.faults = std::move(faults);
  route.proxy->set_faults(route.spec.faults);
}

void ProxyHub::stall_link(const std::string& route_name, std::size_t link, link::Duration duration,
                          link::DirectionFilter which) {
  Route& route = find(route_name);
  if (!route.proxy->stall_link(link, duration, which)) {
    throw ApiError(404, "link: proxy " + route_name + " has no open link " + std::to_string(link));
  }
}

void ProxyHub::reset_link(const std::string& route_name, std::size_t link) {
  Route& route = find(route_name);
  if (!route.proxy->reset_link(link)) {
    throw ApiError(404, "link: proxy " + route_name + " has no open link " + std::to_string(link));
  }
}

void ProxyHub::close() {
  for (auto& [name, route] : routes_)
    route->proxy->close();
}

nlohmann::json to_json(const ProxyHub::Route& route) {
  std::string listen = route.proxy->address();
  if (listen.rfind("tcp://", 0) == 0) listen = listen.substr(6);
  nlohmann::json toxics = nlohmann::json::array();
  for (const auto& toxic : route.spec.toxics)
    toxics.push_back(to_json(toxic));
  return {{"name", route.spec.name},
          {"listen", listen},
          {"upstream", route.spec.upstream},
          {"enabled", route.spec.enabled},
          {"toxics", std::move(toxics)},
          {"protocol", route.spec.protocol},
          {"profile", std::string(route.proxy->options().protocol->profile())}};
}

namespace {

/// body[key] as a string, when given (null counts as not given).
std::optional<std::string> string_field(const nlohmann::json& body, const char* key) {
  const auto it = body.find(key);
  if (it == body.end() || it->is_null()) return std::nullopt;
  if (!it->is_string()) {
    throw ApiError(400,
                   std::string(key) + ": expected a string, got " + std::string(it->type_name()));
  }
  return it->get<std::string>();
}

}  // namespace

RouteSpec parse_route_spec(const nlohmann::json& body) {
  if (!body.is_object()) {
    throw ApiError(400, "body: expected a JSON object {\"name\", \"listen\", \"upstream\", ...}");
  }
  RouteSpec spec;
  const auto name = string_field(body, "name");
  if (!name) throw ApiError(400, "name: missing (expected the route's name)");
  spec.name = *name;
  if (!valid_name(spec.name)) {
    throw ApiError(400, "name: '" + spec.name +
                            "' is not a route name (expected letters, digits, '_', '.' or '-')");
  }
  spec.listen = string_field(body, "listen").value_or("");
  const auto upstream = string_field(body, "upstream");
  if (!upstream || upstream->empty())
    throw ApiError(400, "upstream: missing (expected HOST:PORT or a URI such as tcp://HOST:PORT)");
  spec.upstream = *upstream;
  if (const auto it = body.find("enabled"); it != body.end() && !it->is_null()) {
    if (!it->is_boolean())
      throw ApiError(400, "enabled: expected true or false, got " + std::string(it->type_name()));
    spec.enabled = it->get<bool>();
  }
  spec.protocol = string_field(body, "protocol").value_or("raw");
  if (spec.protocol.empty()) spec.protocol = "raw";
  spec.profile = string_field(body, "profile").value_or("");
  return spec;
}

}  // namespace hil::control
