#pragma once
// How `hil conform check` shows a check: the table for the console, JUnit
// XML for a CI server (one test case per exchange) and one HTML page.
#include <ostream>
#include <string>
#include <string_view>

#include "conform/check.hpp"

namespace hil::conform {

struct ReportOptions {
  std::string capture_path;  ///< named in the reports
  /// The profile whose comparison is shown exchange by exchange.
  std::string profile;
  /// Rank every profile of the car first ("which firmware does my car run").
  bool all_profiles = false;
  /// Widest car and mock column in the console table.
  std::size_t column_width = 38;
};

/// The ranking (with all_profiles), the table, each difference with the
/// profiles that would explain it, and the line `conform: K of N exchanges
/// match (CAR, profile P)`.
void write_console(std::ostream& out, const Capture& capture, const CheckResult& result,
                   const ReportOptions& options);

/// The summary line alone.
std::string summary_line(const Capture& capture, const Comparison& comparison);

std::string junit_xml(const Capture& capture, const CheckResult& result,
                      const ReportOptions& options);

std::string html_page(const Capture& capture, const CheckResult& result,
                      const ReportOptions& options);

}  // namespace hil::conform
