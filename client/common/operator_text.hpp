#pragma once
// The text handling every operator language shares: words with their
// columns, letter case, whole numbers and durations, script lines, and the
// "file:line:col: message" form of a script's errors.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "link/time.hpp"
#include "protocol/common/overloaded.hpp"

namespace hil::client {

using protocol::Overloaded;

std::string to_lower(std::string_view text);
std::string to_upper(std::string_view text);

/// What std::isspace calls blank in the C locale.
inline constexpr std::string_view kBlanks = " \t\n\v\f\r";

/// `text` without the `blanks` at either end (or only at its end).
std::string_view trim(std::string_view text, std::string_view blanks = kBlanks);
std::string_view trim_end(std::string_view text, std::string_view blanks = kBlanks);

/// A word of a line and the 1-based column where it starts.
struct Word {
  std::string_view text;
  std::size_t column = 1;
};

/// Where a `#` starts a comment.
enum class CommentStart : std::uint8_t {
  anywhere,    ///< a `#` ends the word it is in and the line
  word_start,  ///< only a word that begins with `#`; inside a word it is a letter
};

struct SplitLine {
  std::vector<Word> words;
  std::size_t end_column = 1;  ///< one past the last word (1 for none)
};

/// The words of `line` between `blanks`, up to a comment.
SplitLine split_words(std::string_view line, std::string_view blanks = kBlanks,
                      CommentStart comment = CommentStart::anywhere);

/// What a whole number may look like besides its decimal digits.
struct IntegerSyntax {
  bool plus = true;             ///< a leading '+'
  bool minus = true;            ///< a leading '-'
  bool hex = false;             ///< 0x or 0X and hex digits
  std::size_t max_digits = 18;  ///< longer is not a number
};

/// A whole number, or why the text is not one within the range.
struct ParsedInteger {
  enum class Error : std::uint8_t { none, not_a_number, out_of_range };
  std::int64_t value = 0;
  Error error = Error::none;
  explicit operator bool() const { return error == Error::none; }
};

/// `text` as a whole number in [lo, hi].
ParsedInteger parse_integer(std::string_view text, std::int64_t lo, std::int64_t hi,
                            IntegerSyntax syntax = {});

/// A duration with a unit, "500ms", "1s", "1.5s", "2m" or "2min" (units in
/// any letter case), exact to the nanosecond and at most `max`; nullopt
/// otherwise. A point needs a digit after it ("1.s" is refused).
std::optional<link::Duration> parse_duration(std::string_view text, link::Duration max);

/// How duration_text writes a duration that is not whole seconds, or
/// whole milliseconds under a second.
enum class DurationStyle : std::uint8_t {
  milliseconds,  ///< "1500ms", "120s" (WR8, Arduino)
  largest_unit,  ///< "1.5s", "2m" for whole minutes (LOGI)
};

/// A duration as an operator writes it, read back exactly by
/// parse_duration: "2s", "250ms", finer than a millisecond "1.5ms", the
/// rest as `style` says.
std::string duration_text(link::Duration d, DurationStyle style = DurationStyle::milliseconds);

/// Where an operator's line is wrong: the 1-based column of the offending
/// word (one past the end of the line when a word is missing) and what was
/// expected.
struct LineError {
  std::size_t column = 1;
  std::string message;
  friend bool operator==(const LineError&, const LineError&) = default;
};

/// One parsed line of an operator language: an action, nothing (a blank
/// line or a comment), or an error.
template <class Action>
struct ParseResult {
  std::optional<Action> action;  ///< empty for a blank line, a comment, or an error
  std::optional<LineError> error;
  bool ok() const { return !error.has_value(); }
};

/// The lines of a script, without their '\n'; no last empty line after a
/// final newline.
std::vector<std::string_view> split_lines(std::string_view text);

/// "file:line:col: message".
std::string format_location(std::string_view file, std::size_t line, std::size_t column,
                            std::string_view message);

/// A script line that did not parse, or a script that could not be read.
/// Every script parser lists one per wrong line, in order.
struct ScriptError {
  std::string file;        ///< the script's name as a person reads it
  std::size_t line = 0;    ///< 1-based; 0 when the script could not be read
  std::size_t column = 0;  ///< 1-based; 0 with line 0
  std::string message;
  /// "file:line:col: message" ("file: message" when the script could not be read).
  std::string to_string() const;
  friend bool operator==(const ScriptError&, const ScriptError&) = default;
};

}  // namespace hil::client
