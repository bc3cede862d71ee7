// The Arduino IDE's step before compiling a sketch: the .ino files become
// one C++ file with `#include <Arduino.h>` and a prototype for each
// function, so a sketch may call a function defined further down. A small
// scanner, not a C++ parser: it finds the function definitions at brace
// depth 0 once comments, literals and preprocessor lines are set aside.

#include <algorithm>
#include <cctype>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "mocks/avr/sketch_build.hpp"

namespace hil::mocks::avr {

// This file's own namespace: hil's unity builds compile all of hil::mocks as
// one source, where two files' anonymous namespaces are one.
namespace sketch_prototypes_impl {
namespace {

bool is_ident_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}
bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

/// The text as the scanner sees it: comments and preprocessor lines turned
/// into spaces (line breaks kept, so offsets and lines stay the same), and a
/// mark on every character of a string or character literal.
struct Scanned {
  std::string code;
  std::vector<bool> literal;
  bool is_code(std::size_t i) const { return !literal[i]; }
};

/// Skips a string literal that opens at `i` ('"'); returns the offset past
/// its end. A raw string (R"delim(...)delim") ends only at its delimiter.
std::size_t string_end(std::string_view text, std::size_t i) {
  if (i > 0 && text[i - 1] == 'R') {
    const std::size_t open = text.find('(', i + 1);
    if (open != std::string_view::npos && open - i - 1 <= 16) {
      const std::string close = ")" + std::string(text.substr(i + 1, open - i - 1)) + "\"";
      const std::size_t end = text.find(close, open + 1);
      return end == std::string_view::npos ? text.size() : end + close.size();
    }
  }
  for (std::size_t j = i + 1; j < text.size(); ++j) {
    if (text[j] == '\\') {
      ++j;
    } else if (text[j] == '"' || text[j] == '\n') {
      return j + 1;
    }
  }
  return text.size();
}

/// A ' that follows a number's digits (1'000'000) separates digits; any
/// other opens a character literal.
bool is_digit_separator(std::string_view text, std::size_t i) {
  std::size_t start = i;
  while (start > 0 && (is_ident_char(text[start - 1]) || text[start - 1] == '.'))
    --start;
  return start < i && std::isdigit(static_cast<unsigned char>(text[start])) != 0;
}

std::size_t char_literal_end(std::string_view text, std::size_t i) {
  for (std::size_t j = i + 1; j < text.size(); ++j) {
    if (text[j] == '\\') {
      ++j;
    } else if (text[j] == '\'' || text[j] == '\n') {
      return j + 1;
    }
  }
  return text.size();
}

Scanned scan(std::string_view text) {
  Scanned s{std::string(text), std::vector<bool>(text.size(), false)};
  auto blank = [&](std::size_t from, std::size_t to) {
    for (std::size_t k = from; k < to && k < s.code.size(); ++k)
      if (s.code[k] != '\n') s.code[k] = ' ';
  };
  bool line_start = true;  // only spaces since the last line break
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    if (c == '/' && next == '/') {
      std::size_t end = text.find('\n', i);
      if (end == std::string_view::npos) end = text.size();
      blank(i, end);
      i = end;
    } else if (c == '/' && next == '*') {
      const std::size_t close = text.find("*/", i + 2);
      const std::size_t end = close == std::string_view::npos ? text.size() : close + 2;
      blank(i, end);
      i = end;
    } else if (c == '#' && line_start) {
      // A directive runs to the end of the line, or further after a '\'.
      std::size_t j = i;
      while (j < text.size() && text[j] != '\n') {
        if (text[j] == '\\' && j + 1 < text.size() && text[j + 1] == '\n') ++j;
        if (text[j] == '/' && j + 1 < text.size() && text[j + 1] == '*') {
          const std::size_t close = text.find("*/", j + 2);
          j = close == std::string_view::npos ? text.size() : close + 2;
          continue;
        }
        ++j;
      }
      blank(i, j);
      i = j;
    } else if (c == '"' || (c == '\'' && !is_digit_separator(text, i))) {
      const std::size_t end = c == '"' ? string_end(text, i) : char_literal_end(text, i);
      std::fill(s.literal.begin() + static_cast<std::ptrdiff_t>(i),
                s.literal.begin() + static_cast<std::ptrdiff_t>(end), true);
      line_start = false;
      i = end;
      continue;
    } else {
      if (c == '\n') {
        line_start = true;
      } else if (!is_space(c)) {
        line_start = false;
      }
      ++i;
      continue;
    }
    // After a comment or directive, a line break (if one was reached) sets
    // line_start on the next turn.
  }
  return s;
}

/// One function definition or declaration found at depth 0.
struct Function {
  std::size_t start = 0;  ///< offset of its first token
  std::string name;
  std::string prototype;  ///< "static int f(int a);"
};

/// `code[from, to)` with every run of white space outside literals made one
/// space, and the ends trimmed.
std::string squeeze(const Scanned& s, std::size_t from, std::size_t to) {
  std::string out;
  bool pending_space = false;
  for (std::size_t i = from; i < to; ++i) {
    if (s.is_code(i) && is_space(s.code[i])) {
      pending_space = !out.empty();
      continue;
    }
    if (pending_space) out += ' ';
    pending_space = false;
    out += s.code[i];
  }
  return out;
}

/// The parameter list `code[open, close]` (both parentheses) without
/// default arguments: `(int a = 3, char* b = f(1, 2))` is `(int a, char* b)`.
std::string strip_defaults(const Scanned& s, std::size_t open, std::size_t close) {
  std::string out;
  int nesting = 0;
  bool skipping = false;
  std::size_t from = open;
  for (std::size_t i = open + 1; i < close; ++i) {
    if (!s.is_code(i)) continue;
    const char c = s.code[i];
    if (c == '(' || c == '[' || c == '{') ++nesting;
    if (c == ')' || c == ']' || c == '}') --nesting;
    if (nesting != 0) continue;
    if (c == '=' && !skipping) {
      out += squeeze(s, from, i);
      skipping = true;
    } else if (c == ',') {
      if (!skipping) out += squeeze(s, from, i);
      out += ", ";
      skipping = false;
      from = i + 1;
    }
  }
  if (!skipping) out += squeeze(s, from, close);
  // squeeze() of the first piece starts at '(' itself.
  if (out.empty() || out[0] != '(') out.insert(out.begin(), '(');
  if (out.starts_with("( ")) out.erase(1, 1);
  return out + ")";
}

std::string word_before(const Scanned& s, std::size_t end, std::size_t floor,
                        std::size_t* start_out) {
  std::size_t e = end;
  while (e > floor && s.is_code(e - 1) && is_space(s.code[e - 1]))
    --e;
  std::size_t b = e;
  while (b > floor && s.is_code(b - 1) && is_ident_char(s.code[b - 1]))
    --b;
  if (start_out != nullptr) *start_out = b;
  return s.code.substr(b, e - b);
}

bool has_word(std::string_view text, std::string_view word) {
  for (std::size_t at = text.find(word); at != std::string_view::npos;
       at = text.find(word, at + 1)) {
    const bool before_ok = at == 0 || !is_ident_char(text[at - 1]);
    const std::size_t after = at + word.size();
    const bool after_ok = after >= text.size() || !is_ident_char(text[after]);
    if (before_ok && after_ok) return true;
  }
  return false;
}

/// The function whose definition or declaration is `code[from, to)` (the
/// text from the end of the previous statement to its `{` or `;`), if it is
/// a plain function: a return type, an unqualified name, a parameter list.
std::optional<Function> as_function(const Scanned& s, std::size_t from, std::size_t to) {
  while (from < to && s.is_code(from) && is_space(s.code[from]))
    ++from;
  if (from >= to) return std::nullopt;
  // The parenthesised groups at the top level, and any '=' there (an
  // initialiser, not a function).
  struct Group {
    std::size_t open, close;
  };
  std::vector<Group> groups;
  int depth = 0;
  std::size_t open = 0;
  for (std::size_t i = from; i < to; ++i) {
    if (!s.is_code(i)) continue;
    const char c = s.code[i];
    if (c == '(') {
      if (depth++ == 0) open = i;
    } else if (c == ')') {
      if (--depth == 0) groups.push_back({open, i});
      if (depth < 0) return std::nullopt;
    } else if (depth == 0 && c == '=') {
      return std::nullopt;
    }
  }
  if (depth != 0) return std::nullopt;
  static const std::set<std::string, std::less<>> kNotNames = {
      "__attribute__", "noexcept", "decltype", "alignas", "throw",    "if",        "while",
      "for",           "switch",   "return",   "sizeof",  "operator", "__declspec"};
  const Group* params = nullptr;
  std::size_t name_start = 0;
  std::string name;
  for (auto it = groups.rbegin(); it != groups.rend(); ++it) {
    std::size_t b = 0;
    std::string w = word_before(s, it->open, from, &b);
    if (w.empty() || kNotNames.contains(w)) continue;
    params = &*it;
    name = std::move(w);
    name_start = b;
    break;
  }
  if (params == nullptr || std::isdigit(static_cast<unsigned char>(name[0])) != 0)
    return std::nullopt;
  const std::string head = squeeze(s, from, name_start);
  if (head.empty()) return std::nullopt;  // ISR(vector) and other macros
  // A::f (defined outside its class) and ~A are declared in the class.
  if (head.ends_with("::") || head.ends_with("~")) return std::nullopt;
  for (const char* word : {"template", "class", "struct", "union", "enum", "namespace", "typedef",
                           "using", "operator", "return"}) {
    if (has_word(head, word)) return std::nullopt;
  }
  const std::string trailer = squeeze(s, params->close + 1, to);
  if (!trailer.empty() && !trailer.starts_with("noexcept") &&
      !trailer.starts_with("__attribute__") && !trailer.starts_with("throw"))
    return std::nullopt;
  Function f;
  f.start = from;
  f.name = name;
  f.prototype = head + " " + name + strip_defaults(s, params->open, params->close);
  if (!trailer.empty()) f.prototype += " " + trailer;
  f.prototype += ";";
  return f;
}

struct TopLevel {
  std::vector<Function> definitions;
  std::set<std::string, std::less<>> declared;
};

TopLevel find_functions(const Scanned& s) {
  TopLevel top;
  int depth = 0;
  std::size_t chunk = 0;
  for (std::size_t i = 0; i < s.code.size(); ++i) {
    if (!s.is_code(i)) continue;
    const char c = s.code[i];
    if (c == '{') {
      if (depth == 0) {
        if (auto f = as_function(s, chunk, i)) top.definitions.push_back(std::move(*f));
      }
      ++depth;
    } else if (c == '}') {
      depth = std::max(0, depth - 1);
      if (depth == 0) chunk = i + 1;
    } else if (c == ';' && depth == 0) {
      if (auto f = as_function(s, chunk, i)) top.declared.insert(f->name);
      chunk = i + 1;
    }
  }
  return top;
}

std::string line_directive(std::size_t line, const std::filesystem::path& path) {
  std::string quoted;
  for (const char c : path.string()) {
    if (c == '\\' || c == '"') quoted += '\\';
    quoted += c;
  }
  return "#line " + std::to_string(line) + " \"" + quoted + "\"\n";
}

}  // namespace
}  // namespace sketch_prototypes_impl

std::string generate_sketch_cpp(const std::vector<SketchFile>& files) {
  using namespace sketch_prototypes_impl;
  // All files are scanned as one text, as the compiler will see them.
  std::string all;
  std::vector<std::size_t> file_start;
  for (const auto& file : files) {
    file_start.push_back(all.size());
    all += file.text;
    if (!all.empty() && all.back() != '\n') all += '\n';
  }
  const Scanned scanned = scan(all);
  const TopLevel top = find_functions(scanned);

  auto file_of = [&](std::size_t offset) {
    return static_cast<std::size_t>(std::upper_bound(file_start.begin(), file_start.end(), offset) -
                                    file_start.begin() - 1);
  };
  auto line_of = [&](std::size_t offset) {
    const std::size_t begin = file_start[file_of(offset)];
    return 1 + static_cast<std::size_t>(
                   std::count(all.begin() + static_cast<std::ptrdiff_t>(begin),
                              all.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
  };

  std::string prototypes;
  std::set<std::string, std::less<>> given;
  for (const auto& f : top.definitions) {
    if (top.declared.contains(f.name) || given.contains(f.prototype)) continue;
    given.insert(f.prototype);
    prototypes += line_directive(line_of(f.start), files[file_of(f.start)].path);
    prototypes += f.prototype + "\n";
  }

  std::string out = "#include <Arduino.h>\n";
  for (std::size_t k = 0; k < files.size(); ++k) {
    const std::size_t begin = file_start[k];
    const std::size_t end = k + 1 < files.size() ? file_start[k + 1] : all.size();
    out += line_directive(1, files[k].path);
    // The prototypes go just before the first function definition (the
    // types and globals above it may appear in their signatures), or at
    // the end of the main file when it defines none.
    std::size_t at = end;
    if (k != 0 || prototypes.empty()) {
      out.append(all, begin, end - begin);
      continue;
    }
    if (!top.definitions.empty() && file_of(top.definitions.front().start) == 0)
      at = top.definitions.front().start;
    out.append(all, begin, at - begin);
    if (!out.empty() && out.back() != '\n') out += '\n';
    out += prototypes;
    if (at < end) {
      // Spaces keep the column of the first token, so diagnostics name it too.
      const std::size_t line_begin = at == 0 ? std::string::npos : all.rfind('\n', at - 1);
      const std::size_t column = line_begin == std::string::npos ? at : at - line_begin - 1;
      out += line_directive(line_of(at), files[0].path);
      out.append(column, ' ');
      out.append(all, at, end - at);
    }
  }
  return out;
}

}  // namespace hil::mocks::avr
