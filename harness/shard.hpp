#pragma once
// `hil run --shard K/N`: which of the selected scenario files shard K of N
// runs, so that N CI jobs together run each file exactly once. Pure: the
// caller gives the files and their expected durations.
//
// Each file goes to the shard that ranks highest for its key (rendezvous
// hashing: a hash of the key and the shard number), unless that shard is
// already full; a shard is full when its expected time would pass the mean
// by more than a small margin. Adding or removing one file therefore moves
// that file and few others, and no shard runs much longer than the mean.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "harness/scenario.hpp"

namespace hil::harness {

/// Shard `index` (1-based) of `count`.
struct ShardSpec {
  int index = 1;
  int count = 1;
  friend bool operator==(const ShardSpec&, const ShardSpec&) = default;
};

/// "K/N" with 1 <= K <= N; nullopt for anything else (with `error` saying
/// what was expected).
std::optional<ShardSpec> parse_shard(std::string_view text, std::string* error = nullptr);

/// One selected scenario file.
struct ShardItem {
  /// What the shard is chosen from: the path relative to the folder named
  /// on the command line (shard_key()), the same on every machine.
  std::string key;
  std::string path;     ///< as the run names it; breaks ties between equal keys
  double weight_s = 1;  ///< expected run time, seconds
};

/// The weight of a file that does not load (its run is only an error).
inline constexpr double kShardNominalWeightS = 1.0;

/// How far a shard may exceed the mean expected time before files whose
/// first choice it is go to their next choice (0.15: 15 %).
inline constexpr double kShardLoadMargin = 0.15;

/// A file's key: its path, normalised, relative to the deepest of `roots`
/// (the paths named on the command line) that holds it. A file named
/// itself keeps its relative path as written; an absolute one, its name.
std::string shard_key(const std::string& file, const std::vector<std::string>& roots);

/// A wait-until usually ends well before its timeout: a quarter of the
/// timeout is counted (on hil's library, closer to the runs' times than
/// the whole timeout).
inline constexpr int kWaitUntilShareDivisor = 4;
/// What an operator action costs (its command and the car's answer).
inline constexpr Duration kActionTime = std::chrono::milliseconds(100);

/// About how long a run of the scenario takes in its own time: its waits,
/// a share of its wait-untils' timeouts, its actions, the time scheduled
/// steps start at, and the settle time; at most its timeout and settle.
Duration expected_duration(const Scenario& scenario);

/// Every shard's items (indexes into `items`, in the order given), for
/// `count` shards. The result depends on the items' keys, paths and
/// weights, not on their order.
std::vector<std::vector<std::size_t>> shard_partition(const std::vector<ShardItem>& items,
                                                      int count);

/// The indexes (into `items`, ascending) of shard `spec`.
std::vector<std::size_t> shard_members(const std::vector<ShardItem>& items, ShardSpec spec);

}  // namespace hil::harness
