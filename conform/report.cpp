#include "conform/report.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "base/text.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::conform {

namespace {

std::string clip(std::string text, std::size_t width) {
  if (text.size() <= width) return text;
  text.resize(width > 3 ? width - 3 : width);
  return text + "...";
}

std::string explanation(const Capture& capture, const ExchangeComparison& row) {
  if (row.explained_by.empty()) return "no profile of hil answers as the car did";
  std::string out = "answered as the car did by profile";
  out += row.explained_by.size() > 1 ? "s " : " ";
  for (std::size_t i = 0; i < row.explained_by.size(); ++i) {
    if (i > 0) out += i + 1 == row.explained_by.size() ? " and " : ", ";
    out += row.explained_by[i];
  }
  if (row.explained_by.size() == 1) {
    const auto& p = protocol::find_car_profile(capture.header.car, row.explained_by.front());
    out += " (" + std::string(p.summary) + ")";
  }
  return out;
}

}  // namespace

std::string summary_line(const Capture& capture, const Comparison& comparison) {
  return "conform: " + std::to_string(comparison.matches()) + " of " +
         std::to_string(comparison.exchanges.size()) + " exchanges match (" + capture.header.car +
         ", profile " + comparison.mock_profile + ")";
}

void write_console(std::ostream& out, const Capture& capture, const CheckResult& result,
                   const ReportOptions& options) {
  out << "capture: " << options.capture_path << " (" << capture.header.probe_version << ", "
      << capture.header.car << " probed in profile " << capture.header.profile << " at "
      << capture.header.target << ")\n";
  if (options.all_profiles) {
    out << "\nprofiles by matches:\n";
    for (const auto& name : result.ranking()) {
      const auto& c = result.of(name);
      out << "  " << std::left << std::setw(14) << name << std::right << std::setw(4) << c.matches()
          << " of " << c.exchanges.size() << "\n";
    }
  }
  const auto& comparison = result.of(options.profile);
  const int w = static_cast<int>(options.column_width);
  out << "\nagainst the mock in profile " << comparison.mock_profile << ":\n";
  out << std::left << std::setw(4) << "#" << std::setw(24) << "exchange" << std::setw(w + 2)
      << "car" << std::setw(w + 2) << "mock"
      << "verdict\n";
  for (std::size_t i = 0; i < comparison.exchanges.size(); ++i) {
    const auto& row = comparison.exchanges[i];
    out << std::left << std::setw(4) << (i + 1) << std::setw(24) << clip(row.name, 23)
        << std::setw(w + 2) << clip(row.car.summary(), options.column_width) << std::setw(w + 2)
        << clip(row.mock.summary(), options.column_width) << (row.matches() ? "match" : "DIFFER")
        << "\n";
  }
  out << std::right;
  bool any = false;
  for (std::size_t i = 0; i < comparison.exchanges.size(); ++i) {
    const auto& row = comparison.exchanges[i];
    if (row.matches()) continue;
    if (!any) out << "\ndifferences:\n";
    any = true;
    out << "  " << (i + 1) << " " << row.name << " (" << row.what << ")\n";
    for (const auto& d : row.differences)
      out << "      " << d << "\n";
    out << "      -> " << explanation(capture, row) << "\n";
  }
  out << "\n" << summary_line(capture, comparison) << "\n";
}

std::string junit_xml(const Capture& capture, const CheckResult& result,
                      const ReportOptions& options) {
  const auto& comparison = result.of(options.profile);
  const std::size_t failures = comparison.exchanges.size() - comparison.matches();
  std::ostringstream x;
  const std::string suite = "conform." + capture.header.car + "." + comparison.mock_profile;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<testsuites tests=\"" << comparison.exchanges.size() << "\" failures=\"" << failures
    << "\">\n";
  x << "  <testsuite name=\"" << xml_escape(suite) << "\" tests=\"" << comparison.exchanges.size()
    << "\" failures=\"" << failures << "\">\n";
  for (const auto& row : comparison.exchanges) {
    x << "    <testcase classname=\"" << xml_escape(suite) << "\" name=\"" << xml_escape(row.name)
      << "\"";
    if (row.matches()) {
      x << "/>\n";
      continue;
    }
    std::string body = "exchange: " + row.what + "\ncar:  " + row.car.summary() +
                       "\nmock: " + row.mock.summary() + "\n";
    for (const auto& d : row.differences)
      body += d + "\n";
    body += explanation(capture, row) + "\n";
    x << ">\n      <failure message=\"" << xml_escape(row.differences.front()) << "\">"
      << xml_escape(body) << "</failure>\n    </testcase>\n";
  }
  x << "  </testsuite>\n</testsuites>\n";
  return x.str();
}

std::string html_page(const Capture& capture, const CheckResult& result,
                      const ReportOptions& options) {
  const auto& comparison = result.of(options.profile);
  std::ostringstream h;
  const auto e = [](std::string_view t) { return xml_escape(t); };
  h << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    << "<title>" << e(summary_line(capture, comparison)) << "</title>\n<style>"
    << "body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse}"
    << "td,th{border:1px solid #ccc;padding:.25em .5em;vertical-align:top;text-align:left}"
    << "td.f{font-family:monospace;white-space:pre-wrap;max-width:32em;word-break:break-all}"
    << "tr.differ{background:#fde8e8}tr.match td.v{color:#1a7f37}tr.differ td.v{color:#b42318}"
    << "</style></head><body>\n";
  h << "<h1>" << e(summary_line(capture, comparison)) << "</h1>\n";
  h << "<p>Capture <code>" << e(options.capture_path) << "</code>: " << e(capture.header.car)
    << " probed with " << e(capture.header.probe_version) << " in profile "
    << e(capture.header.profile) << " at <code>" << e(capture.header.target) << "</code>.</p>\n";
  h << "<h2>Profiles by matches</h2>\n<table><tr><th>profile</th><th>matches</th></tr>\n";
  for (const auto& name : result.ranking()) {
    const auto& c = result.of(name);
    h << "<tr><td>" << e(name) << "</td><td>" << c.matches() << " of " << c.exchanges.size()
      << "</td></tr>\n";
  }
  h << "</table>\n<h2>Exchanges against profile " << e(comparison.mock_profile) << "</h2>\n";
  h << "<table><tr><th>#</th><th>exchange</th><th>kind</th><th>car</th><th>mock</th>"
    << "<th>verdict</th></tr>\n";
  for (std::size_t i = 0; i < comparison.exchanges.size(); ++i) {
    const auto& row = comparison.exchanges[i];
    h << "<tr class=\"" << (row.matches() ? "match" : "differ") << "\"><td>" << (i + 1)
      << "</td><td><b>" << e(row.name) << "</b><br>" << e(row.what) << "</td><td>"
      << e(to_string(row.kind)) << "</td><td class=\"f\">" << e(row.car.summary())
      << "</td><td class=\"f\">" << e(row.mock.summary()) << "</td><td class=\"v\">";
    if (row.matches()) {
      h << "match";
    } else {
      h << "differ<ul>";
      for (const auto& d : row.differences)
        h << "<li>" << e(d) << "</li>";
      h << "</ul>" << e(explanation(capture, row));
    }
    h << "</td></tr>\n";
  }
  h << "</table>\n</body></html>\n";
  return h.str();
}

}  // namespace hil::conform
