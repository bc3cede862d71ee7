#pragma once
// The logi-client screen read back as text, for the properties of
// tui_model_properties_test.cpp: the fields of the status panel, a line by
// its label, whether a line is drawn whole, and the screen for a failure
// message. Each reads a TuiModel Render (apps/logi-client/tui_model.hpp).

#include <charconv>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "apps/logi-client/tui_model.hpp"
#include "apps/logi-client/tui_view.hpp"

namespace hil::apps::logi_client::screen_text {

/// The text of a panel line split at runs of two or more spaces.
inline std::vector<std::string> columns_of(const std::string& line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && line[i] == ' ')
      ++i;
    std::size_t end = i;
    while (end < line.size() &&
           !(line[end] == ' ' && end + 1 < line.size() && line[end + 1] == ' '))
      ++end;
    std::string part = line.substr(i, end - i);
    while (!part.empty() && part.back() == ' ')
      part.pop_back();
    if (!part.empty()) out.push_back(part);
    i = end;
  }
  return out;
}

/// The status panel's fields, label to value ("SP" -> "30 %"); a label
/// stands alone before its value, or before it with one space ("MODE MAN").
/// A label shown twice is reported in `error`.
inline std::map<std::string, std::string> status_fields(const Panel& panel, std::string& error) {
  std::map<std::string, std::string> fields;
  for (const auto& line : panel.lines) {
    if (line.text.rfind("updated ", 0) == 0 || line.text.rfind("no STAT", 0) == 0) continue;
    const auto parts = columns_of(line.text);
    for (std::size_t i = 0; i < parts.size(); ++i) {
      std::string label = parts[i];
      std::string value;
      if (const auto space = label.find(' '); space != std::string::npos) {
        value = label.substr(space + 1);
        label.resize(space);
      } else if (i + 1 < parts.size()) {
        value = parts[++i];
      }
      if (!fields.emplace(label, value).second) error = "the label " + label + " is shown twice";
    }
  }
  return fields;
}

inline std::optional<long> leading_number(const std::string& text) {
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end == text.data()) return std::nullopt;
  return value;
}

/// Where the shown fields differ from STAT `s`; empty when they all match.
inline std::string telemetry_mismatch(const std::map<std::string, std::string>& shown,
                                      const proto::Status& s) {
  std::string why;
  const auto value = [&](const std::string& label) -> std::optional<std::string> {
    const auto it = shown.find(label);
    if (it == shown.end()) {
      why += label + " not shown; ";
      return std::nullopt;
    }
    return it->second;
  };
  const auto number = [&](const std::string& label, long want) {
    const auto text = value(label);
    if (text && leading_number(*text) != want)
      why += label + " shows '" + *text + "', the STAT says " + std::to_string(want) + "; ";
  };
  const auto word = [&](const std::string& label, const std::string& want) {
    const auto text = value(label);
    if (text && *text != want)
      why += label + " shows '" + *text + "', the STAT says " + want + "; ";
  };
  number("SP", s.speed_percent);
  number("STA", s.station);
  number("RUN", s.running ? 1 : 0);
  word("MODE", std::string(proto::to_string(s.mode)));
  word("MAN", std::string(proto::to_string(s.manual)));
  number("DIS", s.distance_cm);
  std::string track;  // H4 H3 H2 H1, as the car's document writes TRK
  for (int bit = 3; bit >= 0; --bit)
    track += ((s.track_mask >> bit) & 1) != 0 ? '1' : '0';
  word("TRK", track);
  number("DEV", s.deviation);
  number("OBS", s.obstacle ? 1 : 0);
  word("RPM", "LR " + std::to_string(s.rpm[0]) + " LF " + std::to_string(s.rpm[1]) + " RF " +
                  std::to_string(s.rpm[2]) + " RR " + std::to_string(s.rpm[3]));
  for (const auto& [key, text] : s.extra)
    word(key, text);
  if (shown.size() != 10 + s.extra.size())
    why += std::to_string(shown.size()) + " fields shown for a STAT of " +
           std::to_string(10 + s.extra.size()) + "; ";
  return why;
}

/// The first line of `panel` that starts with `label`, and its index.
inline std::optional<std::pair<std::size_t, std::string>> line_of(const Panel& panel,
                                                                  std::string_view label) {
  for (std::size_t i = 0; i < panel.lines.size(); ++i) {
    if (panel.lines[i].text.rfind(label, 0) == 0) return std::pair{i, panel.lines[i].text};
  }
  return std::nullopt;
}

/// Why line `index` of a panel drawn in `box` would not be seen whole
/// (the view draws height - 2 lines of width - 3 characters inside the
/// border, apps/logi-client/tui_view.cpp); empty when it is.
inline std::string cut_off(const TuiLayout::Box& box, std::size_t index, const std::string& text) {
  if (static_cast<int>(index) >= box.height - 2)
    return "line " + std::to_string(index + 1) + " '" + text + "' is below the panel's " +
           std::to_string(box.height - 2) + " rows";
  if (static_cast<int>(text.size()) > box.width - 3)
    return "'" + text + "' is cut at " + std::to_string(box.width - 3) + " characters";
  return {};
}

/// The header, banner, status and controls panels and message line, indented.
inline std::string whole_screen(const Render& r) {
  std::string s = "    " + r.header.text + "\n";
  if (r.stale) s += "    " + *r.stale + "\n";
  for (const auto* p : {&r.status, &r.controls}) {
    s += "    [" + p->title + "]\n";
    for (const auto& l : p->lines)
      s += "    " + l.text + "\n";
  }
  return s + "    " + r.message.text + "\n";
}

}  // namespace hil::apps::logi_client::screen_text
