#include "harness/timeline.hpp"

#include <utility>

namespace hil::harness {

void Timeline::add(Record record) {
  records_.push_back(std::move(record));
}

void Timeline::add(Time at, RecordKind kind, nlohmann::json data) {
  records_.push_back(Record{at, kind, std::move(data)});
}

nlohmann::ordered_json Timeline::to_json(const Record& record) {
  nlohmann::ordered_json j;
  j["t_ms"] = link::to_ms(record.at);
  j["source"] = std::string(to_string(record.source()));
  j["kind"] = std::string(record.kind.name());
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
