// JUnit XML for CI servers (GitLab, Jenkins, GitHub): one <testsuite>, one
// <testcase> per run, the failure block with its evidence inside <failure>.

#include <cstdio>

#include "base/text.hpp"
#include "harness/report.hpp"

namespace hil::harness {
namespace {

std::string junit_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s);
  return buf;
}

std::string step_list(const ScenarioOutcome& o) {
  std::string out = "seed " + std::to_string(o.seed) + "\n";
  for (const auto& s : o.steps) {
    out += format_seconds(s.started) + " .. " + format_seconds(s.ended) + "  " +
           (s.ok ? "ok    " : "FAILED") + "  " + (s.phase.empty() ? "steps" : s.phase) + " line " +
           std::to_string(s.line) + ": " + s.text;
    if (!s.ok && !s.reason.empty()) out += "  (" + s.reason + ")";
    out += "\n";
  }
  for (const auto& e : o.expectations) {
    out += std::string(e.passed ? "met   " : "NOT MET") + "  " + e.where() + ": " + e.label;
    if (!e.passed) out += "  (" + e.message + ")";
    out += "\n";
  }
  if (!o.repro_command.empty()) out += "repeat: " + o.repro_command + "\n";
  return out;
}

}  // namespace

std::string junit_classname(const std::string& file, const std::vector<std::string>& tags) {
  std::string folder;
  if (const auto slash = file.rfind('/'); slash != std::string::npos)
    folder = file.substr(0, slash);
  while (folder.rfind("./", 0) == 0)
    folder.erase(0, 2);
  while (!folder.empty() && folder.front() == '/')
    folder.erase(0, 1);
  if (folder.empty() || folder == ".") return tags.empty() ? "hil" : tags.front();
  for (char& c : folder)
    if (c == '/') c = '.';
  return folder;
}

std::string junit_xml(const std::vector<ReportEntry>& entries) {
  std::size_t failures = 0;
  std::size_t skipped = 0;
  double total = 0;
  for (const auto& e : entries) {
    if (!e.outcome.passed()) ++failures;
    if (e.outcome.was_skipped()) ++skipped;
    total += e.outcome.wall_seconds;
  }
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<testsuite name=\"hil\" tests=\"" + std::to_string(entries.size()) + "\" failures=\"" +
         std::to_string(failures) + "\" errors=\"0\" skipped=\"" + std::to_string(skipped) +
         "\" time=\"" + junit_seconds(total) + "\">\n";
  for (const auto& e : entries) {
    const auto& o = e.outcome;
    std::string name = o.name.empty() ? o.file : o.name;
    if (e.repeats > 1)
      name += " #" + std::to_string(e.repeat + 1) + " (seed " + std::to_string(o.seed) + ")";
    out += "  <testcase classname=\"" + xml_escape(junit_classname(o.file, o.tags)) + "\" name=\"" +
           xml_escape(name) + "\" time=\"" + junit_seconds(o.wall_seconds) + "\"";
    if (!o.file.empty()) out += " file=\"" + xml_escape(o.file) + "\"";
    out += ">\n";
    if (o.was_skipped()) out += "    <skipped message=\"" + xml_escape(o.skipped) + "\"/>\n";
    if (!o.passed()) {
      out += "    <failure message=\"" + xml_escape(o.first_failure()) + "\" type=\"" +
             (o.error.empty() ? "failure" : "error") + "\">" + xml_escape(failure_text(o)) +
             "</failure>\n";
    }
    out += "    <system-out>" + xml_escape(step_list(o)) + "</system-out>\n";
    out += "  </testcase>\n";
  }
  out += "</testsuite>\n";
  return out;
}

}  // namespace hil::harness
