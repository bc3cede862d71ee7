#include "client/leka/operator.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <utility>

#include "client/common/operator_text.hpp"

namespace hil::client::leka {

namespace {

struct Token {
  std::string text;
  std::size_t column = 1;  // 1-based
};

// One command's words, and where the command ends (for "expected ..." errors).
struct CommandWords {
  std::vector<Token> words;
  std::size_t column = 1;
  std::size_t end_column = 1;
};

// What a value is, for its range and its error message.
struct ArgSpec {
  std::string_view name;
  int lo;
  int hi;
  bool spin = false;  // also takes forward / backward
};

std::string range_text(const ArgSpec& a) {
  if (a.spin) return "0 (forward) or 1 (backward)";
  auto hex = [](int v) {
    static const char* digits = "0123456789ABCDEF";
    std::string s = "0x";
    s += digits[(v >> 4) & 0xF];
    s += digits[v & 0xF];
    return s;
  };
  if (a.lo >= 0x40) return hex(a.lo) + ".." + hex(a.hi);
  return std::to_string(a.lo) + ".." + std::to_string(a.hi);
}

std::optional<int> parse_int(std::string_view text) {
  const auto v = parse_integer(text, INT32_MIN, INT32_MAX,
                               {.plus = false, .minus = true, .hex = true, .max_digits = 9});
  if (!v) return std::nullopt;
  return static_cast<int>(v.value);
}

// At most an hour, to the microsecond the robot's pacing can keep.
std::optional<Duration> parse_wait(std::string_view text) {
  const auto d = parse_duration(text, link::seconds(3600));
  if (!d) return std::nullopt;
  return std::chrono::round<std::chrono::microseconds>(*d);
}

// Splits a line into commands at ';', words at blanks, stopping at '#'.
// Dotted names ("led.belt.single") become separate words at the same column.
std::vector<CommandWords> split_commands(std::string_view text) {
  text = text.substr(0, text.find('#'));
  std::vector<CommandWords> commands;
  std::size_t start = 0;  // where the command's text begins
  for (;;) {
    const std::size_t semicolon = std::min(text.find(';', start), text.size());
    const auto split = split_words(text.substr(start, semicolon - start), " \t\r\n");
    CommandWords& c = commands.emplace_back();
    for (const Word& w : split.words) {
      const std::size_t column = start + w.column;
      const bool dotted =
          w.text.find('.') != std::string_view::npos && !(w.text[0] >= '0' && w.text[0] <= '9');
      if (!dotted) {
        c.words.push_back({std::string(w.text), column});
        continue;
      }
      for (std::size_t from = 0; from <= w.text.size();) {
        const std::size_t dot = std::min(w.text.find('.', from), w.text.size());
        c.words.push_back({std::string(w.text.substr(from, dot - from)), column});
        from = dot + 1;
      }
    }
    if (!c.words.empty()) {
      c.column = c.words.front().column;
      c.end_column = start + split.end_column;
    } else {
      // An empty command is pointed at by its ';', or just past the last one.
      c.column = start + 1;
      c.end_column = semicolon < text.size() ? semicolon + 1 : start + 1;
    }
    if (semicolon >= text.size()) break;
    start = semicolon + 1;
  }
  return commands;
}

constexpr std::string_view kCommandList =
    "info, stop, ear, belt, motor, motivator, guidance or wait";

// One command parsed: its builder call, or an error.
class CommandParser {
 public:
  CommandParser(const proto::ValueLimits& limits, GroupBuilder& builder)
      : limits_(limits), builder_(builder) {}

  // Adds the command to the builder; an error if it is wrong.
  std::optional<OperatorError> parse(const CommandWords& c) {
    words_ = &c;
    pos_ = 0;
    std::string head = next_word();
    if (head == "led") {
      if (pos_ >= c.words.size()) return OperatorError{c.end_column, "led: expected ear or belt"};
      head = next_word();
      if (head != "ear" && head != "belt")
        return OperatorError{at(pos_ - 1), "led: expected ear or belt, got '" + head + "'"};
    }
    if (head == "info")
      return finish("info", {}, [&](const std::vector<int>&) { builder_.info(); });
    if (head == "stop") {
      auto sub = subcommand("stop", {"led", "motor", "robot"});
      if (auto* e = std::get_if<OperatorError>(&sub)) return *e;
      const std::string what = std::get<std::string>(sub);
      return finish("stop " + what, {}, [&](const std::vector<int>&) {
        if (what == "led") builder_.stop_led();
        if (what == "motor") builder_.stop_motor();
        if (what == "robot") builder_.stop_robot();
      });
    }
    if (head == "ear") {
      auto sub = subcommand("ear", {"all", "single"});
      if (auto* e = std::get_if<OperatorError>(&sub)) return *e;
      if (std::get<std::string>(sub) == "all")
        return finish("ear all", rgb({}),
                      [&](const std::vector<int>& v) { builder_.ear_all(color(v, 0)); });
      return finish("ear single", rgb({{"led", 0, 1}}),
                    [&](const std::vector<int>& v) { builder_.ear_single(v[0], color(v, 1)); });
    }
    if (head == "belt") {
      const int max = limits_.max_belt_led_id;
      auto sub = subcommand("belt", {"all", "range", "single"});
      if (auto* e = std::get_if<OperatorError>(&sub)) return *e;
      const std::string what = std::get<std::string>(sub);
      if (what == "all")
        return finish("belt all", rgb({}),
                      [&](const std::vector<int>& v) { builder_.belt_all(color(v, 0)); });
      if (what == "range")
        return finish(
            "belt range", rgb({{"first", 0, max}, {"last", 0, max}}),
            [&](const std::vector<int>& v) { builder_.belt_range(v[0], v[1], color(v, 2)); });
      return finish("belt single", rgb({{"led", 0, max}}),
                    [&](const std::vector<int>& v) { builder_.belt_single(v[0], color(v, 1)); });
    }
    if (head == "motor") {
      auto sub = subcommand("motor", {"all", "duo", "left", "right"});
      if (auto* e = std::get_if<OperatorError>(&sub)) return *e;
      const std::string what = std::get<std::string>(sub);
      const ArgSpec speed{"speed", 0, 255};
      if (what == "all")
        return finish("motor all", {{"direction", 0, 1, true}, speed},
                      [&](const std::vector<int>& v) { builder_.motor_all(v[0], v[1]); });
      if (what == "duo")
        return finish(
            "motor duo",
            {{"left_spin", 0, 1, true},
             {"left_speed", 0, 255},
             {"right_spin", 0, 1, true},
             {"right_speed", 0, 255}},
            [&](const std::vector<int>& v) { builder_.motor_duo(v[0], v[1], v[2], v[3]); });
      if (what == "left")
        return finish("motor left", {{"spin", 0, 1, true}, speed},
                      [&](const std::vector<int>& v) { builder_.motor_left(v[0], v[1]); });
      return finish("motor right", {{"spin", 0, 1, true}, speed},
                    [&](const std::vector<int>& v) { builder_.motor_right(v[0], v[1]); });
    }
    if (head == "motivator")
      return finish("motivator", {{"id", 0x51, 0x55}},
                    [&](const std::vector<int>& v) { builder_.motivator(v[0]); });
    if (head == "guidance")
      return finish("guidance", {{"id", 0x41, 0x4F}},
                    [&](const std::vector<int>& v) { builder_.guidance(v[0]); });
    if (head == "wait") return OperatorError{c.column, "wait must be alone on its line"};
    return OperatorError{
        c.column, "unknown command '" + head + "' (expected " + std::string(kCommandList) + ")"};
  }

 private:
  std::string next_word() { return words_->words[pos_++].text; }
  std::size_t at(std::size_t index) const { return words_->words[index].column; }

  std::variant<std::string, OperatorError> subcommand(const std::string& what,
                                                      std::vector<std::string_view> options) {
    std::string list;
    for (std::size_t i = 0; i < options.size(); ++i)
      list += (i == 0 ? "" : i + 1 == options.size() ? " or " : ", ") + std::string(options[i]);
    if (pos_ >= words_->words.size())
      return OperatorError{words_->end_column, what + ": expected " + list};
    const std::string word = next_word();
    if (std::find(options.begin(), options.end(), word) == options.end())
      return OperatorError{at(pos_ - 1), what + ": expected " + list + ", got '" + word + "'"};
    return word;
  }

  static std::vector<ArgSpec> rgb(std::vector<ArgSpec> before) {
    before.push_back({"red", 0, 255});
    before.push_back({"green", 0, 255});
    before.push_back({"blue", 0, 255});
    return before;
  }
  static proto::Rgb color(const std::vector<int>& v, std::size_t from) {
    return {static_cast<std::uint8_t>(v[from]), static_cast<std::uint8_t>(v[from + 1]),
            static_cast<std::uint8_t>(v[from + 2])};
  }

  template <class Add>
  std::optional<OperatorError> finish(const std::string& name, std::vector<ArgSpec> args, Add add) {
    std::vector<int> values;
    for (std::size_t k = 0; k < args.size(); ++k) {
      ArgSpec spec = args[k];
      // A range's last LED is checked against its first.
      if (name == "belt range" && spec.name == "last") spec.lo = values[0];
      if (pos_ >= words_->words.size()) {
        std::string takes;
        for (const auto& a : args)
          takes += " " + std::string(a.name);
        return OperatorError{words_->end_column, name + ": expected " + std::string(spec.name) +
                                                     " (" + range_text(spec) + "); it takes" +
                                                     takes};
      }
      const Token& token = words_->words[pos_++];
      std::optional<int> value;
      if (spec.spin && (token.text == "forward" || token.text == "fwd")) value = 0;
      if (spec.spin && (token.text == "backward" || token.text == "back")) value = 1;
      if (!value) value = parse_int(token.text);
      if (!value)
        return OperatorError{token.column, name + ": " + std::string(spec.name) +
                                               " must be a number " + range_text(spec) + ", got '" +
                                               token.text + "'"};
      if (*value < spec.lo || *value > spec.hi)
        return OperatorError{token.column, name + ": " + std::string(spec.name) + " must be " +
                                               range_text(spec) + ", got " + token.text};
      values.push_back(*value);
    }
    if (pos_ < words_->words.size()) {
      const Token& extra = words_->words[pos_];
      std::string takes;
      for (const auto& a : args)
        takes += " " + std::string(a.name);
      return OperatorError{extra.column, name + ": unexpected '" + extra.text + "'; it takes" +
                                             (args.empty() ? std::string(" nothing") : takes)};
    }
    const BuildResult before = builder_.result();
    add(values);
    const BuildResult after = builder_.result();
    // The checks above mirror the builder's; should they ever differ, the
    // builder has the last word.
    if (before.error != BuildError::out_of_range && after.error == BuildError::out_of_range)
      return OperatorError{words_->column, name + ": " + after.field + " is out of range"};
    return std::nullopt;
  }

  const proto::ValueLimits& limits_;
  GroupBuilder& builder_;
  const CommandWords* words_ = nullptr;
  std::size_t pos_ = 0;
};

template <class Parse>
Script parse_each(const std::vector<std::string_view>& texts, const std::string& source,
                  Parse parse) {
  Script script;
  script.source = source;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    auto parsed = parse(texts[i]);
    if (parsed.error) {
      script.errors.push_back({source, i + 1, parsed.error->column, parsed.error->message});
      continue;
    }
    if (!parsed.action) continue;
    // The line as shown in results: without its comment or trailing blanks.
    std::string text(trim_end(texts[i].substr(0, texts[i].find('#')), " \t\r"));
    script.lines.push_back({i + 1, std::move(text), std::move(*parsed.action)});
  }
  return script;
}

ParseResult<OperatorLine> error_at(std::size_t column, std::string message) {
  return {.action = std::nullopt, .error = OperatorError{column, std::move(message)}};
}

}  // namespace

ParseResult<OperatorLine> parse_operator_line(std::string_view text,
                                              const proto::ValueLimits& limits) {
  auto commands = split_commands(text);
  OperatorLine line;
  const bool all_empty = std::all_of(commands.begin(), commands.end(),
                                     [](const CommandWords& c) { return c.words.empty(); });
  if (all_empty && commands.size() == 1) return {};
  // wait stands alone.
  if (commands.size() == 1 && commands[0].words[0].text == "wait") {
    const auto& words = commands[0].words;
    if (words.size() < 2)
      return error_at(commands[0].end_column, "wait: expected a duration such as 500ms or 1s");
    if (words.size() > 2)
      return error_at(words[2].column, "wait: unexpected '" + words[2].text +
                                           "'; it takes one duration such as 500ms or 1s");
    const auto d = parse_wait(words[1].text);
    if (!d)
      return error_at(words[1].column,
                      "wait: expected a duration such as 500ms or 1s "
                      "(at most 3600s), got '" +
                          words[1].text + "'");
    line.kind = OperatorLine::Kind::wait;
    line.wait = *d;
    return {.action = std::move(line), .error = std::nullopt};
  }
  line.kind = OperatorLine::Kind::group;
  GroupBuilder builder(limits);
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const auto& c = commands[i];
    if (c.words.empty()) {
      return error_at(c.end_column, i + 1 == commands.size() ? "expected a command after ';'"
                                                             : "expected a command before ';'");
    }
    if (c.words[0].text == "info" && c.words.size() == 1) {
      if (!builder.group().commands.empty())
        line.parts.emplace_back(std::exchange(builder, GroupBuilder(limits)));
      line.parts.emplace_back(InfoPart{c.column});
      ++line.commands;
      continue;
    }
    CommandParser parser(limits, builder);
    if (auto error = parser.parse(c)) return {.action = std::nullopt, .error = std::move(*error)};
    ++line.commands;
  }
  if (!builder.group().commands.empty()) line.parts.emplace_back(std::move(builder));
  return {.action = std::move(line), .error = std::nullopt};
}

Script parse_script(std::string_view text, const std::string& source,
                    const proto::ValueLimits& limits) {
  return parse_each(split_lines(text), source,
                    [&](std::string_view line) { return parse_operator_line(line, limits); });
}

Script parse_lines(const std::vector<std::string>& lines, const std::string& source,
                   const proto::ValueLimits& limits) {
  std::vector<std::string_view> views(lines.begin(), lines.end());
  return parse_each(views, source,
                    [&](std::string_view line) { return parse_operator_line(line, limits); });
}

std::vector<Bytes> frames_of(const OperatorLine& line, const ClientConfig& config) {
  // The core's own limit (it caps what the config asks for).
  const std::size_t max_group =
      LekaClientCore(config).config().max_frame_bytes - proto::kOverheadBytes;
  std::vector<Bytes> frames;
  for (const auto& part : line.parts) {
    if (const auto* builder = std::get_if<GroupBuilder>(&part)) {
      for (auto& f : split_frames(builder->group(), max_group, config.dialect))
        frames.push_back(std::move(f));
    } else {
      frames.push_back(proto::encode(proto::CommandGroup{{proto::Info{}}}, {}, config.dialect));
    }
  }
  return frames;
}

// ------------------------------------------------------------------ runner

OperatorRunner::OperatorRunner(link::Executor& executor, LekaSession& session)
    : executor_(executor), session_(session) {}

OperatorRunner::~OperatorRunner() {
  *alive_ = false;
  cancel();
}

void OperatorRunner::run(Script script, LineCallback on_line, DoneCallback on_done) {
  cancel();
  script_ = std::move(script);
  index_ = 0;
  on_line_ = std::move(on_line);
  on_done_ = std::move(on_done);
  running_ = true;
  next();
}

void OperatorRunner::cancel() {
  running_ = false;
  ++generation_;
  if (timer_ != 0) executor_.cancel(timer_);
  timer_ = 0;
}

void OperatorRunner::next() {
  if (!running_) return;
  if (index_ >= script_.lines.size()) {
    running_ = false;
    if (on_done_) on_done_(true);
    return;
  }
  const ScriptLine& line = script_.lines[index_];
  current_ = LineResult{};
  current_.number = line.number;
  current_.text = line.text;
  current_.started = executor_.now();
  ++generation_;
  if (line.line.kind == OperatorLine::Kind::wait) {
    timer_ = executor_.call_after(line.line.wait, [this, alive = alive_, g = generation_] {
      if (!*alive || g != generation_) return;
      timer_ = 0;
      if (!session_.is_open()) return finish(false, "the port closed");
      finish(true);
    });
    return;
  }
  start_group(line);
}

void OperatorRunner::start_group(const ScriptLine& line) {
  if (!session_.is_open()) return finish(false, "the port is not open");
  const auto frames = frames_of(line.line, session_.core().config());
  current_.frames = frames.size();
  for (const auto& f : frames)
    current_.bytes += f.size();
  infos_waiting_ = 0;
  const std::uint64_t g = generation_;
  // Replies land in the order asked; slots keep that order in the result.
  auto slots = std::make_shared<std::vector<std::optional<InfoReply>>>();
  for (const auto& part : line.line.parts) {
    if (const auto* builder = std::get_if<GroupBuilder>(&part)) {
      const BuildResult r = session_.send(*builder);
      if (!r.ok()) return finish(false, "refused by the client: " + r.field);
      continue;
    }
    const std::size_t slot = slots->size();
    slots->emplace_back();
    ++infos_waiting_;
    session_.info([this, alive = alive_, g, slot, slots](const InfoResult& r) {
      if (!*alive || g != generation_ || !running_) return;
      if (r.status == InfoStatus::timeout)
        return finish(false, "info: no answer within " +
                                 std::to_string(std::chrono::duration_cast<link::milliseconds>(
                                                    session_.core().config().info_timeout)
                                                    .count()) +
                                 " ms");
      if (r.status == InfoStatus::closed)
        return finish(false, "info: the port closed before the answer");
      (*slots)[slot] = r.reply;
      if (--infos_waiting_ == 0) {
        for (auto& s : *slots)
          if (s) current_.infos.push_back(*s);
        check_group();
      }
    });
  }
  // Let the session's own work at this instant run first.
  timer_ = executor_.post([this, alive = alive_, g] {
    if (!*alive || g != generation_) return;
    timer_ = 0;
    check_group();
  });
}

void OperatorRunner::check_group() {
  if (!running_) return;
  if (!session_.is_open()) return finish(false, "the port closed");
  if (session_.core().queued_frames() > 0) {
    // Look again when the session's pacing timer has let the next frame go.
    if (timer_ != 0) return;
    const auto due = session_.core().next_wakeup().value_or(executor_.now());
    timer_ =
        executor_.call_at(std::max(due, executor_.now()), [this, alive = alive_, g = generation_] {
          if (!*alive || g != generation_) return;
          timer_ = 0;
          check_group();
        });
    return;
  }
  if (infos_waiting_ > 0) return;
  finish(true);
}

void OperatorRunner::finish(bool ok, std::string error) {
  if (!running_) return;
  if (timer_ != 0) executor_.cancel(timer_);
  timer_ = 0;
  ++generation_;
  current_.ok = ok;
  current_.error = std::move(error);
  current_.finished = executor_.now();
  const LineResult result = current_;
  if (on_line_) on_line_(result);
  if (!ok) {
    running_ = false;
    if (on_done_) on_done_(false);
    return;
  }
  ++index_;
  next();
}

}  // namespace hil::client::leka
