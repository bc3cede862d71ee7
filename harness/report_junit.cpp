// JUnit XML for CI servers (GitLab, Jenkins, GitHub): one <testsuite>, one
// <testcase> per run, the failure block with its evidence inside <failure>.

#include <cstdio>

#include "harness/report.hpp"

namespace hil::harness {
namespace {

// The length of the UTF-8 sequence starting at `i` and its code point, or
// 0 when the bytes there are not valid UTF-8.
std::size_t utf8_at(std::string_view s, std::size_t i, char32_t& cp) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  std::size_t n = 0;
  if (c < 0x80) {
    cp = c;
    return 1;
  }
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
    cp = c & 0x1F;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    cp = c & 0x0F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    cp = c & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(k) & 0x3F);
  }
  // Overlong forms, surrogates and values past U+10FFFF are not characters.
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
      (cp >= 0xD800 && cp <= 0xDFFF))
    return 0;
  return n;
}

std::string classname(const ScenarioOutcome& o) {
  std::string folder;
  if (const auto slash = o.file.rfind('/'); slash != std::string::npos)
    folder = o.file.substr(0, slash);
  while (folder.rfind("./", 0) == 0)
    folder.erase(0, 2);
  while (!folder.empty() && folder.front() == '/')
    folder.erase(0, 1);
  if (folder.empty() || folder == ".") return o.tags.empty() ? "hil" : o.tags.front();
  for (char& c : folder)
    if (c == '/') c = '.';
  return folder;
}

std::string seconds(double s) {
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
    out += std::string(e.passed ? "met   " : "NOT MET") + "  expect line " +
           std::to_string(e.line) + ": " + e.label;
    if (!e.passed) out += "  (" + e.message + ")";
    out += "\n";
  }
  if (!o.repro_command.empty()) out += "repeat: " + o.repro_command + "\n";
  return out;
}

}  // namespace

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    char32_t cp = 0;
    const std::size_t n = utf8_at(text, i, cp);
    if (n == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD for a byte that is not UTF-8
      ++i;
      continue;
    }
    switch (cp) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        if ((cp < 0x20 && cp != '\t' && cp != '\n' && cp != '\r') || cp == 0xFFFE || cp == 0xFFFF) {
          // XML 1.0 cannot carry these even as references.
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned>(cp & 0xFF));
          out += buf;
        } else {
          out.append(text.substr(i, n));
        }
    }
    i += n;
  }
  return out;
}

std::string junit_xml(const std::vector<ReportEntry>& entries) {
  std::size_t failures = 0;
  double total = 0;
  for (const auto& e : entries) {
    if (!e.outcome.passed()) ++failures;
    total += e.outcome.wall_seconds;
  }
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<testsuite name=\"hil\" tests=\"" + std::to_string(entries.size()) + "\" failures=\"" +
         std::to_string(failures) + "\" errors=\"0\" skipped=\"0\" time=\"" + seconds(total) +
         "\">\n";
  for (const auto& e : entries) {
    const auto& o = e.outcome;
    std::string name = o.name.empty() ? o.file : o.name;
    if (e.repeats > 1)
      name += " #" + std::to_string(e.repeat + 1) + " (seed " + std::to_string(o.seed) + ")";
    out += "  <testcase classname=\"" + xml_escape(classname(o)) + "\" name=\"" + xml_escape(name) +
           "\" time=\"" + seconds(o.wall_seconds) + "\"";
    if (!o.file.empty()) out += " file=\"" + xml_escape(o.file) + "\"";
    out += ">\n";
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
