#include "mocks/behaviour.hpp"

#include <algorithm>

#include "protocol/common/overloaded.hpp"

namespace hil::mocks {

std::string_view action_name(const Action& action) {
  return std::visit(protocol::Overloaded{
                        [](const Reject&) { return std::string_view("reject"); },
                        [](const Ignore&) { return std::string_view("ignore"); },
                        [](const MuteTelemetry&) { return std::string_view("mute-telemetry"); },
                        [](const SendBytes&) { return std::string_view("send"); },
                        [](const EnterFault&) { return std::string_view("fault"); },
                        [](const ClearFault&) { return std::string_view("clear-fault"); },
                        [](const CloseConnection&) { return std::string_view("close"); },
                    },
                    action);
}

void Script::arm(Behaviour behaviour) {
  ++armed_;
  if (behaviour.name.empty()) behaviour.name = "#" + std::to_string(armed_);
  if (behaviour.when.after_count == 0) behaviour.when.after_count = 1;
  waiting_.push_back(Waiting{std::move(behaviour), 0});
}

void Script::clear() {
  waiting_.clear();
  rejects_.clear();
  ignores_.clear();
}

void Script::activate(Time now, const Behaviour& b) {
  if (const auto* r = std::get_if<Reject>(&b.action)) {
    if (r->count > 0) rejects_.push_back(*r);
  } else if (const auto* i = std::get_if<Ignore>(&b.action)) {
    if (i->count && *i->count == 0) return;
    ActiveIgnore active{*i, std::nullopt};
    if (i->duration) active.until = now + *i->duration;
    ignores_.push_back(std::move(active));
  }
}

void Script::expire(Time now) {
  std::erase_if(ignores_, [now](const ActiveIgnore& i) { return i.until && now >= *i.until; });
}

std::vector<Behaviour> Script::take_due(Time now) {
  expire(now);
  std::vector<Behaviour> due;
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    const When& w = it->behaviour.when;
    const bool time_ok = !w.at || now >= *w.at;
    if (time_ok && w.after_frame.empty()) {
      activate(now, it->behaviour);
      due.push_back(std::move(it->behaviour));
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
  return due;
}

std::vector<Behaviour> Script::frame_handled(Time now, std::string_view kind) {
  std::vector<Behaviour> fired;
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    const When& w = it->behaviour.when;
    const bool time_ok = !w.at || now >= *w.at;
    if (!w.after_frame.empty() && time_ok && kind_matches(w.after_frame, kind) &&
        ++it->frames_seen >= w.after_count) {
      activate(now, it->behaviour);
      fired.push_back(std::move(it->behaviour));
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
  return fired;
}

Disposition Script::dispose(Time now, std::string_view kind) {
  expire(now);
  for (auto it = rejects_.begin(); it != rejects_.end(); ++it) {
    if (!kind_matches(it->match, kind)) continue;
    if (--it->count == 0) rejects_.erase(it);
    return Disposition::reject;
  }
  for (auto it = ignores_.begin(); it != ignores_.end(); ++it) {
    if (!kind_matches(it->rule.match, kind)) continue;
    if (it->rule.count && --*it->rule.count == 0) ignores_.erase(it);
    return Disposition::ignore;
  }
  return Disposition::handle;
}

std::optional<Time> Script::next_due() const {
  std::optional<Time> next;
  const auto consider = [&next](Time t) {
    if (!next || t < *next) next = t;
  };
  for (const auto& w : waiting_) {
    if (w.behaviour.when.after_frame.empty()) consider(w.behaviour.when.at.value_or(Time{0}));
  }
  for (const auto& i : ignores_) {
    if (i.until) consider(*i.until);
  }
  return next;
}

}  // namespace hil::mocks
