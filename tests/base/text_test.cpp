// Text that leaves hil for other programs: UTF-8 read one character at a
// time, and the XML escaping of the SVG pictures and the HTML and JUnit
// reports.
#include "base/text.hpp"

#include <gtest/gtest.h>

#include <string_view>

namespace hil {
namespace {

using namespace std::string_view_literals;

/// The length utf8_at finds at the start of `text`, and the code point it read.
std::pair<std::size_t, char32_t> first(std::string_view text) {
  char32_t cp = 0;
  const std::size_t n = utf8_at(text, 0, cp);
  return {n, n == 0 ? 0 : cp};
}

TEST(Utf8, ReadsOneCharacterOfEachLength) {
  EXPECT_EQ(first("a"), std::make_pair(std::size_t{1}, U'a'));
  EXPECT_EQ(first("\xC3\xA9x"), std::make_pair(std::size_t{2}, U'\u00E9'));
  EXPECT_EQ(first("\xE2\x82\xAC"), std::make_pair(std::size_t{3}, U'\u20AC'));
  EXPECT_EQ(first("\xF0\x9F\x9A\x97"), std::make_pair(std::size_t{4}, U'\U0001F697'));
  char32_t cp = 0;
  EXPECT_EQ(utf8_at("ab\xC3\xA9", 2, cp), 2u);
  EXPECT_EQ(cp, U'\u00E9');
}

TEST(Utf8, RefusesWhatIsNotACharacter) {
  EXPECT_EQ(first("\x80").first, 0u);              // a stray continuation byte
  EXPECT_EQ(first("\xC3").first, 0u);              // a cut sequence
  EXPECT_EQ(first("\xC3x").first, 0u);             // a sequence broken off
  EXPECT_EQ(first("\xC0\xAF").first, 0u);          // an overlong '/'
  EXPECT_EQ(first("\xE0\x80\xAF").first, 0u);      // overlong in three bytes
  EXPECT_EQ(first("\xF0\x80\x80\xAF").first, 0u);  // overlong in four bytes
  EXPECT_EQ(first("\xED\xA0\x80").first, 0u);      // a surrogate
  EXPECT_EQ(first("\xF4\x90\x80\x80").first, 0u);  // past U+10FFFF
  EXPECT_EQ(first("\xFF").first, 0u);
}

TEST(XmlEscape, EscapesEverythingXmlCannotCarryRaw) {
  EXPECT_EQ(xml_escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
  EXPECT_EQ(xml_escape("bell\x07"), "bell\\x07");
  EXPECT_EQ(xml_escape("caf\xC3\xA9"), "caf\xC3\xA9");
  EXPECT_EQ(xml_escape("bad\xFF"), "bad\xEF\xBF\xBD");
  EXPECT_EQ(xml_escape("cut\xC3"), "cut\xEF\xBF\xBD");
}

TEST(XmlEscape, KeepsLineBreaksAndTabsAndShowsTheRest) {
  EXPECT_EQ(xml_escape("a\tb\nc\r"), "a\tb\nc\r");
  EXPECT_EQ(xml_escape("nul\0!"sv), "nul\\x00!");
  EXPECT_EQ(xml_escape("\xEF\xBF\xBE\xEF\xBF\xBF"), "\\xFE\\xFF");  // U+FFFE, U+FFFF
  EXPECT_EQ(xml_escape("\xF0\x9F\x9A\x97"), "\xF0\x9F\x9A\x97");
  EXPECT_EQ(xml_escape(""), "");
}

TEST(EscapeControls, WritesLineEndsTabsAndControlBytesAsEscapes) {
  EXPECT_EQ(escape_controls("OK\r\n"), "OK\\r\\n");
  EXPECT_EQ(escape_controls("a\tb"), "a\\tb");
  EXPECT_EQ(escape_controls(std::string("\x01\x7F", 2)), "\\x01\\x7F");
  EXPECT_EQ(escape_controls(std::string("\0", 1)), "\\x00");
  EXPECT_EQ(escape_controls("caf\xC3\xA9 ^01|ACK|PONG*5E$"), "caf\xC3\xA9 ^01|ACK|PONG*5E$");
}

}  // namespace
}  // namespace hil
