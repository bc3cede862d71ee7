#include "control/proxy_metrics.hpp"

#include <string>

namespace hil::control {
namespace {

using base::MetricFamily;

MetricFamily family(std::string name, std::string help, MetricFamily::Type type) {
  return MetricFamily{std::move(name), std::move(help), type, {}};
}

void by_direction(MetricFamily& family, const std::string& route,
                  const std::array<std::uint64_t, 2>& values) {
  for (const link::Direction d : {link::Direction::to_car, link::Direction::to_client}) {
    family.add({{"route", route}, {"direction", std::string(link::to_string(d))}},
               static_cast<double>(values[static_cast<std::size_t>(d)]));
  }
}

}  // namespace

std::vector<base::MetricFamily> proxy_metrics(const ProxyHub& hub) {
  using Type = MetricFamily::Type;
  auto bytes = family("hil_proxy_bytes_total", "Bytes the proxy delivered, by route and direction.",
                      Type::counter);
  auto frames =
      family("hil_proxy_frames_total",
             "Frames the route's protocol decoded, by route and direction.", Type::counter);
  auto bad_frames = family("hil_proxy_bad_frames_total",
                           "Runs of bytes the route's protocol could not decode, by route and "
                           "direction.",
                           Type::counter);
  auto faults = family("hil_proxy_faults_total",
                       "Faults the proxy injected, by route and rule kind.", Type::counter);
  auto connections = family("hil_proxy_connections_total",
                            "Client connections accepted, refused ones included.", Type::counter);
  auto refused = family("hil_proxy_refused_connections_total",
                        "Client connections refused by a refuse rule.", Type::counter);
  auto open_links = family("hil_proxy_open_links", "Links open now.", Type::gauge);
  auto enabled =
      family("hil_proxy_route_enabled", "1 when the route listens, 0 when disabled.", Type::gauge);
  for (const ProxyHub::Route* route : hub.routes()) {
    const std::string& name = route->spec.name;
    const link::ProxyCounters counters =
        route->proxy ? route->proxy->counters() : link::ProxyCounters{};
    by_direction(bytes, name, counters.bytes);
    by_direction(frames, name, counters.frames);
    by_direction(bad_frames, name, counters.bad_frames);
    for (std::size_t k = 0; k < counters.faults.size(); ++k) {
      faults.add({{"route", name},
                  {"kind", std::string(link::to_string(static_cast<link::FaultKind>(k)))}},
                 static_cast<double>(counters.faults[k]));
    }
    connections.add({{"route", name}}, static_cast<double>(counters.connections));
    refused.add({{"route", name}}, static_cast<double>(counters.refused));
    open_links.add({{"route", name}}, static_cast<double>(counters.open_links));
    const bool on = route->proxy ? route->proxy->enabled() : route->spec.enabled;
    enabled.add({{"route", name}}, on ? 1 : 0);
  }
  return {bytes, frames, bad_frames, faults, connections, refused, open_links, enabled};
}

}  // namespace hil::control
