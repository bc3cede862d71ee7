#include "link/faults/rule_book.hpp"

#include <algorithm>

#include "protocol/common/text.hpp"

namespace hil::link::faults {

void RuleBook::install(FaultProfile profile, Direction d, Time now) {
  std::vector<std::pair<FaultRule, std::uint64_t>> kept;  // limit_data rules and their counts
  for (std::size_t i = 0; i < profile_.rules.size(); ++i) {
    const auto& rule = profile_.rules[i];
    if (action<LimitData>(i) && !rule.name.empty()) kept.emplace_back(rule, state_[i].bytes_passed);
  }
  profile_ = std::move(profile);
  state_.assign(profile_.rules.size(), RuleState{});
  for (std::size_t i = 0; i < profile_.rules.size(); ++i) {
    const auto& rule = profile_.rules[i];
    auto& st = state_[i];
    if (action<LimitData>(i)) {
      for (const auto& [old, passed] : kept) {
        if (old.name == rule.name && old.action == rule.action) st.bytes_passed = passed;
      }
    }
    st.applies = applies_to(rule.direction, d);
    if (!st.applies || !rule.trigger.at || *rule.trigger.at < now) continue;
    const FaultKind k = rule.kind();
    st.armed = k == FaultKind::stall || k == FaultKind::disconnect || k == FaultKind::reset;
  }
}

std::string RuleBook::name(std::size_t i) const {
  const auto& name = profile_.rules[i].name;
  return name.empty() ? "#" + std::to_string(i + 1) : name;
}

bool RuleBook::none_apply() const {
  return std::none_of(state_.begin(), state_.end(), [](const RuleState& r) { return r.applies; });
}

bool RuleBook::selected(std::size_t i, const WireFrame& frame, Time now, std::uint64_t n,
                        FaultRandom& rng, bool applicable) {
  const auto& rule = profile_.rules[i];
  auto& st = state_[i];
  if (!st.applies || !applicable || !rule.window.contains(now)) return false;
  const auto& t = rule.trigger;
  if (!protocol::kind_matches(t.match, frame.kind)) return false;
  const std::uint64_t m = ++st.matched;
  if (t.at_frame && *t.at_frame != n) return false;
  if (t.first && m > *t.first) return false;
  if (t.every && m % *t.every != 0) return false;
  if (t.probability && !rng.chance(*t.probability)) return false;
  return true;
}

std::optional<std::size_t> RuleBook::bandwidth_at(Time t) const {
  for (std::size_t i = 0; i < profile_.rules.size(); ++i) {
    if (state_[i].applies && action<Bandwidth>(i) && profile_.rules[i].window.contains(t)) return i;
  }
  return std::nullopt;
}

std::optional<std::size_t> RuleBook::first_armed(Time now, std::optional<Time> before) const {
  std::optional<std::size_t> which;
  for (std::size_t i = 0; i < profile_.rules.size(); ++i) {
    if (!state_[i].armed) continue;
    const Time at = *profile_.rules[i].trigger.at;
    if (at > now || (before && at >= *before)) continue;
    before = at;
    which = i;
  }
  return which;
}

std::optional<Time> RuleBook::next_armed() const {
  std::optional<Time> next;
  for (std::size_t i = 0; i < profile_.rules.size(); ++i) {
    if (!state_[i].armed) continue;
    const Time at = *profile_.rules[i].trigger.at;
    if (!next || at < *next) next = at;
  }
  return next;
}

std::optional<std::pair<std::size_t, Time>> RuleBook::refusing(Time now) const {
  for (std::size_t i = 0; i < profile_.rules.size(); ++i) {
    const auto* refuse = action<Refuse>(i);
    if (!state_[i].applies || !refuse) continue;
    const auto& rule = profile_.rules[i];
    const Time begin = rule.trigger.at.value_or(Time{0});
    const Time end = begin + refuse->duration;
    if (now < begin || now >= end || !rule.window.contains(now)) continue;
    return std::pair{i, end};
  }
  return std::nullopt;
}

}  // namespace hil::link::faults
