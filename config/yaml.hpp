#pragma once
// The YAML reading kit every hil loader uses: worlds (sim/arena_yaml),
// fault profiles (link/faults/profile_yaml), behaviours
// (mocks/behaviour_yaml) and scenarios (harness/scenario_*). It parses the
// text, reports every problem as a ConfigError at the node it is about,
// checks a map's keys (with a "did you mean" for a typo) and reads the
// values all the languages share: words, whole numbers, numbers, booleans,
// durations and distances with units.

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config/error.hpp"

namespace hil::config {

/// Key names in the order messages list them.
using Keys = std::vector<std::string>;

/// "a, b, c".
std::string join(const Keys& keys);
/// The candidate a typo most likely meant, if one is close enough to guess
/// (an edit distance of at most a third of the word, and at least 2).
std::optional<std::string> closest(std::string_view word, const Keys& candidates);
/// "; did you mean 'x'?" for the closest candidate, or "".
std::string did_you_mean(std::string_view word, const Keys& candidates);

/// How a node looks, for "got ..." in messages: a scalar quoted and cut at
/// 40 characters (a hostile file cannot make a message of megabytes), "a
/// list of N", "a map" or "nothing".
std::string describe(const YAML::Node& node);

/// A finite decimal number, with an optional '+' or '-'; nullopt otherwise.
std::optional<double> parse_number(std::string_view text);
/// Decimal digits only; nullopt otherwise (and on overflow).
std::optional<std::uint64_t> parse_whole(std::string_view text);

/// The whole of a file, or a ConfigError "PATH: cannot read the WHAT:
/// REASON" (a directory, a missing file, a read error).
std::string read_file(const std::string& path, std::string_view what);

/// A position of yaml-cpp (counting from 0, -1 for none) counted from 1, 0
/// for none.
int line_of(const YAML::Mark& mark);
int column_of(const YAML::Mark& mark);

/// A ConfigError in `file` at `mark`.
[[noreturn]] void fail_at(const std::string& file, const YAML::Mark& mark,
                          const std::string& message);

/// One YAML file being read: its name for messages and the checks and
/// values every loader shares. Every function that fails throws
/// ConfigError at the node it was given.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }

  /// Parses `text`; a syntax error is a ConfigError "not valid YAML: ..."
  /// at its position.
  YAML::Node parse(std::string_view text) const;

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& message) const;
  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const;
  /// At a column inside a one-line scalar (1-based within its text).
  [[noreturn]] void fail_inside(const YAML::Node& node, int column_in_text,
                                const std::string& message) const;

  /// Every key of `map` is a plain word from `allowed`, given once. Fails
  /// with "WHERE: unknown key 'k' (LABEL: allowed...); did you mean 'x'?"
  /// or "WHERE: key 'k' is given twice"; `where` empty leaves out "WHERE: ".
  void check_keys(const YAML::Node& map, const Keys& allowed, const std::string& where,
                  std::string_view label = "allowed") const;
  /// map[key], or a failure "WHERE: 'key' is missing" at the map.
  YAML::Node required(const YAML::Node& map, const std::string& key,
                      const std::string& where) const;
  /// Which of `keys` `map` has, "" for none; a second one fails at itself
  /// with clash(first, second) as the message.
  template <class Clash>
  std::string one_key(const YAML::Node& map, const Keys& keys, Clash clash) const {
    std::string found;
    for (const auto& k : keys) {
      if (!map[k]) continue;
      if (!found.empty()) fail(map[k], clash(found, k));
      found = k;
    }
    return found;
  }

  /// The scalar's own text (an unquoted 001 stays "001").
  std::string scalar(const YAML::Node& n, const std::string& what) const;
  /// "map", "list", "empty value" or "value", for "not a ..." messages.
  static std::string shape(const YAML::Node& n);
  std::chrono::nanoseconds duration(const YAML::Node& n, const std::string& what) const;
  /// A duration that may be negative ("-100ms"), for offsets.
  std::chrono::nanoseconds signed_duration(const YAML::Node& n, const std::string& what) const;
  std::uint64_t whole(const YAML::Node& n, const std::string& what, std::uint64_t min) const;
  double number(const YAML::Node& n, const std::string& what) const;
  /// true/yes/on or false/no/off.
  bool boolean(const YAML::Node& n, const std::string& what) const;
  /// A length above 0 in metres: a number, or one with a unit (0.3m, 30cm, 300mm).
  double metres(const YAML::Node& n, const std::string& what) const;

 private:
  std::string file_;
};

/// One map of a file's list being read (a fault rule, a behaviour): the
/// values such an item is made of, every failure "PREFIX: what" at the node
/// it is about, the prefix naming the item ("rule 3 (drop)").
class ItemReader {
 protected:
  /// `keys_label` introduces the allowed keys when one is unknown ("this
  /// kind takes"). `file` and `node` must outlive the reader.
  ItemReader(const std::string& file, const YAML::Node& node, std::string prefix,
             std::string keys_label)
      : source_(file),
        node_(node),
        prefix_(std::move(prefix)),
        keys_label_(std::move(keys_label)) {}

  /// The value of the key that says what the item is ('kind', 'do'): the
  /// item must be a map that has it.
  YAML::Node leading(const char* key) const;
  /// The item's value at `key`, or nullopt when it has none.
  std::optional<YAML::Node> get(const char* key) const;
  /// Every key of the item is one of `allowed` (any range of words), given once.
  template <class Words>
  void check_keys(const Words& allowed) const {
    Reader(source_).check_keys(node_, Keys(allowed.begin(), allowed.end()), prefix_, keys_label_);
  }
  [[noreturn]] void bad(const YAML::Node& n, const std::string& what) const;
  /// The text of `n`, which must be a single value.
  std::string scalar(const YAML::Node& n, const char* key) const;
  /// A whole number of at least `min`.
  std::uint64_t count(const YAML::Node& n, const char* key, std::uint64_t min = 1) const;
  /// A duration with a unit (250ms, 1.5s).
  std::chrono::nanoseconds duration(const YAML::Node& n, const char* key) const;

  const std::string& source_;
  const YAML::Node& node_;
  std::string prefix_;

 private:
  std::string keys_label_;
};

}  // namespace hil::config
