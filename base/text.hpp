#pragma once
// Text that leaves hil for other programs: UTF-8 read one character at a
// time, XML escaping for the SVG pictures and the HTML and JUnit reports,
// and control bytes escaped for one-line frame texts.

#include <cstddef>
#include <string>
#include <string_view>

namespace hil {

/// The length of the UTF-8 sequence that starts at `text[i]`, with its code
/// point in `code_point`; 0 when the bytes there are not UTF-8 (a stray
/// continuation byte, a cut sequence, an overlong form, a surrogate or a
/// value past U+10FFFF).
std::size_t utf8_at(std::string_view text, std::size_t i, char32_t& code_point);

/// `text` made safe inside an XML element or a quoted attribute: & < > " '
/// become references, a byte that is not UTF-8 becomes U+FFFD, and the
/// control characters XML 1.0 cannot carry (even as references) are
/// written "\xNN".
std::string xml_escape(std::string_view text);

/// `text` as one printable line, for frames in reports and tables: CR, LF
/// and tab become "\r", "\n" and "\t", other control bytes (and DEL)
/// "\xNN"; everything else, UTF-8 included, is kept.
std::string escape_controls(std::string_view text);

}  // namespace hil
