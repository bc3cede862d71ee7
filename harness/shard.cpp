#include "harness/shard.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <numeric>

namespace hil::harness {
namespace {

namespace fs = std::filesystem;

std::optional<int> positive(std::string_view text) {
  int value = 0;
  const auto* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < 1) return std::nullopt;
  return value;
}

// FNV-1a over the bytes, then a final mix: the same on every machine.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::uint64_t key_hash(std::string_view key) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : key) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

// How much shard `shard` wants the key: the highest score is its first choice.
std::uint64_t score(std::uint64_t key, int shard) {
  return mix(key ^ mix(static_cast<std::uint64_t>(shard)));
}

// The shards in the key's order of preference.
std::vector<int> ranking(std::string_view key, int count) {
  const std::uint64_t h = key_hash(key);
  std::vector<std::pair<std::uint64_t, int>> scored;
  scored.reserve(static_cast<std::size_t>(count));
  for (int s = 0; s < count; ++s)
    scored.emplace_back(score(h, s), s);
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::vector<int> out;
  out.reserve(scored.size());
  for (const auto& [_, s] : scored)
    out.push_back(s);
  return out;
}

Duration steps_time(const std::vector<Step>& steps) {
  Duration total{0};
  for (const auto& step : steps) {
    if (const auto* wait = std::get_if<WaitStep>(&step.action)) total += wait->duration;
    if (const auto* until = std::get_if<WaitUntilStep>(&step.action))
      total += until->timeout / kWaitUntilShareDivisor;
    if (std::holds_alternative<ActionStep>(step.action)) total += kActionTime;
  }
  return total;
}

}  // namespace

std::optional<ShardSpec> parse_shard(std::string_view text, std::string* error) {
  const auto fail = [&](const std::string& why) -> std::optional<ShardSpec> {
    if (error) *error = "'" + std::string(text) + "' " + why;
    return std::nullopt;
  };
  const auto slash = text.find('/');
  if (slash == std::string_view::npos)
    return fail("is not K/N (shard K of N, 1 <= K <= N, e.g. 2/4)");
  const auto k = positive(text.substr(0, slash));
  const auto n = positive(text.substr(slash + 1));
  if (!k || !n) return fail("is not K/N with whole numbers K and N of at least 1 (e.g. 2/4)");
  if (*k > *n) return fail("names shard " + std::to_string(*k) + " of only " + std::to_string(*n));
  return ShardSpec{*k, *n};
}

std::string shard_key(const std::string& file, const std::vector<std::string>& roots) {
  const fs::path f = fs::path(file).lexically_normal();
  std::optional<fs::path> best;
  std::size_t best_depth = 0;
  for (const auto& root : roots) {
    fs::path r = fs::path(root).lexically_normal();
    if (!r.empty() && r.filename().empty()) r = r.parent_path();
    if (r == f) continue;  // the file itself was named
    const fs::path rel = f.lexically_relative(r);
    if (rel.empty() || *rel.begin() == "..") continue;
    const auto depth = static_cast<std::size_t>(std::distance(r.begin(), r.end()));
    if (!best || depth > best_depth) {
      best = rel;
      best_depth = depth;
    }
  }
  if (best) return best->generic_string();
  if (f.is_absolute()) return f.filename().generic_string();
  return f.generic_string();
}

Duration expected_duration(const Scenario& scenario) {
  Duration main =
      steps_time(scenario.setup) + steps_time(scenario.steps) + steps_time(scenario.teardown);
  for (const auto& scheduled : scenario.schedule) {
    // A step at a time from the start starts then; one after an event, at
    // least its offset after the start.
    const Duration at = std::max(Duration{0}, scheduled.when.offset) +
                        steps_time(std::vector<Step>{scheduled.step});
    main = std::max(main, at);
  }
  return std::min(main + scenario.settle, scenario.timeout + scenario.settle);
}

std::vector<std::vector<std::size_t>> shard_partition(const std::vector<ShardItem>& items,
                                                      int count) {
  count = std::max(count, 1);
  std::vector<std::vector<std::size_t>> shards(static_cast<std::size_t>(count));
  if (items.empty()) return shards;
  // The heaviest first, so the light ones fill the gaps; ties by key and
  // path, so the order given does not matter.
  std::vector<std::size_t> order(items.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto& x = items[a];
    const auto& y = items[b];
    if (x.weight_s != y.weight_s) return x.weight_s > y.weight_s;
    if (x.key != y.key) return x.key < y.key;
    return x.path < y.path;
  });
  double total = 0;
  for (const auto& item : items)
    total += std::max(item.weight_s, 0.0);
  const double capacity = total / count * (1 + kShardLoadMargin);
  std::vector<double> load(static_cast<std::size_t>(count), 0);
  for (const std::size_t i : order) {
    const double w = std::max(items[i].weight_s, 0.0);
    const auto ranked = ranking(items[i].key, count);
    std::optional<int> chosen;
    for (const int s : ranked) {
      if (load[static_cast<std::size_t>(s)] + w <= capacity) {
        chosen = s;
        break;
      }
    }
    if (!chosen) {
      // Too heavy for any shard's room: the least loaded (by the key's
      // preference among equals) takes it.
      chosen = ranked.front();
      for (const int s : ranked)
        if (load[static_cast<std::size_t>(s)] < load[static_cast<std::size_t>(*chosen)]) chosen = s;
    }
    load[static_cast<std::size_t>(*chosen)] += w;
    shards[static_cast<std::size_t>(*chosen)].push_back(i);
  }
  for (auto& shard : shards)
    std::sort(shard.begin(), shard.end());
  return shards;
}

std::vector<std::size_t> shard_members(const std::vector<ShardItem>& items, ShardSpec spec) {
  auto shards = shard_partition(items, spec.count);
  return std::move(shards[static_cast<std::size_t>(spec.index - 1)]);
}

}  // namespace hil::harness
