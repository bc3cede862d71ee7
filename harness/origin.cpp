#include "harness/origin.hpp"

#include <chrono>
#include <utility>
#include <variant>

#include "base/duration.hpp"
#include "base/enum_names.hpp"

namespace hil::harness {
namespace {

constexpr auto kCauseTexts = base::enum_names<Origin::Cause>(
    {Origin::Cause::run_start, "the run's start"},
    {Origin::Cause::first_connection, "the client's first connection"},
    {Origin::Cause::first_result, "the client's first result line"},
    {Origin::Cause::program_start, "the client program's start"});

constexpr auto kCauseWords = base::enum_names<Origin::Cause>(
    {Origin::Cause::run_start, "run_start"}, {Origin::Cause::first_connection, "connection"},
    {Origin::Cause::first_result, "result"}, {Origin::Cause::program_start, "program_start"});

// A record that shows the program reached the car: its connection
// accepted or refused by a `refuse` fault, or its first byte (a serial
// port shows its opening as `open`).
bool first_contact(const Record& r) {
  if (r.kind == WireKind::open || r.kind == link::FaultKind::refuse) return true;
  return r.kind == WireKind::frame && r.data.value("dir", std::string()) == "to_car";
}

}  // namespace

std::string origin_text(const Origin& origin) {
  return std::string(kCauseTexts.name(origin.cause)) + " at +" + hil::seconds_text(origin.at, 3);
}

bool has_timed_rules(const link::FaultProfile& profile) {
  for (const auto& rule : profile.rules)
    if (rule.trigger.at || rule.window.from != Time(0) || rule.window.to) return true;
  return false;
}

link::FaultProfile moved(link::FaultProfile profile, Duration by) {
  for (auto& rule : profile.rules) {
    if (rule.trigger.at) *rule.trigger.at += by;
    // A window from the start stays open from the start.
    if (rule.window.from != Time(0)) rule.window.from += by;
    if (rule.window.to) *rule.window.to += by;
  }
  return profile;
}

link::FaultProfile awaiting_origin(link::FaultProfile profile) {
  // Far enough to be "not before the origin" in any run (a year).
  const Time later = Time(0) + std::chrono::hours(24 * 365);
  for (auto& rule : profile.rules) {
    if (rule.trigger.at) {
      if (*rule.trigger.at != Time(0)) {
        rule.trigger.at = later;
      } else if (auto* refuse = std::get_if<link::Refuse>(&rule.action)) {
        refuse->duration = later - Time(0);
      } else if (auto* stall = std::get_if<link::Stall>(&rule.action)) {
        stall->duration = later - Time(0);
      }
    }
    // A window from 0 stays open; one that opens later opens not before the
    // origin (and ends with it).
    if (rule.window.from != Time(0)) rule.window.from = later;
    rule.window.to.reset();
  }
  return profile;
}

OriginWatch::OriginWatch(link::Executor& executor, RunTimeline& timeline, Duration startup_timeout)
    : executor_(executor), timeline_(timeline), program_start_(executor.now()) {
  listener_ = timeline_.listen([this](const Record& r) {
    if (first_contact(r)) {
      fix(r.at, Origin::Cause::first_connection);
    } else if (r.kind == ClientKind::exit) {
      // Gone without a sign: nothing more will come.
      fix(program_start_, Origin::Cause::program_start);
    }
  });
  timer_ = executor_.call_at(program_start_ + startup_timeout, [this] {
    timer_ = 0;
    fix(program_start_, Origin::Cause::program_start);
  });
}

OriginWatch::~OriginWatch() {
  *alive_ = false;
  if (listener_ != 0) timeline_.unlisten(listener_);
  if (timer_ != 0) executor_.cancel(timer_);
}

void OriginWatch::first_result() {
  fix(executor_.now(), Origin::Cause::first_result);
}

void OriginWatch::when_fixed(std::function<void(const Origin&)> f) {
  if (origin_) {
    f(*origin_);
    return;
  }
  waiting_.push_back(std::move(f));
}

Origin OriginWatch::settled() {
  if (!origin_) fix(program_start_, Origin::Cause::program_start);
  return *origin_;
}

void OriginWatch::fix(Time at, Origin::Cause cause) {
  if (origin_) return;
  origin_ = Origin{at, cause};
  if (listener_ != 0) timeline_.unlisten(listener_);
  listener_ = 0;
  if (timer_ != 0) executor_.cancel(timer_);
  timer_ = 0;
  // Called from a timeline listener too, which must not add records: the
  // origin's record goes in on the next turn, stamped with its own time.
  executor_.post([this, alive = std::weak_ptr<bool>(alive_), origin = *origin_] {
    if (const auto a = alive.lock(); !a || !*a) return;
    timeline_.add_at(origin.at, ClientKind::origin,
                     {{"cause", std::string(kCauseWords.name(origin.cause))},
                      {"text", "origin: " + origin_text(origin)}});
  });
  for (auto& f : std::exchange(waiting_, {}))
    f(*origin_);
}

}  // namespace hil::harness
