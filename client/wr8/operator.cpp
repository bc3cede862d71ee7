#include "client/wr8/operator.hpp"

#include <cstdint>
#include <stdexcept>
#include <utility>

#include "base/enum_names.hpp"
#include "client/common/operator_text.hpp"

namespace hil::client::wr8 {

namespace {

// Blanks between words; a `#` starts a comment only where a word would.
SplitLine words_of(std::string_view line) {
  return split_words(line, " \t\r\n", CommentStart::word_start);
}

std::optional<std::int32_t> parse_i32(std::string_view s) {
  const auto v = parse_integer(s, INT32_MIN, INT32_MAX);
  if (!v) return std::nullopt;
  return static_cast<std::int32_t>(v.value);
}

// "500ms", "1s", "1.5s", "2min": a non-negative number and a unit.
std::optional<Duration> parse_duration(std::string_view s) {
  return client::parse_duration(s, Duration(1'000'000'000'000'000'000));
}

ParsedLine fail(std::size_t column, std::string message) {
  return {std::nullopt, LineError{column, std::move(message)}};
}

ParsedLine ok(OperatorAction action) {
  return {std::move(action), std::nullopt};
}

constexpr std::string_view kVocabulary =
    "connect, disconnect, drive CM, turn DEG, task CODE [VALUE...], get-settings, "
    "set NAME=VALUE..., wait DURATION, wait-data";

// A signed whole number is the rest.
constexpr auto kWr8ValueTypeTexts =
    base::enum_names<proto::ValueType>({proto::ValueType::float32, "a number"},
                                       {proto::ValueType::unsigned_int, "a whole number >= 0"});

std::string value_type_text(proto::ValueType type) {
  return std::string(kWr8ValueTypeTexts.name(type, "a whole number"));
}

// The names `set` reads, as the CLI writes them.
constexpr auto kWr8SettingNames = base::enum_names<proto::SettingCode>(
    {proto::SettingCode::p, "p"}, {proto::SettingCode::i, "i"}, {proto::SettingCode::d, "d"},
    {proto::SettingCode::servo_zero, "servo-zero"});

std::string setting_name(proto::SettingCode code) {
  if (const auto name = kWr8SettingNames.find(code)) return std::string(*name);
  return std::to_string(static_cast<int>(code));
}

}  // namespace

std::string first_word(std::string_view line) {
  const auto split = words_of(line);
  return split.words.empty() ? std::string() : to_lower(split.words.front().text);
}

ParsedLine parse_operator_line(std::string_view line, const proto::Profile& profile) {
  const auto split = words_of(line);
  const auto& tokens = split.words;
  if (tokens.empty()) return {};
  const std::string verb = to_lower(tokens[0].text);
  const std::size_t end_column = line.size() + 1;
  auto no_more = [&](std::size_t from, std::string_view what) -> std::optional<LineError> {
    if (tokens.size() > from)
      return LineError{tokens[from].column, "unexpected '" + std::string(tokens[from].text) +
                                                "' after " + std::string(what)};
    return std::nullopt;
  };
  auto bare = [&](OperatorAction action) -> ParsedLine {
    if (auto e = no_more(1, verb)) return {std::nullopt, e};
    return ok(std::move(action));
  };
  auto one_int = [&](std::string_view what) -> std::variant<std::int32_t, LineError> {
    if (tokens.size() < 2)
      return LineError{end_column, "expected " + std::string(what) + " after " + verb};
    const auto v = parse_i32(tokens[1].text);
    if (!v)
      return LineError{tokens[1].column, "expected " + std::string(what) +
                                             " (a whole number), got '" +
                                             std::string(tokens[1].text) + "'"};
    if (auto e = no_more(2, verb + " " + std::string(tokens[1].text))) return *e;
    return *v;
  };

  if (verb == "connect") return bare(op::Connect{});
  if (verb == "disconnect") return bare(op::Disconnect{});
  if (verb == "get-settings") return bare(op::GetSettings{});
  if (verb == "wait-data") return bare(op::WaitData{});
  if (verb == "drive" || verb == "turn") {
    const auto r = one_int(verb == "drive" ? "a distance in cm" : "an angle in degrees");
    if (const auto* e = std::get_if<LineError>(&r)) return {std::nullopt, *e};
    const std::int32_t v = std::get<std::int32_t>(r);
    if (verb == "drive") return ok(op::Drive{v});
    return ok(op::Turn{v});
  }
  if (verb == "wait") {
    if (tokens.size() < 2) return fail(end_column, "expected a duration after wait (500ms, 1s)");
    const auto d = parse_duration(tokens[1].text);
    if (!d)
      return fail(tokens[1].column, "expected a duration such as 500ms, 1s or 1.5s, got '" +
                                        std::string(tokens[1].text) + "'");
    if (auto e = no_more(2, "the duration")) return {std::nullopt, e};
    return ok(op::Wait{*d});
  }
  if (verb == "task") {
    if (tokens.size() < 2)
      return fail(end_column,
                  "expected a task code after task (check, drive, turn, blink, get-settings or "
                  "0..4)");
    const auto code = proto::parse_task(tokens[1].text);
    if (!code)
      return fail(tokens[1].column,
                  "expected a task code (check, drive, turn, blink, get-settings or 0..4), got '" +
                      std::string(tokens[1].text) + "'");
    const auto type = profile.task_value_type[static_cast<std::size_t>(*code)];
    op::RawTask task{*code, {}};
    for (std::size_t i = 2; i < tokens.size(); ++i) {
      const auto w = proto::parse_value(tokens[i].text, type);
      if (!w)
        return fail(tokens[i].column, "expected a parameter value (" + value_type_text(type) +
                                          ", or 0x and up to 8 hex digits), got '" +
                                          std::string(tokens[i].text) + "'");
      task.params.push_back(*w);
    }
    return ok(std::move(task));
  }
  if (verb == "set") {
    if (tokens.size() < 2)
      return fail(end_column,
                  "expected NAME=VALUE after set (names " + kWr8SettingNames.list() + ")");
    op::SetSettings set;
    for (std::size_t i = 1; i < tokens.size(); ++i) {
      const std::string_view t = tokens[i].text;
      const auto eq = t.find('=');
      if (eq == std::string_view::npos)
        return fail(tokens[i].column, "expected NAME=VALUE, got '" + std::string(t) + "'");
      const auto code = proto::parse_setting(t.substr(0, eq));
      if (!code)
        return fail(tokens[i].column, "expected a setting name (" + kWr8SettingNames.list() +
                                          " or 0..3), got '" + std::string(t.substr(0, eq)) + "'");
      const auto type = profile.setting_value_type[static_cast<std::size_t>(*code)];
      const auto w = proto::parse_value(t.substr(eq + 1), type);
      if (!w)
        return fail(tokens[i].column + eq + 1, "expected a value for " + setting_name(*code) +
                                                   " (" + value_type_text(type) + "), got '" +
                                                   std::string(t.substr(eq + 1)) + "'");
      set.settings.push_back({*code, *w});
    }
    return ok(std::move(set));
  }
  return fail(tokens[0].column, word_not_in_profile(tokens[0].text, "document", kVocabulary));
}

std::string word_not_in_profile(std::string_view word, std::string_view profile,
                                std::string_view vocabulary) {
  struct Owner {
    std::string_view word;
    std::string_view profiles;
  };
  static constexpr Owner kOwners[] = {
      {"drive", "document"},
      {"turn", "document"},
      {"task", "document"},
      {"get-settings", "document"},
      {"forward", "svgui-2019"},
      {"wheels", "svgui-2019"},
      {"signals", "svgui-2019"},
      {"settings", "svgui-2019"},
      {"control", "svgui-head"},
      {"set-request", "svgui-head"},
      {"set", "document and svgui-head"},
  };
  const std::string lower = to_lower(word);
  for (const auto& o : kOwners) {
    if (o.word == lower) {
      return "'" + std::string(word) + "' is not a word of profile " + std::string(profile) + " (" +
             std::string(o.profiles) + " only); " + std::string(profile) + " takes " +
             std::string(vocabulary);
    }
  }
  return "unknown action '" + std::string(word) + "'; expected " + std::string(vocabulary);
}

Script parse_operator_script(std::string_view text, std::string file,
                             const proto::Profile& profile) {
  return parse_script_lines<Script>(
      text, file, [&](std::string_view line) { return parse_operator_line(line, profile); });
}

std::string refusal_text(Refusal refusal) {
  std::string why(to_string(refusal));
  for (char& c : why)
    if (c == '_') c = ' ';
  return "refused: " + why;
}

std::string format_settings(const std::vector<proto::Setting>& settings,
                            const proto::Profile& profile) {
  std::string out;
  for (const auto& s : settings) {
    if (!out.empty()) out += ' ';
    out +=
        setting_name(s.code) + "=" +
        proto::format_value(s.value, profile.setting_value_type[static_cast<std::size_t>(s.code)]);
  }
  return out;
}

std::string to_text(const OperatorAction& action, const proto::Profile& profile) {
  return std::visit(
      Overloaded{
          [](const op::Connect&) -> std::string { return "connect"; },
          [](const op::Disconnect&) -> std::string { return "disconnect"; },
          [](const op::Drive& a) { return "drive " + std::to_string(a.distance_cm); },
          [](const op::Turn& a) { return "turn " + std::to_string(a.angle_deg); },
          [&](const op::RawTask& a) {
            std::string out = "task " + std::string(proto::to_string(a.code));
            const auto type = profile.task_value_type[static_cast<std::size_t>(a.code)];
            for (const auto& w : a.params)
              out += " " + proto::format_value(w, type);
            return out;
          },
          [](const op::GetSettings&) -> std::string { return "get-settings"; },
          [&](const op::SetSettings& a) { return "set " + format_settings(a.settings, profile); },
          [](const op::Wait& a) { return "wait " + duration_text(a.duration); },
          [](const op::WaitData&) -> std::string { return "wait-data"; },
      },
      action);
}

// ---- runner ----

void OperatorRunner::execute(OperatorAction action, Done done) {
  if (begin(std::move(action), std::move(done))) return;
  std::visit(
      Overloaded{
          [&](const op::Drive& a) { start_request(session_.drive(a.distance_cm)); },
          [&](const op::Turn& a) { start_request(session_.turn(a.angle_deg)); },
          [&](const op::RawTask& a) { start_request(session_.task(a.code, a.params)); },
          [&](const op::GetSettings&) { start_request(session_.get_settings()); },
          [&](const op::SetSettings& a) { start_request(session_.set_settings(a.settings)); },
          [](const auto&) {},  // the shared words, which begin() carried out
      },
      current_->action);
}

void OperatorRunner::start_request(SubmitResult submitted) {
  if (!submitted) {
    refuse(submitted.refusal);
    return;
  }
  current_->pending.coi = submitted.coi;
}

void OperatorRunner::on_request(const RequestEvent& r) {
  if (!current_ || !current_->pending.coi || *current_->pending.coi != r.coi) return;
  const auto& config = session_.core().config();
  RequestWait& wait = current_->pending;
  switch (r.state) {
    case RequestState::sent:
      return;
    case RequestState::started:
      wait.started = true;
      return;
    case RequestState::completed: {
      std::string detail = "completed";
      if (!wait.settings.empty()) detail = format_settings(wait.settings, config.profile);
      finish(true, detail);
      return;
    }
    case RequestState::error:
      finish(false, "the vehicle answered error");
      return;
    case RequestState::timed_out: {
      if (wait.started || !wait.settings.empty()) {
        const Duration limit = r.kind == RequestKind::task
                                   ? config.completion_timeout[static_cast<std::size_t>(r.task)]
                                   : config.answer_timeout;
        finish(false, "started but not completed within " + duration_text(limit));
      } else {
        finish(false, "no answer within " + duration_text(config.answer_timeout));
      }
      return;
    }
    case RequestState::cancelled:
      finish(false, "the connection ended before the answer");
      return;
  }
}

void OperatorRunner::on_event(Time, const Event& event) {
  dispatch(event, Overloaded{
                      [&](const TelemetryEvent& e) {
                        on_data("DATA " + std::string(proto::to_string(e.live.state)) + " at " +
                                std::to_string(e.live.timestamp_ms) + " ms");
                      },
                      [&](const SettingsEvent& e) {
                        RequestWait& wait = current_->pending;
                        if (wait.coi && *wait.coi == e.coi) wait.settings = e.settings;
                      },
                      [&](const RequestEvent& r) { on_request(r); },
                  });
}

}  // namespace hil::client::wr8
