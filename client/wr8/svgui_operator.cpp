#include "client/wr8/svgui_operator.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "client/common/operator_text.hpp"

namespace hil::client::wr8 {

namespace {

using svgui::Version;

constexpr std::string_view kVocabulary2019 =
    "connect, disconnect, forward CM, wheels DEG, signals, settings p=P i=I d=D servo-zero=Z, "
    "wait DURATION, wait-data";
constexpr std::string_view kVocabularyHead =
    "connect, disconnect, control X Y, control off, set NAME=VALUE..., set-request, "
    "wait DURATION, wait-data";

ParsedSvguiLine svgui_fail(std::size_t column, std::string message) {
  return {std::nullopt, LineError{column, std::move(message)}};
}

ParsedSvguiLine svgui_ok(SvguiAction action) {
  return {std::move(action), std::nullopt};
}

/// A decimal number such as 0.5, -1 or 1e-3; nothing else (no inf, nan, hex).
std::optional<double> parse_real(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  for (const char c : s) {
    const bool ok = (c >= '0' && c <= '9') || c == '.' || c == '-' || c == 'e' || c == 'E';
    if (!ok) return std::nullopt;
  }
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// The shortest text that reads back as exactly `v`.
std::string real_text(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc{} ? std::string(buf, end) : std::string("?");
}

std::optional<std::size_t> set_index(std::string_view name) {
  const std::string lower = to_lower(name);
  for (std::size_t i = 0; i < svgui::kSetNames.size(); ++i) {
    if (svgui::kSetNames[i] == lower) return i;
  }
  return std::nullopt;
}

std::string set_names() {
  std::string out;
  for (const auto name : svgui::kSetNames) {
    if (!out.empty()) out += ", ";
    out += name;
  }
  return out;
}

constexpr std::array<std::string_view, 4> kSettingsNames = {"p", "i", "d", "servo-zero"};

// Words and their columns, as the document vocabulary splits them.
struct Line {
  std::vector<Word> words;
  std::size_t end_column = 1;
  std::string verb;
};

Line split(std::string_view line) {
  auto s = split_words(line, " \t\r\n", CommentStart::word_start);
  Line out{std::move(s.words), line.size() + 1, {}};
  if (!out.words.empty()) out.verb = to_lower(out.words[0].text);
  return out;
}

std::optional<LineError> nothing_after(const Line& l, std::size_t from, std::string_view what) {
  if (l.words.size() <= from) return std::nullopt;
  return LineError{l.words[from].column, "unexpected '" + std::string(l.words[from].text) +
                                             "' after " + std::string(what)};
}

/// `verb N`: one whole number.
std::variant<std::int32_t, LineError> one_int(const Line& l, std::string_view what) {
  if (l.words.size() < 2)
    return LineError{l.end_column, "expected " + std::string(what) + " after " + l.verb};
  const auto v = parse_integer(l.words[1].text, INT32_MIN, INT32_MAX);
  if (!v)
    return LineError{l.words[1].column, "expected " + std::string(what) +
                                            " (a whole number), got '" +
                                            std::string(l.words[1].text) + "'"};
  if (auto e = nothing_after(l, 2, l.verb + " " + std::string(l.words[1].text))) return *e;
  return static_cast<std::int32_t>(v.value);
}

ParsedSvguiLine parse_settings_2019(const Line& l) {
  op::Settings2019 settings;
  std::array<bool, 4> given{};
  for (std::size_t i = 1; i < l.words.size(); ++i) {
    const std::string_view t = l.words[i].text;
    const auto eq = t.find('=');
    if (eq == std::string_view::npos)
      return svgui_fail(l.words[i].column, "expected NAME=VALUE, got '" + std::string(t) + "'");
    const std::string name = to_lower(t.substr(0, eq));
    std::size_t k = 0;
    while (k < kSettingsNames.size() && kSettingsNames[k] != name)
      ++k;
    if (k == kSettingsNames.size())
      return svgui_fail(l.words[i].column,
                        "expected a setting name (p, i, d or servo-zero), got '" +
                            std::string(t.substr(0, eq)) + "'");
    const auto v = parse_integer(t.substr(eq + 1), INT32_MIN, INT32_MAX);
    if (!v)
      return svgui_fail(l.words[i].column + eq + 1, "expected a whole number for " + name +
                                                        " (the packet carries int32), got '" +
                                                        std::string(t.substr(eq + 1)) + "'");
    settings.values[k] = static_cast<std::int32_t>(v.value);
    given[k] = true;
  }
  for (std::size_t k = 0; k < given.size(); ++k) {
    if (!given[k])
      return svgui_fail(l.end_column,
                        "settings needs all of p, i, d and servo-zero (the packet "
                        "carries all four); " +
                            std::string(kSettingsNames[k]) + " is missing");
  }
  return svgui_ok(settings);
}

ParsedSvguiLine parse_control(const Line& l) {
  if (l.words.size() == 2 && to_lower(l.words[1].text) == "off") return svgui_ok(op::ControlOff{});
  double axes[2] = {0, 0};
  const char* what[2] = {"the x axis (steering)", "the y axis (engine)"};
  for (std::size_t i = 0; i < 2; ++i) {
    if (l.words.size() < i + 2)
      return svgui_fail(l.end_column, "expected " + std::string(what[i]) +
                                          ", a number from -1 to 1, after control" +
                                          (i == 0 ? " (or 'off')" : ""));
    const auto v = parse_real(l.words[i + 1].text);
    if (!v || *v < -1.0 || *v > 1.0)
      return svgui_fail(l.words[i + 1].column, "expected " + std::string(what[i]) +
                                                   ", a number from -1 to 1, got '" +
                                                   std::string(l.words[i + 1].text) + "'");
    axes[i] = *v;
  }
  if (auto e = nothing_after(l, 3, "the two axes")) return {std::nullopt, e};
  return svgui_ok(op::Control{axes[0], axes[1]});
}

ParsedSvguiLine parse_set(const Line& l) {
  if (l.words.size() < 2)
    return svgui_fail(l.end_column, "expected NAME=VALUE after set (names " + set_names() + ")");
  op::Set set;
  for (std::size_t i = 1; i < l.words.size(); ++i) {
    const std::string_view t = l.words[i].text;
    const auto eq = t.find('=');
    if (eq == std::string_view::npos)
      return svgui_fail(l.words[i].column, "expected NAME=VALUE, got '" + std::string(t) + "'");
    const auto index = set_index(t.substr(0, eq));
    if (!index)
      return svgui_fail(l.words[i].column, "expected a setting name (" + set_names() + "), got '" +
                                               std::string(t.substr(0, eq)) + "'");
    const auto v = parse_real(t.substr(eq + 1));
    if (!v)
      return svgui_fail(l.words[i].column + eq + 1,
                        "expected a number for " + std::string(svgui::kSetNames[*index]) +
                            ", got '" + std::string(t.substr(eq + 1)) + "'");
    set.values.emplace_back(*index, *v);
  }
  return svgui_ok(std::move(set));
}

}  // namespace

std::string_view svgui_vocabulary(svgui::Version version) {
  return version == Version::v2019 ? kVocabulary2019 : kVocabularyHead;
}

ParsedSvguiLine parse_svgui_line(std::string_view text, svgui::Version version) {
  const Line l = split(text);
  if (l.words.empty()) return {};
  const std::string_view profile = svgui::profile_of(version);
  const auto not_here = [&] {
    return svgui_fail(l.words[0].column,
                      word_not_in_profile(l.words[0].text, profile, svgui_vocabulary(version)));
  };
  // The shared words read as the document vocabulary reads them.
  if (l.verb == "connect" || l.verb == "disconnect" || l.verb == "wait" || l.verb == "wait-data") {
    auto parsed = parse_operator_line(text);
    if (parsed.error) return {std::nullopt, parsed.error};
    return std::visit(
        Overloaded{
            [](const op::Connect& a) { return svgui_ok(a); },
            [](const op::Disconnect& a) { return svgui_ok(a); },
            [](const op::Wait& a) { return svgui_ok(a); },
            [](const op::WaitData& a) { return svgui_ok(a); },
            [](const auto&) { return ParsedSvguiLine{}; },  // not reached: the verb decides
        },
        *parsed.action);
  }
  if (version == Version::v2019) {
    if (l.verb == "forward" || l.verb == "wheels") {
      const auto r = one_int(l, l.verb == "forward" ? "a distance in cm" : "an angle in degrees");
      if (const auto* e = std::get_if<LineError>(&r)) return {std::nullopt, *e};
      const std::int32_t v = std::get<std::int32_t>(r);
      if (l.verb == "forward") return svgui_ok(op::Forward{v});
      return svgui_ok(op::Wheels{v});
    }
    if (l.verb == "signals") {
      if (auto e = nothing_after(l, 1, "signals")) return {std::nullopt, e};
      return svgui_ok(op::Signals{});
    }
    if (l.verb == "settings") return parse_settings_2019(l);
    return not_here();
  }
  if (l.verb == "control") return parse_control(l);
  if (l.verb == "set") return parse_set(l);
  if (l.verb == "set-request") {
    if (auto e = nothing_after(l, 1, "set-request")) return {std::nullopt, e};
    return svgui_ok(op::SetRequest{});
  }
  return not_here();
}

SvguiScript parse_svgui_script(std::string_view text, std::string file, svgui::Version version) {
  return parse_script_lines<SvguiScript>(
      text, file, [&](std::string_view line) { return parse_svgui_line(line, version); });
}

std::string format_set(const svgui::Set& set) {
  std::string out;
  for (std::size_t i = 0; i < set.values.size(); ++i) {
    if (!out.empty()) out += ' ';
    out += std::string(svgui::kSetNames[i]) + "=" + real_text(set.values[i]);
  }
  return out;
}

std::string to_text(const SvguiAction& action) {
  return std::visit(
      Overloaded{
          [](const op::Connect&) -> std::string { return "connect"; },
          [](const op::Disconnect&) -> std::string { return "disconnect"; },
          [](const op::Wait& a) { return "wait " + duration_text(a.duration); },
          [](const op::WaitData&) -> std::string { return "wait-data"; },
          [](const op::Forward& a) { return "forward " + std::to_string(a.distance_cm); },
          [](const op::Wheels& a) { return "wheels " + std::to_string(a.angle_deg); },
          [](const op::Signals&) -> std::string { return "signals"; },
          [](const op::Settings2019& a) {
            std::string out = "settings";
            for (std::size_t k = 0; k < a.values.size(); ++k)
              out += " " + std::string(kSettingsNames[k]) + "=" + std::to_string(a.values[k]);
            return out;
          },
          [](const op::Control& a) {
            return "control " + real_text(a.x_axis) + " " + real_text(a.y_axis);
          },
          [](const op::ControlOff&) -> std::string { return "control off"; },
          [](const op::Set& a) {
            std::string out = "set";
            for (const auto& [i, v] : a.values)
              out += " " + std::string(svgui::kSetNames[i]) + "=" + real_text(v);
            return out;
          },
          [](const op::SetRequest&) -> std::string { return "set-request"; },
      },
      action);
}

// ---- runner ----

void SvguiRunner::execute(SvguiAction action, Done done) {
  if (begin(std::move(action), std::move(done))) return;
  const auto refused = [this](Refusal r) { refuse(r); };
  std::visit(
      Overloaded{
          [&](const op::Forward& a) {
            start_request(session_.forward(a.distance_cm), RequestKind::task,
                          proto::TaskCode::drive);
          },
          [&](const op::Wheels& a) {
            start_request(session_.wheels(a.angle_deg), RequestKind::task, proto::TaskCode::turn);
          },
          [&](const op::Signals&) {
            start_request(session_.signals(), RequestKind::task, proto::TaskCode::blink);
          },
          [&](const op::Settings2019& a) {
            const auto r = session_.settings(a.values);
            if (!r) {
              refused(r.refusal);
              return;
            }
            finish(true, "sent under COI " + std::to_string(r.coi) +
                             "; not confirmed: the v2019 vehicle never answers SETTINGS");
          },
          [&](const op::Control& a) {
            const Refusal r = session_.control(a.x_axis, a.y_axis);
            if (r != Refusal::none) {
              refused(r);
              return;
            }
            finish(true,
                   "held: CONTROL every " + duration_text(session_.core().config().control_period));
          },
          [&](const op::ControlOff&) {
            const bool held = session_.core().held_control().has_value();
            const Refusal r = session_.release_control();
            if (r != Refusal::none) {
              refused(r);
              return;
            }
            finish(true, held ? "released: CONTROL 0 0 sent" : "control was not held");
          },
          [&](const op::Set& a) { start_set(a); },
          [&](const op::SetRequest&) {
            start_request(session_.set_request(), RequestKind::task, proto::TaskCode::get_settings);
          },
          [](const auto&) {},  // the shared words, which begin() carried out
      },
      current_->action);
}

void SvguiRunner::start_set(const op::Set& set) {
  svgui::Set values;
  std::array<bool, 12> given{};
  for (const auto& [i, v] : set.values) {
    values.values[i] = v;
    given[i] = true;
  }
  const auto& known = session_.core().read_settings();
  for (std::size_t i = 0; i < given.size(); ++i) {
    if (given[i]) continue;
    if (!known) {
      finish(false, "set needs all twelve values, or a set-request first to fill the rest (" +
                        std::string(svgui::kSetNames[i]) + " is missing)");
      return;
    }
    values.values[i] = known->values[i];
  }
  start_request(session_.set(values), RequestKind::settings, proto::TaskCode::check);
}

void SvguiRunner::start_request(SubmitResult submitted, RequestKind kind, proto::TaskCode task) {
  if (!submitted) {
    refuse(submitted.refusal);
    return;
  }
  current_->pending = RequestEvent{submitted.coi, kind, task, RequestState::sent, {}};
}

void SvguiRunner::on_request(const RequestEvent& r) {
  if (!current_ || !current_->pending) return;
  const RequestEvent& want = *current_->pending;
  if (r.coi != want.coi || r.kind != want.kind || r.task != want.task) return;
  const auto with_note = [&r](std::string text) {
    return r.note.empty() ? text : text + " (" + r.note + ")";
  };
  switch (r.state) {
    case RequestState::sent:
    case RequestState::started:
      return;
    case RequestState::completed:
      if (r.task == proto::TaskCode::get_settings && session_.core().read_settings()) {
        finish(true, format_set(*session_.core().read_settings()));
      } else {
        finish(true, r.kind == RequestKind::settings ? "applied" : "completed");
      }
      return;
    case RequestState::error:
      finish(false, with_note("the vehicle answered error"));
      return;
    case RequestState::timed_out:
      // The real head vehicles answer no SET: sent is all that can be known.
      if (r.kind == RequestKind::settings) {
        finish(true, "sent; not confirmed: " + r.note);
        return;
      }
      finish(false, r.note.empty() ? std::string("timed out") : r.note);
      return;
    case RequestState::cancelled:
      finish(false, "the connection ended before the answer");
      return;
  }
}

void SvguiRunner::on_event(Time, const SvguiEvent& event) {
  dispatch(
      event, Overloaded{
                 [&](const DataEvent& e) {
                   on_data("DATA " + std::string(proto::to_string(e.data.state)) + " at " +
                           std::to_string(e.data.timestamp_ms) + " ms");
                 },
                 [&](const HighFreqEvent& e) {
                   on_data("HIGH-FREQ DATA at " + std::to_string(e.data.timestamp_ms) + " ms");
                 },
                 [&](const LowFreqEvent& e) {
                   on_data("LOW-FREQ DATA " + std::string(proto::to_string(e.data.state)) + " at " +
                           std::to_string(e.data.timestamp_ms) + " ms");
                 },
                 [&](const ConnectionEvent& e) {
                   on_connection(e);
                   if (e.state == ConnectionState::connected && waits_for<op::Connect>() &&
                       !session_.core().config().wait_for_login)
                     finish(true, "connected; AUTH sent, its answer not awaited");
                 },
                 [&](const RequestEvent& r) { on_request(r); },
             });
}

}  // namespace hil::client::wr8
