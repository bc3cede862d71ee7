#include "harness/scenario_search.hpp"

#include <algorithm>
#include <fstream>
#include <set>

namespace hil::harness {
namespace fs = std::filesystem;

namespace {

bool is_yaml(const fs::path& path) {
  const auto ext = path.extension().string();
  return ext == ".yaml" || ext == ".yml";
}

}  // namespace

bool looks_like_scenario(const fs::path& path) {
  if (!is_yaml(path)) return false;
  std::ifstream in(path);
  bool car = false;
  bool steps = false;
  for (std::string line; std::getline(in, line) && !(car && steps);) {
    car = car || line.rfind("car:", 0) == 0;
    steps = steps || line.rfind("steps:", 0) == 0;
  }
  return car && steps;
}

ScenarioSearch find_scenario_files(const std::vector<std::string>& paths) {
  std::set<std::string> files;
  std::set<std::string> others;
  for (const auto& arg : paths) {
    const fs::path path(arg);
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      for (auto it = fs::recursive_directory_iterator(
               path, fs::directory_options::skip_permission_denied, ec);
           !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (!it->is_regular_file(ec) || !is_yaml(it->path())) continue;
        const std::string file = it->path().lexically_normal().string();
        (looks_like_scenario(it->path()) ? files : others).insert(file);
      }
      if (ec) throw ScenarioSearchError("cannot read folder " + arg + ": " + ec.message());
    } else if (fs::exists(path, ec)) {
      files.insert(path.lexically_normal().string());
    } else {
      throw ScenarioSearchError(arg + ": no such file or folder");
    }
  }
  return {{files.begin(), files.end()}, {others.begin(), others.end()}};
}

bool has_any_tag(const std::vector<std::string>& have, const std::vector<std::string>& wanted) {
  return std::any_of(wanted.begin(), wanted.end(), [&](const std::string& t) {
    return std::find(have.begin(), have.end(), t) != have.end();
  });
}

}  // namespace hil::harness
