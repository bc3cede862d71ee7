#include "link/faults/profile.hpp"

#include <stdexcept>
#include <type_traits>

#include "base/enum_names.hpp"

namespace hil::link {

constexpr base::EnumNames<FaultKind, kFaultKindCount> kFaultKindNames = base::enum_names<FaultKind>(
    {FaultKind::fragment, "fragment"}, {FaultKind::coalesce, "coalesce"},
    {FaultKind::corrupt, "corrupt"}, {FaultKind::drop, "drop"}, {FaultKind::duplicate, "duplicate"},
    {FaultKind::garbage, "garbage"}, {FaultKind::delay, "delay"}, {FaultKind::stall, "stall"},
    {FaultKind::bandwidth, "bandwidth"}, {FaultKind::disconnect, "disconnect"},
    {FaultKind::reset, "reset"}, {FaultKind::refuse, "refuse"},
    {FaultKind::limit_data, "limit_data"}, {FaultKind::slow_close, "slow_close"});

constexpr base::EnumNames<DirectionFilter, 3> kDirectionFilterNames =
    base::enum_names<DirectionFilter>({DirectionFilter::to_car, "to_car"},
                                      {DirectionFilter::to_client, "to_client"},
                                      {DirectionFilter::both, "both"});

constexpr base::EnumNames<CorruptTarget, 3> kCorruptTargetNames = base::enum_names<CorruptTarget>(
    {CorruptTarget::checksum, "checksum"}, {CorruptTarget::field, "field"},
    {CorruptTarget::random, "random"});

namespace {

static_assert(kFaultKindNames.size() == std::variant_size_v<FaultAction>);

bool frame_kind(FaultKind k) {
  switch (k) {
    case FaultKind::fragment:
    case FaultKind::coalesce:
    case FaultKind::corrupt:
    case FaultKind::drop:
    case FaultKind::duplicate:
    case FaultKind::garbage:
    case FaultKind::delay:
      return true;
    default:
      return false;
  }
}

bool bad_range(const ByteCountRange& r) {
  return r.min < 1 || r.min > r.max;
}
bool bad_range(const DurationRange& r) {
  return r.min < Duration{0} || r.min > r.max;
}

}  // namespace

std::string_view to_string(Direction d) {
  return d == Direction::to_car ? "to_car" : "to_client";
}

std::string_view to_string(DirectionFilter d) {
  return kDirectionFilterNames.name(d, "both");
}

bool applies_to(DirectionFilter filter, Direction d) {
  if (filter == DirectionFilter::both) return true;
  return (filter == DirectionFilter::to_car) == (d == Direction::to_car);
}

std::string_view to_string(CorruptTarget t) {
  return kCorruptTargetNames.name(t, "random");
}

std::string_view to_string(FaultKind k) {
  return kFaultKindNames.name(k);
}

std::optional<FaultKind> parse_fault_kind(std::string_view text) {
  return kFaultKindNames.parse(text);
}

FaultKind kind_of(const FaultAction& action) {
  return static_cast<FaultKind>(action.index());
}

FaultProfile for_direction(const FaultProfile& profile, Direction d) {
  FaultProfile out;
  for (std::size_t i = 0; i < profile.rules.size(); ++i) {
    const auto& rule = profile.rules[i];
    if (!applies_to(rule.direction, d)) continue;
    out.rules.push_back(rule);
    if (out.rules.back().name.empty()) out.rules.back().name = "#" + std::to_string(i + 1);
  }
  return out;
}

std::optional<std::string> rule_problem(const FaultRule& rule) {
  const auto& t = rule.trigger;
  const FaultKind kind = rule.kind();
  if (t.probability && !(*t.probability >= 0.0 && *t.probability <= 1.0)) {
    return "'probability' must be a number in [0, 1]";
  }
  if (t.at_frame && *t.at_frame < 1) return "'at_frame' counts from 1";
  if (t.first && *t.first < 1) return "'first' must be at least 1";
  if (t.every && *t.every < 1) return "'every' must be at least 1";
  if (t.at && *t.at < Time{0}) return "'at' must not be negative";
  if (rule.window.from < Time{0}) return "'from' must not be negative";
  if (rule.window.to && *rule.window.to <= rule.window.from) return "'to' must be after 'from'";

  if (frame_kind(kind) && t.at) {
    return "'at' is for stall, disconnect, reset and refuse; frame rules use frame triggers";
  }
  if (kind == FaultKind::bandwidth && (t.at || t.has_frame_condition())) {
    return "bandwidth applies to every write in its window and takes no trigger";
  }
  if (kind == FaultKind::limit_data && (t.at || t.has_frame_condition())) {
    return "limit_data counts every byte in its window and takes no trigger";
  }
  if (kind == FaultKind::slow_close && (t.at || t.has_frame_condition())) {
    return "slow_close acts when the sender closes and takes no trigger";
  }
  if (kind == FaultKind::refuse && t.has_frame_condition()) {
    return "refuse takes 'at' and 'for', not frame triggers";
  }
  if (kind == FaultKind::stall || kind == FaultKind::disconnect || kind == FaultKind::reset) {
    if (!t.at && !t.has_frame_condition()) {
      return "needs 'at' or a frame trigger (at_frame, first, every, probability, match)";
    }
    if (t.at && t.has_frame_condition()) return "takes 'at' or frame triggers, not both";
  }

  return std::visit(
      [](const auto& a) -> std::optional<std::string> {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, Fragment>) {
          if (bad_range(a.piece_bytes)) return "'sizes' must be [min, max] with 1 <= min <= max";
          if (bad_range(a.gap)) return "'gap' must be [min, max] with 0 <= min <= max";
        } else if constexpr (std::is_same_v<A, Coalesce>) {
          if (a.count == 1) return "'count' must be at least 2";
          if (a.window < Duration{0}) return "'window' must not be negative";
          if (a.count == 0 && a.window == Duration{0}) return "needs 'count' or 'window'";
        } else if constexpr (std::is_same_v<A, Corrupt>) {
          if (a.bits < 1) return "'bits' must be at least 1";
          if (a.target == CorruptTarget::field && a.field.empty()) {
            return "target 'field' needs 'field: NAME'";
          }
          if (a.target != CorruptTarget::field && !a.field.empty()) {
            return "'field' is only for target 'field'";
          }
        } else if constexpr (std::is_same_v<A, Drop>) {
          if (a.unit == DropUnit::bytes && bad_range(a.count)) {
            return "'count' must be [min, max] with 1 <= min <= max";
          }
        } else if constexpr (std::is_same_v<A, Duplicate>) {
          if (a.copies < 1) return "'copies' must be at least 1";
        } else if constexpr (std::is_same_v<A, Garbage>) {
          if (a.fixed.empty() && bad_range(a.length)) {
            return "'length' must be [min, max] with 1 <= min <= max";
          }
        } else if constexpr (std::is_same_v<A, Delay>) {
          if (a.base < Duration{0} || a.jitter < Duration{0}) return "delays must not be negative";
        } else if constexpr (std::is_same_v<A, Stall> || std::is_same_v<A, Refuse>) {
          if (a.duration <= Duration{0}) return "'for' must be a positive duration";
        } else if constexpr (std::is_same_v<A, Bandwidth>) {
          if (a.bytes_per_second == 0) return "the rate must be positive";
        } else if constexpr (std::is_same_v<A, LimitData>) {
          if (a.bytes < 1) return "'bytes' must be at least 1";
        } else if constexpr (std::is_same_v<A, SlowClose>) {
          if (a.delay < Duration{0}) return "'delay' must not be negative";
        }
        return std::nullopt;
      },
      rule.action);
}

void validate(const FaultProfile& profile) {
  for (std::size_t i = 0; i < profile.rules.size(); ++i) {
    if (auto problem = rule_problem(profile.rules[i])) {
      throw std::invalid_argument("rule " + std::to_string(i + 1) + " (" +
                                  std::string(to_string(profile.rules[i].kind())) +
                                  "): " + *problem);
    }
  }
}

}  // namespace hil::link
