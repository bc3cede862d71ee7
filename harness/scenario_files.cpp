#include "harness/scenario_parts.hpp"

#include "harness/scenario_yaml.hpp"
#include "link/faults/profile_yaml.hpp"

namespace hil::harness::scenario_parts {
namespace {
namespace fs = std::filesystem;

/// Files a scenario names: they must exist and stay inside its root.
class FileReader : public config::Reader {
 public:
  explicit FileReader(const ScenarioFacts& facts) : config::Reader(facts.file), facts_(facts) {}

  /// A file named relative to the scenario's folder; it must exist and,
  /// unless allowed, stay inside the scenario's root.
  std::string existing_file(const YAML::Node& n, const std::string& what) const {
    const std::string name = scalar(n, "the " + what);
    if (name.empty()) fail(n, "the " + what + " name must not be empty");
    const bool absolute = fs::path(name).is_absolute();
    const fs::path path = absolute ? fs::path(name) : facts_.dir / name;
    const auto outside = [&](const std::string& why) {
      fail(n, what + " '" + name + "' " + why + ": a scenario may only name files inside " +
                  scenario_root(file()) +
                  " (its folder's parent); pass --allow-outside-paths to hil run to allow it");
    };
    if (!facts_.allow_outside_paths && absolute) outside("is an absolute path");
    // Checked by name first, so a ../ escape is refused whether or not the
    // file exists (no probing of the disk from a scenario).
    const fs::path root(scenario_root(file()));
    if (!facts_.allow_outside_paths && !inside(fs::absolute(path).lexically_normal(), root))
      outside("is outside the scenario's root");
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      fail(n, what + " '" + name + "' does not exist (looked for " + path.string() + ")");
    }
    // A symlink inside the root may point out of it: compare where it
    // really leads with where the root really is.
    const fs::path target = fs::weakly_canonical(path, ec);
    if (!facts_.allow_outside_paths && !inside(target, fs::weakly_canonical(root, ec)))
      outside("leads outside the scenario's root (to " + target.string() + ")");
    return path.lexically_normal().string();
  }

  static bool inside(const fs::path& resolved, const fs::path& root) {
    const fs::path relative = resolved.lexically_relative(root);
    return !relative.empty() && *relative.begin() != ".." && !relative.is_absolute();
  }

  link::FaultProfile faults(const YAML::Node& n, const std::string& what) const {
    if (n.IsNull()) return {};
    if (n.IsScalar()) {
      if (n.Scalar() == "off" || n.Scalar() == "none") return {};
      return fault_file(n);
    }
    if (n.IsMap() && n["file"]) {
      check_keys(n, {"file"}, what);
      return fault_file(n["file"]);
    }
    if (n.IsMap() || n.IsSequence()) {
      if (n.IsMap()) check_keys(n, {"rules", "description"}, what);
      return link::parse_fault_profile(n, file());
    }
    fail(n, what + " must be off, a profile file, {file: FILE}, or {rules: [...]}");
  }

  link::FaultProfile fault_file(const YAML::Node& n) const {
    const std::string path = existing_file(n, "fault profile file");
    return link::load_fault_profile(path);
  }

 private:
  const ScenarioFacts& facts_;
};

}  // namespace

std::string read_existing_file(const ScenarioFacts& facts, const YAML::Node& n,
                               const std::string& what) {
  return FileReader(facts).existing_file(n, what);
}

link::FaultProfile read_faults(const ScenarioFacts& facts, const YAML::Node& n,
                               const std::string& what) {
  return FileReader(facts).faults(n, what);
}

}  // namespace hil::harness::scenario_parts
