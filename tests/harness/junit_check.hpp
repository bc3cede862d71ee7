#pragma once
// A JUnit file read back by a real XML parser (Python's), as CI tools read
// it.

#include <cstdlib>
#include <filesystem>
#include <string>

namespace hil::test {

/// Whether python3 and its XML parser are on this machine.
inline bool python_xml_available() {
  return std::system("python3 -c 'import xml.dom.minidom' >/dev/null 2>&1") == 0;
}

/// The exit status of python3 parsing the JUnit file at `path` and
/// checking that it holds `testcases` testcase elements: 0 when it does.
inline int python_checks_junit(const std::filesystem::path& path, int testcases) {
  const std::string check =
      "python3 -c \"import sys, xml.dom.minidom as m; "
      "assert len(m.parse(sys.argv[1]).getElementsByTagName('testcase')) == " +
      std::to_string(testcases) + "\" '" + path.string() + "'";
  return std::system(check.c_str());
}

}  // namespace hil::test
