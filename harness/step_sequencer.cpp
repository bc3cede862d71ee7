#include "harness/step_sequencer.hpp"

#include <utility>

#include "harness/expect.hpp"
#include "harness/origin.hpp"
#include "harness/run_driver.hpp"
#include "protocol/common/overloaded.hpp"
#include "sim/geometry.hpp"

namespace hil::harness {

StepSequencer::StepSequencer(const Scenario& scenario, std::vector<StepOutcome>& steps,
                             StepTargets targets)
    : scenario_(scenario), steps_(steps), targets_(targets), faults_in_force_(scenario.faults) {
  for (const auto& s : scenario_.setup)
    main_.steps.push_back(add(s, "setup"));
  for (const auto& s : scenario_.steps)
    main_.steps.push_back(add(s, "steps"));
  for (const auto& s : scenario_.teardown)
    teardown_.steps.push_back(add(s, "teardown"));
  teardown_.stop_on_failure = false;  // clean up as much as can be
  schedule_base_ = steps_.size();
  for (const auto& s : scenario_.schedule)
    add(s.step, "schedule");
}

StepSequencer::~StepSequencer() {
  *alive_ = false;
}

std::size_t StepSequencer::add(const Step& step, const char* phase) {
  StepOutcome o;
  o.line = step.line;
  o.text = step.text;
  o.phase = phase;
  o.ran = false;
  o.ok = true;
  steps_.push_back(std::move(o));
  plan_.push_back(&step);
  return steps_.size() - 1;
}

std::function<void()> StepSequencer::guarded(std::function<void()> f) const {
  return [alive = std::weak_ptr<bool>(alive_), f = std::move(f)] {
    if (const auto a = alive.lock(); a && *a) f();
  };
}

void StepSequencer::post(std::function<void()> f) {
  targets_.executor.post(guarded(std::move(f)));
}

std::function<void()> StepSequencer::scheduled_start(std::size_t index) {
  return guarded([this, index] {
    if (!closed_ && !schedule_stopped_) begin_step(index, [](bool) {});
  });
}

void StepSequencer::origin_fixed(Time origin) {
  origin_shift_ = origin - Time(0);
  for (std::size_t j = 0; j < scenario_.schedule.size(); ++j) {
    const Anchor& when = scenario_.schedule[j].when;
    if (!when.event)
      targets_.executor.call_at(origin + when.offset, scheduled_start(schedule_base_ + j));
  }
  if (origin_shift_ != Duration(0) && has_timed_rules(faults_in_force_)) {
    // Told from a timeline listener perhaps, while the link is opening: on
    // the next turn.
    post([this] { targets_.server.set_faults(moved(faults_in_force_, origin_shift_)); });
  }
}

void StepSequencer::start_schedule() {
  for (std::size_t j = 0; j < scenario_.schedule.size(); ++j) {
    const Anchor& when = scenario_.schedule[j].when;
    if (!when.event) continue;  // origin_fixed() arms it
    auto fire = scheduled_start(schedule_base_ + j);
    // The n-th matching record arms the step; a "last" occurrence cannot be
    // known while the run goes on, so it means the first.
    const int wanted = when.occurrence > 0 ? when.occurrence : 1;
    auto seen = std::make_shared<int>(0);
    auto id = std::make_shared<RunTimeline::ListenerId>(0);
    *id = targets_.timeline.listen([this, when, wanted, seen, id, fire](const Record& r) {
      if (!matches(*when.event, r) || ++*seen < wanted) return;
      targets_.timeline.unlisten(*id);
      targets_.executor.call_at(r.at + when.offset, fire);
    });
  }
}

void StepSequencer::start(Sequence which) {
  post([this, which] { advance(order(which)); });
}

bool StepSequencer::done(Sequence which) const {
  return (which == Sequence::main ? main_ : teardown_).done;
}

void StepSequencer::advance(Order& seq) {
  if (seq.done || closed_) return;
  if (seq.next >= seq.steps.size()) {
    seq.done = true;
    return;
  }
  const std::size_t index = seq.steps[seq.next++];
  begin_step(index, [this, &seq, index](bool ok) {
    if (seq.done) return;  // timed out meanwhile
    if (!ok && seq.stop_on_failure) {
      skip_rest(seq, "not run: the step on line " + std::to_string(steps_[index].line) + " failed");
      return;
    }
    post([this, &seq] { advance(seq); });
  });
}

void StepSequencer::skip_rest(Order& seq, const std::string& reason) {
  for (; seq.next < seq.steps.size(); ++seq.next) {
    StepOutcome& o = steps_[seq.steps[seq.next]];
    o.ran = false;
    o.ok = false;
    o.reason = reason;
  }
  seq.done = true;
}

void StepSequencer::begin_step(std::size_t index, std::function<void(bool ok)> then) {
  const Step& step = *plan_[index];
  StepOutcome& o = steps_[index];
  o.ran = true;
  o.started = targets_.executor.now();
  running_[index].then = std::move(then);
  targets_.timeline.add(
      StepKind::start,
      {{"index", index}, {"line", step.line}, {"text", step.text}, {"phase", o.phase}});
  std::visit(protocol::Overloaded{
                 [&](const ActionStep&) {
                   actions_.push_back(index);
                   pump_actions();
                 },
                 [&](const WaitStep& w) {
                   running_[index].timer = targets_.executor.call_after(
                       w.duration, [this, index] { finish_step(index, true, ""); });
                 },
                 [&](const WaitUntilStep& w) { begin_wait_until(index, w); },
                 [&](const CarStep& c) {
                   targets_.timeline.add(
                       CarEventKind::behaviour,
                       {{"name", c.behaviour.name},
                        {"action", std::string(mocks::action_name(c.behaviour.action))}});
                   mocks::Behaviour behaviour = c.behaviour;
                   if (behaviour.when.at) *behaviour.when.at += origin_shift_;
                   targets_.car.firmware().arm(std::move(behaviour));
                   finish_later(index, true, "");
                 },
                 [&](const FaultsStep& f) {
                   faults_in_force_ = f.profile;
                   targets_.server.set_faults(moved(f.profile, origin_shift_));
                   finish_later(index, true, "");
                 },
                 [&](const ObstacleStep& s) { begin_obstacle(index, s); },
             },
             step.action);
}

void StepSequencer::finish_later(std::size_t index, bool ok, std::string reason) {
  post([this, index, ok, reason = std::move(reason)] { finish_step(index, ok, reason); });
}

void StepSequencer::finish_step(std::size_t index, bool ok, std::string reason, bool cut_short) {
  const auto it = running_.find(index);
  if (it == running_.end()) return;  // already ended (a timeout)
  if (const Step& step = *plan_[index]; step.expect_failure && !cut_short) {
    if (ok) {
      reason = "expected to fail, but it succeeded";
    } else if (!step.failure_contains.empty() &&
               reason.find(step.failure_contains) == std::string::npos) {
      reason = "failed, but not with '" + step.failure_contains + "': " + reason;
    } else {
      reason = "failed as expected: " + reason;
    }
    ok = !ok && reason.starts_with("failed as expected");
  }
  Running r = std::move(it->second);
  running_.erase(it);
  if (r.timer != 0) targets_.executor.cancel(r.timer);
  if (r.listener != 0) targets_.timeline.unlisten(r.listener);
  StepOutcome& o = steps_[index];
  o.ok = ok;
  o.reason = std::move(reason);
  o.ended = targets_.executor.now();
  targets_.timeline.add(StepKind::end, {{"index", index},
                                        {"line", o.line},
                                        {"text", o.text},
                                        {"phase", o.phase},
                                        {"ok", ok},
                                        {"reason", o.reason}});
  if (r.then) r.then(ok);
}

void StepSequencer::begin_wait_until(std::size_t index, const WaitUntilStep& wait) {
  const Time started = targets_.executor.now();
  // A match at this very moment, recorded just before the step began, counts.
  const auto& records = targets_.timeline.timeline().records();
  for (auto it = records.rbegin(); it != records.rend() && it->at >= started; ++it) {
    if (it->kind == StepKind::start) continue;
    if (matches(wait.until, *it)) {
      finish_later(index, true, "");
      return;
    }
  }
  Running& r = running_[index];
  r.listener = targets_.timeline.listen([this, index, matcher = wait.until](const Record& rec) {
    if (!matches(matcher, rec)) return;
    const auto it = running_.find(index);
    if (it == running_.end() || it->second.listener == 0) return;
    targets_.timeline.unlisten(it->second.listener);
    it->second.listener = 0;
    finish_later(index, true, "");
  });
  const std::string what = wait.until.text.empty() ? plan_[index]->text : wait.until.text;
  r.timer = targets_.executor.call_after(wait.timeout, [this, index, what, timeout = wait.timeout] {
    finish_step(index, false, "no '" + what + "' within " + run_seconds_text(timeout));
  });
}

void StepSequencer::begin_obstacle(std::size_t index, const ObstacleStep& step) {
  sim::World& world = targets_.car.world();
  if (!step.add) {
    std::size_t lifted = 0;
    const auto [from, to] = obstacles_.equal_range(step.name);
    for (auto it = from; it != to; ++it)
      if (world.remove_obstacle(it->second)) ++lifted;
    obstacles_.erase(step.name);
    if (lifted == 0)
      finish_later(index, false, "no obstacle named '" + step.name + "' to take away");
    else
      finish_later(index, true, "");
    return;
  }
  world.advance_to(targets_.executor.now());
  sim::Vehicle& vehicle = targets_.car.vehicle();
  const auto footprint = vehicle.chassis().footprint();
  constexpr double kDepthM = 0.10;  // a parcel: 10 cm deep, 30 cm wide
  constexpr double kWidthM = 0.30;
  const double front_m = footprint.center_ahead_m + footprint.length_m / 2;
  const auto center = vehicle.pose().to_arena({front_m + step.ahead_m + kDepthM / 2, 0});
  try {
    obstacles_.emplace(step.name,
                       world.add_obstacle(sim::BoxObstacle{step.name, center, kDepthM, kWidthM,
                                                           vehicle.pose().heading_rad}));
    finish_later(index, true, "");
  } catch (const std::exception& e) {
    finish_later(index, false, e.what());
  }
}

// A client that takes actions side by side gets each at once (a scheduled
// emergency stop beside the sequence's action); others one at a time.
void StepSequencer::pump_actions() {
  ScenarioClient& client = targets_.client;
  while (!actions_.empty() && !closed_ && (actions_under_way_ == 0 || client.concurrent())) {
    const std::size_t index = actions_.front();
    actions_.pop_front();
    ++actions_under_way_;
    const std::string text = std::get<ActionStep>(plan_[index]->action).text;
    client.execute(text, [this, index, text](bool ok, const std::string& reason) {
      --actions_under_way_;
      targets_.timeline.add(ClientKind::action,
                            {{"index", index}, {"text", text}, {"ok", ok}, {"reason", reason}});
      finish_step(index, ok, reason);
      pump_actions();
    });
  }
}

void StepSequencer::end_under_way(const std::string& reason) {
  std::vector<std::size_t> under_way;
  for (const auto& [index, r] : running_)
    under_way.push_back(index);
  for (const auto index : under_way)
    finish_step(index, false, reason, true);
}

void StepSequencer::time_out(Sequence which, const std::string& reason) {
  skip_rest(order(which), reason);
  targets_.client.cancel();
  actions_under_way_ = 0;
  actions_.clear();
  end_under_way(reason);
}

void StepSequencer::stop_schedule() {
  schedule_stopped_ = true;
}

void StepSequencer::close() {
  closed_ = true;
  // Scheduled steps still under way (a wait_until that never matched) end
  // with the run; those whose moment never came stay "not run".
  end_under_way("still under way when the run ended");
  for (std::size_t i = schedule_base_; i < steps_.size(); ++i) {
    if (!steps_[i].ran) steps_[i].reason = "not run: its moment never came";
  }
}

}  // namespace hil::harness
