#pragma once
// Metrics in the Prometheus text exposition format (version 0.0.4), for a
// scraper of `GET /metrics` on hil proxy and hil mock --view.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hil::base {

/// One metric family: its samples share a name, a help line and a type.
struct MetricFamily {
  enum class Type { counter, gauge };
  std::string name;  ///< [a-zA-Z_:][a-zA-Z0-9_:]*; counters end in "_total"
  std::string help;
  Type type = Type::counter;
  struct Sample {
    std::vector<std::pair<std::string, std::string>> labels;  ///< name, value
    double value = 0;
  };
  std::vector<Sample> samples;

  /// Adds a sample; returns *this for chaining.
  MetricFamily& add(std::vector<std::pair<std::string, std::string>> labels, double value);
};

/// The text of `families` (HELP, TYPE, then one line per sample; label
/// values escaped). Throws std::invalid_argument for a name Prometheus
/// would refuse.
std::string prometheus_text(const std::vector<MetricFamily>& families);

/// The Content-Type a /metrics reply carries.
inline constexpr const char* kPrometheusContentType = "text/plain; version=0.0.4; charset=utf-8";

}  // namespace hil::base
