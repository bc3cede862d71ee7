#pragma once
// The proxy's counters as Prometheus metric families (GET /metrics on
// hil proxy): bytes, frames, bad frames, faults by kind and connections,
// per route and direction. docs/proxy-api.md lists every name.

#include <vector>

#include "base/prometheus_text.hpp"
#include "control/proxy_hub.hpp"

namespace hil::control {

std::vector<base::MetricFamily> proxy_metrics(const ProxyHub& hub);

}  // namespace hil::control
