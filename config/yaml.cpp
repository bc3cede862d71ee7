#include "config/yaml.hpp"

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include <yaml-cpp/depthguard.h>

#include "base/duration.hpp"

namespace hil::config {
namespace {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string text_of(const YAML::Node& n) {
  return n.IsScalar() ? n.Scalar() : std::string();
}

}  // namespace

std::string join(const Keys& keys) {
  std::string text;
  for (const auto& k : keys)
    text += (text.empty() ? "" : ", ") + k;
  return text;
}

std::optional<std::string> closest(std::string_view word, const Keys& candidates) {
  std::optional<std::string> best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

std::string did_you_mean(std::string_view word, const Keys& candidates) {
  if (auto c = closest(word, candidates)) return "; did you mean '" + *c + "'?";
  return {};
}

std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar: {
      constexpr std::size_t kMaxShown = 40;
      const std::string& text = n.Scalar();
      if (text.size() <= kMaxShown) return "'" + text + "'";
      return "'" + text.substr(0, kMaxShown) + "...'";
    }
    case YAML::NodeType::Sequence:
      return "a list of " + std::to_string(n.size());
    case YAML::NodeType::Map:
      return "a map";
    default:
      return "nothing";
  }
}

std::optional<double> parse_number(std::string_view text) {
  // YAML allows an explicit plus sign; from_chars does not.
  if (text.starts_with('+')) {
    text.remove_prefix(1);
    if (text.starts_with('-')) return std::nullopt;
  }
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc{} || ptr != end || !std::isfinite(value))
    return std::nullopt;
  return value;
}

std::optional<std::uint64_t> parse_whole(std::string_view text) {
  std::uint64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc{} || ptr != end) return std::nullopt;
  return value;
}

int line_of(const YAML::Mark& mark) {
  return mark.line >= 0 ? mark.line + 1 : 0;
}
int column_of(const YAML::Mark& mark) {
  return mark.column >= 0 ? mark.column + 1 : 0;
}

std::string read_file(const std::string& path, std::string_view what) {
  const std::string cannot = "cannot read the " + std::string(what) + ": ";
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ConfigError(path, 0, 0, cannot + "it is a directory");
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) throw ConfigError(path, 0, 0, cannot + std::strerror(errno));
  std::string text;
  char buffer[65536];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, file)) > 0)
    text.append(buffer, got);
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed) throw ConfigError(path, 0, 0, cannot + std::strerror(error));
  return text;
}

YAML::Node Reader::parse(std::string_view text) const {
  try {
    return YAML::Load(std::string(text));
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp's own text for this case reads "bad file".
    fail(e.mark, "not valid YAML: nested too deeply");
  } catch (const YAML::Exception& e) {
    fail(e.mark, "not valid YAML: " + e.msg);
  }
}

void fail_at(const std::string& file, const YAML::Mark& mark, const std::string& message) {
  throw ConfigError(file, line_of(mark), column_of(mark), message);
}

void Reader::fail(const YAML::Mark& mark, const std::string& message) const {
  fail_at(file_, mark, message);
}

void Reader::fail(const YAML::Node& node, const std::string& message) const {
  fail(node.Mark(), message);
}

void Reader::fail_inside(const YAML::Node& node, int column_in_text,
                         const std::string& message) const {
  YAML::Mark mark = node.Mark();
  if (mark.line >= 0 && node.Scalar().find('\n') == std::string::npos)
    mark.column += column_in_text - 1 + (node.Tag() == "!" ? 1 : 0);
  fail(mark, message);
}

void Reader::check_keys(const YAML::Node& map, const Keys& allowed, const std::string& where,
                        std::string_view label) const {
  const std::string prefix = where.empty() ? std::string() : where + ": ";
  std::set<std::string, std::less<>> seen;
  for (auto it = map.begin(); it != map.end(); ++it) {
    // A copy: the iterator hands out a temporary pair.
    const YAML::Node key = it->first;
    if (!key.IsScalar()) fail(key, prefix + "keys must be plain words");
    const std::string& k = key.Scalar();
    if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
      fail(key, prefix + "unknown key '" + k + "' (" + std::string(label) + ": " + join(allowed) +
                    ")" + did_you_mean(k, allowed));
    }
    if (!seen.insert(k).second) fail(key, prefix + "key '" + k + "' is given twice");
  }
}

YAML::Node Reader::required(const YAML::Node& map, const std::string& key,
                            const std::string& where) const {
  const YAML::Node n = map[key];
  if (!n) fail(map, where + ": '" + key + "' is missing");
  return n;
}

std::string Reader::scalar(const YAML::Node& n, const std::string& what) const {
  if (!n.IsScalar()) fail(n, what + " must be a text or a number, not a " + shape(n));
  return n.Scalar();
}

std::string Reader::shape(const YAML::Node& n) {
  if (n.IsMap()) return "map";
  if (n.IsSequence()) return "list";
  if (n.IsNull()) return "empty value";
  return "value";
}

std::chrono::nanoseconds Reader::duration(const YAML::Node& n, const std::string& what) const {
  const std::string text = text_of(n);
  const auto d = parse_duration(text);
  if (!n.IsScalar() || !d)
    fail(n, what + " must be a duration with a unit (500ms, 2s, 1.5s), got '" + text + "'");
  return *d;
}

std::chrono::nanoseconds Reader::signed_duration(const YAML::Node& n,
                                                 const std::string& what) const {
  if (n.IsScalar() && n.Scalar().starts_with("-")) {
    const auto d = parse_duration(std::string_view(n.Scalar()).substr(1));
    if (!d)
      fail(n, what + " must be a duration with a unit (500ms, -100ms), got '" + n.Scalar() + "'");
    return -*d;
  }
  return duration(n, what);
}

std::uint64_t Reader::whole(const YAML::Node& n, const std::string& what,
                            std::uint64_t min) const {
  const std::string text = text_of(n);
  const auto value = parse_whole(text);
  if (!n.IsScalar() || !value || *value < min)
    fail(n, what + " must be a whole number >= " + std::to_string(min) + ", got '" + text + "'");
  return *value;
}

double Reader::number(const YAML::Node& n, const std::string& what) const {
  const std::string text = text_of(n);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (!n.IsScalar() || text.empty() || ec != std::errc() || end != text.data() + text.size())
    fail(n, what + " must be a number, got '" + text + "'");
  return value;
}

bool Reader::boolean(const YAML::Node& n, const std::string& what) const {
  const std::string text = text_of(n);
  if (text == "true" || text == "yes" || text == "on") return true;
  if (text == "false" || text == "no" || text == "off") return false;
  fail(n, what + " must be true or false, got '" + text + "'");
}

double Reader::metres(const YAML::Node& n, const std::string& what) const {
  std::string text = text_of(n);
  double scale = 1.0;
  if (text.ends_with("mm")) {
    scale = 0.001;
    text.resize(text.size() - 2);
  } else if (text.ends_with("cm")) {
    scale = 0.01;
    text.resize(text.size() - 2);
  } else if (text.ends_with("m")) {
    text.resize(text.size() - 1);
  }
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (!n.IsScalar() || text.empty() || ec != std::errc() || end != text.data() + text.size() ||
      value <= 0) {
    fail(n, what + " must be a distance above 0 (0.3m, 30cm, or metres as a number), got '" +
                text_of(n) + "'");
  }
  return value * scale;
}

YAML::Node ItemReader::leading(const char* key) const {
  if (!node_.IsMap()) bad(node_, "must be a map with at least '" + std::string(key) + "'");
  const YAML::Node n = node_[key];
  if (!n) bad(node_, "'" + std::string(key) + "' is missing");
  return n;
}

std::optional<YAML::Node> ItemReader::get(const char* key) const {
  YAML::Node n = node_[key];
  if (!n) return std::nullopt;
  return n;
}

void ItemReader::bad(const YAML::Node& n, const std::string& what) const {
  fail_at(source_, n.Mark(), prefix_ + ": " + what);
}

std::string ItemReader::scalar(const YAML::Node& n, const char* key) const {
  if (!n.IsScalar()) bad(n, "'" + std::string(key) + "' must be a single value");
  return n.Scalar();
}

std::uint64_t ItemReader::count(const YAML::Node& n, const char* key, std::uint64_t min) const {
  const auto v = parse_whole(scalar(n, key));
  if (!v || *v < min)
    bad(n, "'" + std::string(key) + "' must be a whole number >= " + std::to_string(min));
  return *v;
}

std::chrono::nanoseconds ItemReader::duration(const YAML::Node& n, const char* key) const {
  const auto d = parse_duration(scalar(n, key));
  if (!d) {
    bad(n, "'" + std::string(key) +
               "' must be a duration with a unit, like 250ms or 1.5s (units: ns, us, ms, s)");
  }
  return *d;
}

}  // namespace hil::config
