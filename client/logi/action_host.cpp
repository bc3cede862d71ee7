#include "client/logi/action_host.hpp"

#include <utility>

namespace hil::client::logi {

namespace {

bool status_shows_moving(const proto::Status& s) {
  return s.running || s.manual != proto::Direction::stop;
}

}  // namespace

// ---- MotionTracker ----

void MotionTracker::on_event(const Event& event) {
  if (const auto* c = std::get_if<CommandEvent>(&event)) {
    const bool ended_ok = c->state == CommandState::accepted;
    const bool maybe = ended_ok || c->state == CommandState::uncertain;
    if (const auto* m = std::get_if<proto::Move>(&c->command)) {
      if (m->direction != proto::Direction::stop && maybe) commanded_ = true;
      if (m->direction == proto::Direction::stop && ended_ok) commanded_ = false;
    } else if (const auto* r = std::get_if<proto::SetRun>(&c->command)) {
      if (r->run && maybe) commanded_ = true;
      if (!r->run && ended_ok) commanded_ = false;
    }
  } else if (const auto* s = std::get_if<StatusEvent>(&event)) {
    if (status_shows_moving(s->status)) {
      seen_moving_ = true;
    } else if (seen_moving_) {
      seen_moving_ = false;
      commanded_ = false;  // it moved and has stopped (an arrival, say)
    }
  } else if (const auto* conn = std::get_if<ConnectionEvent>(&event)) {
    if (conn->state != ConnectionState::connected) commanded_ = seen_moving_ = false;
  }
}

bool MotionTracker::may_be_moving(const LogiClientCore& core) const {
  const auto& s = core.last_status();
  return commanded_ || (s && status_shows_moving(*s));
}

// ---- ActionHost ----

ActionHost::ActionHost(LogiSession& session, link::Executor& executor)
    : session_(session), executor_(executor) {}

ActionHost::~ActionHost() {
  *alive_ = false;
}

void ActionHost::run(std::vector<OperatorStep> steps, OperatorRunnerOptions options,
                     ResultSink on_result, DoneSink on_done) {
  // An uncertain request a runner saw is confirmable by a later one.
  options.confirmable = confirmable_;
  for (const auto& step : steps) {
    if (std::holds_alternative<op::Confirm>(step.action)) confirmable_.reset();
  }
  const std::uint64_t id = ++next_id_;
  auto runner = std::make_unique<OperatorRunner>(
      session_, executor_, std::move(steps), options, std::move(on_result),
      [this, id, on_done = std::move(on_done)](const RunSummary& summary) {
        ended(id, summary, on_done);
      });
  auto* started = runner.get();
  running_.emplace(id, std::move(runner));
  started->start();
}

void ActionHost::ended(std::uint64_t id, const RunSummary& summary, DoneSink on_done) {
  const auto it = running_.find(id);
  if (it == running_.end()) return;  // cancel() ended it
  std::vector<ActionResult> results = it->second->results();
  retired_.push_back(std::move(it->second));  // it is still on the stack
  running_.erase(it);
  ++ending_;
  executor_.post(
      [this, alive = alive_, summary, results = std::move(results), on_done = std::move(on_done)] {
        if (!*alive) return;
        --ending_;
        retired_.clear();
        if (on_done) on_done(summary, results);
      });
}

void ActionHost::on_event(Time now, const Event& event) {
  if (const auto* c = std::get_if<CommandEvent>(&event)) {
    if (c->state == CommandState::uncertain && c->resend_on_confirm) confirmable_ = c->request;
  } else if (const auto* conn = std::get_if<ConnectionEvent>(&event)) {
    if (conn->state != ConnectionState::connected) confirmable_.reset();
  }
  motion_.on_event(event);
  // A runner may end (and leave running_) while it hears the event.
  std::vector<std::uint64_t> ids;
  ids.reserve(running_.size());
  for (const auto& [id, runner] : running_)
    ids.push_back(id);
  for (const auto id : ids) {
    if (const auto it = running_.find(id); it != running_.end()) it->second->on_event(now, event);
  }
}

void ActionHost::cancel() {
  auto cancelled = std::exchange(running_, {});
  for (auto& [id, runner] : cancelled) {
    runner->cancel();  // reports the action under way; its end is not passed on
    retired_.push_back(std::move(runner));
  }
}

}  // namespace hil::client::logi
