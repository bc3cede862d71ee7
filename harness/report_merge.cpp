#include "harness/report_merge.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include <pugixml.hpp>

namespace hil::harness {
namespace {

namespace fs = std::filesystem;

struct Case {
  RunResult run;
  pugi::xml_document node;  ///< the <testcase>, as the input had it (JUnit inputs)
};

std::string seconds3(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s);
  return buf;
}

// The <testcase>s of a JUnit document (under <testsuite>, or <testsuites>).
std::vector<Case> read_junit(const MergeInput& input, std::size_t index) {
  pugi::xml_document doc;
  const auto parsed = doc.load_buffer(input.text.data(), input.text.size());
  if (!parsed) {
    throw MergeInputError(index, input.source + ": not XML: " + parsed.description() + " at byte " +
                                     std::to_string(parsed.offset));
  }
  const auto suites = doc.select_nodes("//testsuite");
  if (suites.empty())
    throw MergeInputError(index, input.source + ": not JUnit XML (no <testsuite>)");
  std::vector<Case> out;
  for (const auto& suite : suites) {
    for (const auto& tc : suite.node().children("testcase")) {
      Case c;
      c.run.file = normal_scenario_path(tc.attribute("file").as_string());
      c.run.name = tc.attribute("name").as_string();
      if (c.run.file.empty()) {
        throw MergeInputError(index, input.source + ": test case '" + c.run.name +
                                         "' has no file attribute (not written by hil run)");
      }
      c.run.wall_seconds = tc.attribute("time").as_double();
      const auto failure = tc.child("failure") ? tc.child("failure") : tc.child("error");
      const auto skipped = tc.child("skipped");
      if (failure) {
        c.run.verdict = Verdict::fail;
        c.run.first_failure = failure.attribute("message").as_string();
        c.run.failure_text = failure.text().as_string();
      } else if (skipped) {
        c.run.verdict = Verdict::skip;
        c.run.first_failure = skipped.attribute("message").as_string();
      }
      c.node.append_copy(tc);
      out.push_back(std::move(c));
    }
  }
  return out;
}

// A <testcase> for a run read from results.json, as hil run writes one.
void add_testcase(pugi::xml_document& doc, const RunResult& r) {
  auto tc = doc.append_child("testcase");
  std::string name = r.name.empty() ? r.file : r.name;
  if (r.repeats > 1)
    name += " #" + std::to_string(r.repeat + 1) + " (seed " + std::to_string(r.seed) + ")";
  tc.append_attribute("classname") = junit_classname(r.file, r.tags).c_str();
  tc.append_attribute("name") = name.c_str();
  tc.append_attribute("time") = seconds3(r.wall_seconds).c_str();
  tc.append_attribute("file") = r.file.c_str();
  if (r.verdict == Verdict::skip)
    tc.append_child("skipped").append_attribute("message") = r.first_failure.c_str();
  if (r.verdict == Verdict::fail) {
    auto failure = tc.append_child("failure");
    failure.append_attribute("message") = r.first_failure.c_str();
    failure.append_attribute("type") = "failure";
    failure.text() = r.failure_text.c_str();
  }
  std::string out = "seed " + std::to_string(r.seed) + "\n";
  if (!r.repro_command.empty()) out += "repeat: " + r.repro_command + "\n";
  tc.append_child("system-out").text() = out.c_str();
}

std::vector<Case> read_results(const MergeInput& input, std::size_t index) {
  std::vector<RunResult> runs;
  try {
    runs = parse_results_json(input.text);
  } catch (const std::exception& e) {
    throw MergeInputError(index, input.source + ": " + e.what());
  }
  std::vector<Case> out;
  for (auto& r : runs) {
    Case c;
    r.file = normal_scenario_path(r.file);
    add_testcase(c.node, r);
    c.run = std::move(r);
    out.push_back(std::move(c));
  }
  return out;
}

std::string unique_folder(const std::string& wanted, std::set<std::string>& taken) {
  std::string name = wanted;
  for (int n = 2; taken.count(name) != 0; ++n)
    name = wanted + "-" + std::to_string(n);
  taken.insert(name);
  return name;
}

std::string junit_document(const std::vector<Case>& cases) {
  std::size_t failures = 0;
  std::size_t errors = 0;
  std::size_t skipped = 0;
  double total = 0;
  for (const auto& c : cases) {
    const auto tc = c.node.first_child();
    failures += tc.child("failure") ? 1 : 0;
    errors += !tc.child("failure") && tc.child("error") ? 1 : 0;
    skipped += tc.child("skipped") ? 1 : 0;
    total += tc.attribute("time").as_double();
  }
  pugi::xml_document doc;
  auto decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  auto suite = doc.append_child("testsuite");
  suite.append_attribute("name") = "hil";
  suite.append_attribute("tests") = static_cast<unsigned long long>(cases.size());
  suite.append_attribute("failures") = static_cast<unsigned long long>(failures);
  suite.append_attribute("errors") = static_cast<unsigned long long>(errors);
  suite.append_attribute("skipped") = static_cast<unsigned long long>(skipped);
  suite.append_attribute("time") = seconds3(total).c_str();
  for (const auto& c : cases)
    suite.append_copy(c.node.first_child());
  std::ostringstream out;
  doc.save(out, "  ", pugi::format_default, pugi::encoding_utf8);
  return out.str();
}

bool ends_with_path(const std::string& path, const std::string& tail) {
  return path.size() > tail.size() &&
         path.compare(path.size() - tail.size(), tail.size(), tail) == 0 &&
         path[path.size() - tail.size() - 1] == '/';
}

// The same scenario named from another folder: one path is the other with
// folders in front ("/builds/x/scenarios/logi/a.yaml", "scenarios/logi/a.yaml").
bool same_file_elsewhere(const std::string& a, const std::string& b) {
  return ends_with_path(a, b) || ends_with_path(b, a);
}

std::string sources_text(const std::vector<std::string>& sources) {
  std::string out;
  for (const auto& s : sources)
    out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

std::string normal_scenario_path(const std::string& path) {
  if (path.empty()) return {};
  std::string out = fs::path(path).lexically_normal().generic_string();
  while (out.rfind("./", 0) == 0)
    out.erase(0, 2);
  return out;
}

MergeResult merge_reports(const std::vector<MergeInput>& inputs, const MergeOptions& options) {
  MergeResult result;
  std::vector<Case> cases;
  std::vector<std::size_t> case_inputs;
  std::set<std::string> taken;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    auto read = inputs[i].kind == MergeInput::Kind::junit ? read_junit(inputs[i], i)
                                                          : read_results(inputs[i], i);
    // A shard's run folders keep their names unless an earlier shard took them.
    std::map<std::string, std::string> renamed;
    for (auto& c : read) {
      if (c.run.folder.empty()) continue;
      auto [it, fresh] = renamed.try_emplace(c.run.folder);
      if (fresh) {
        it->second = unique_folder(c.run.folder, taken);
        result.copies.push_back({i, c.run.folder, it->second});
      }
      c.run.folder = it->second;
    }
    for (auto& c : read) {
      cases.push_back(std::move(c));
      case_inputs.push_back(i);
    }
  }
  // Which inputs each scenario file came from, in input order.
  std::map<std::string, std::vector<std::size_t>> seen;
  std::map<std::string, std::string> names;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const auto& run = cases[k].run;
    auto& from = seen[run.file];
    if (from.empty() || from.back() != case_inputs[k]) from.push_back(case_inputs[k]);
    names.try_emplace(run.file, run.name);
    if (run.verdict == Verdict::fail) {
      std::string name = run.name;
      if (run.repeats > 1) name += " #" + std::to_string(run.repeat + 1);
      result.failed.push_back({run.file, name, {inputs[case_inputs[k]].source}});
    }
  }
  for (const auto& [file, from] : seen) {
    std::set<std::size_t> distinct(from.begin(), from.end());
    if (distinct.size() < 2) continue;
    MergeFinding d{file, names[file], {}};
    for (const auto i : distinct)
      d.sources.push_back(inputs[i].source);
    result.doubled.push_back(std::move(d));
  }
  if (options.expected) {
    std::set<std::string> expected;
    for (const auto& f : *options.expected)
      expected.insert(normal_scenario_path(f));
    for (const auto& f : expected) {
      const bool found =
          seen.count(f) != 0 || std::any_of(seen.begin(), seen.end(), [&](const auto& s) {
            return same_file_elsewhere(f, s.first);
          });
      if (!found) result.missing.push_back(f);
    }
  }
  result.junit = junit_document(cases);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    result.runs.push_back(std::move(cases[k].run));
    result.run_inputs.push_back(case_inputs[k]);
  }
  return result;
}

std::string MergeResult::summary() const {
  // Per scenario file: failed if any run failed, skipped if every run was.
  std::map<std::string, Verdict> verdicts;
  for (const auto& r : runs) {
    auto [it, fresh] = verdicts.try_emplace(r.file, r.verdict);
    if (fresh) continue;
    if (r.verdict == Verdict::fail || it->second == Verdict::fail) {
      it->second = Verdict::fail;
    } else if (r.verdict == Verdict::pass) {
      it->second = Verdict::pass;
    }
  }
  std::size_t passed = 0;
  std::size_t failed_count = 0;
  std::size_t skipped = 0;
  for (const auto& [_, v] : verdicts)
    (v == Verdict::pass ? passed : v == Verdict::skip ? skipped : failed_count) += 1;
  std::string line =
      std::to_string(passed) + " passed, " + std::to_string(failed_count) + " failed";
  if (skipped > 0) line += ", " + std::to_string(skipped) + " skipped";
  if (!missing.empty()) line += ", " + std::to_string(missing.size()) + " missing";
  if (!doubled.empty()) line += ", " + std::to_string(doubled.size()) + " doubled";
  return line;
}

std::vector<std::string> MergeResult::problems() const {
  std::vector<std::string> out;
  for (const auto& f : failed)
    out.push_back("failed: " + f.name + " (" + f.file + ") in " + sources_text(f.sources));
  for (const auto& m : missing)
    out.push_back("missing: " + m + " is in no input: no shard ran it");
  for (const auto& d : doubled) {
    out.push_back("doubled: " + d.name + " (" + d.file + ") ran in " +
                  std::to_string(d.sources.size()) + " inputs: " + sources_text(d.sources));
  }
  return out;
}

}  // namespace hil::harness
