#pragma once
// Tables of operator lines a parser refuses, with the column and message
// each error must have, checked case by case.

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace hil::client::test {

/// A line the parser refuses, the 1-based column its error names, and the
/// error's message (whole, or a part of it; see MessageMatch).
struct SyntaxErrorCase {
  std::string line;
  std::size_t column;
  std::string message;
};

enum class MessageMatch {
  whole,  ///< the error's message is the case's
  part,   ///< the error's message contains the case's
};

/// Checks every case: `parse_error(line)` (an error with a column and a
/// message) names the case's column and has its message.
template <class ParseError>
void expect_syntax_errors(const std::vector<SyntaxErrorCase>& cases, MessageMatch match,
                          ParseError&& parse_error) {
  for (const auto& c : cases) {
    const auto e = parse_error(c.line);
    EXPECT_EQ(e.column, c.column) << c.line << ": " << e.message;
    if (match == MessageMatch::whole) {
      EXPECT_EQ(e.message, c.message) << c.line;
    } else {
      EXPECT_NE(e.message.find(c.message), std::string::npos) << c.line << ": " << e.message;
    }
  }
}

}  // namespace hil::client::test
