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

template <class Ready>
std::vector<Behaviour> Script::fire(Time now, Ready ready) {
  std::vector<Behaviour> fired;
  for (auto it = waiting_.begin(); it != waiting_.end();) {
    const When& w = it->behaviour.when;
    if ((!w.at || now >= *w.at) && ready(*it)) {
      activate(now, it->behaviour);
      fired.push_back(std::move(it->behaviour));
      it = waiting_.erase(it);
    } else {
      ++it;
    }
  }
  return fired;
}

std::vector<Behaviour> Script::take_due(Time now) {
  expire(now);
  return fire(now, [](const Waiting& w) { return w.behaviour.when.after_frame.empty(); });
}

std::vector<Behaviour> Script::frame_handled(Time now, std::string_view kind) {
  return fire(now, [kind](Waiting& w) {
    const When& when = w.behaviour.when;
    return !when.after_frame.empty() && kind_matches(when.after_frame, kind) &&
           ++w.frames_seen >= when.after_count;
  });
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
  link::Earliest next;
  for (const auto& w : waiting_) {
    if (w.behaviour.when.after_frame.empty()) next.consider(w.behaviour.when.at.value_or(Time{0}));
  }
  for (const auto& i : ignores_)
    next.consider(i.until);
  return next.time();
}

}  // namespace hil::mocks
