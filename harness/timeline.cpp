#include "harness/timeline.hpp"

#include <utility>

namespace hil::harness {

std::string_view to_string(Source source) {
  switch (source) {
    case Source::wire:
      return "wire";
    case Source::fault:
      return "fault";
    case Source::client:
      return "client";
    case Source::sim:
      return "sim";
    case Source::step:
      return "step";
    case Source::car:
      return "car";
  }
  return "?";
}

void Timeline::add(Record record) {
  records_.push_back(std::move(record));
}

void Timeline::add(Time at, Source source, std::string kind, nlohmann::json data) {
  records_.push_back(Record{at, source, std::move(kind), std::move(data)});
}

nlohmann::ordered_json Timeline::to_json(const Record& record) {
  nlohmann::ordered_json j;
  j["t_ms"] = link::to_ms(record.at);
  j["source"] = std::string(to_string(record.source));
  j["kind"] = record.kind;
  for (const auto& [key, value] : record.data.items())
    j[key] = value;
  return j;
}

std::string Timeline::to_ndjson() const {
  std::string out;
  for (const auto& r : records_)
    out += to_json(r).dump() + "\n";
  return out;
}

}  // namespace hil::harness
