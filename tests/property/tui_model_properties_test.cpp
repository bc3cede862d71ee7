// The logi-client screen, read back as text: the terminal UI's model
// (apps/logi-client/tui_model.hpp) over the LOGI client and the mock LOGI
// car of the property bench (tests/property/logi_rig.hpp), in virtual time.
// A random operator presses keys as a terminal delivers them (a held
// direction key arrives once, then repeats), the car misbehaves and the
// link corrupts, drops, splits and sticks frames together; the model gets
// the client's events and log as the program hands them over
// (apps/logi-client/tui.cpp). Before every key the lines the model would
// draw are read back and must show:
//
//  - every field of the last STAT the client received, how old it is, and
//    the stale warning exactly while the client has it raised (DoD item 10);
//  - the mode of the latest STAT or MD sent, and the direction the client is
//    driving, which is none after a release, an emergency stop or a lost
//    link (DoD item 11).
//
// Three feed bugs planted on purpose show that each check has teeth.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/detail/Configuration.h>
#include <rapidcheck/gtest.h>
#include <rapidcheck/state.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/logi-client/tui_model.hpp"
#include "apps/logi-client/tui_view.hpp"
#include "base/duration.hpp"
#include "tests/property/logi_rig.hpp"
#include "tests/property/planted_check.hpp"
#include "tests/property/random_faults.hpp"
#include "tests/property/session_commands.hpp"
#include "tests/property/tui_screen_text.hpp"

namespace hil::apps::logi_client {
namespace {

namespace prop = client::logi::prop;
using namespace screen_text;
using link::milliseconds;
using prop::expect_caught_and_clean;
using prop::run_planted;
using proto::Direction;
using proto::Mode;

/// What a property reads off the screen.
enum class Shown : std::uint8_t {
  telemetry,           ///< the status panel and the stale banner
  mode_and_direction,  ///< the controls panel's Mode and Drive lines
};

/// Bugs planted between the client and the screen, as a program could
/// wire it wrongly; the model itself is the shipped one.
enum class ScreenBug : std::uint8_t {
  none,
  stat_when_changed,      ///< a STAT reaches the screen only when more than DIS changed
  stale_not_forwarded,    ///< the stale warning's events never reach the screen
  estop_past_the_screen,  ///< Space stops the car through the session, not the model
};

/// The terminal the screen is checked on: the smallest usual one, 24 rows
/// of 80 columns, where the status panel keeps 36 characters of a line,
/// as many as the RPM line of four wheels reversing at three digits has
/// ("RPM  LR -113 LF -113 RF -113 RR -113").
constexpr int kRows = 24;
constexpr int kColumns = 80;

std::string dir_text(std::optional<Direction> d) {
  return d ? std::string(proto::to_string(*d)) : std::string("none");
}

// ---- the bench ----

class ScreenRig;

/// The screen's calls on the session, made on the bench's client as the
/// program's LiveSession makes them on its LogiSession.
class BenchSession final : public SessionControl {
 public:
  explicit BenchSession(ScreenRig& rig) : rig_(rig) {}
  void connect(const std::string& host, std::uint16_t port) override;
  void disconnect() override;
  logi::SubmitResult submit(const proto::Message& command) override;
  logi::SubmitResult press(Direction direction) override;
  logi::SubmitResult release() override;
  logi::SubmitResult emergency_stop() override;
  logi::SubmitResult confirm_resend(logi::RequestId request) override;
  bool busy() const override;
  std::string save_log(LogFormat) override { return "the bench keeps no log files"; }

 private:
  ScreenRig& rig_;
};

/// A direction key the operator holds down in hold driving.
struct KeyDown {
  int code = 0;
  Direction direction = Direction::fwd;
  Time pressed{0};
  Time last_event{0};  ///< the press or its latest repeat
  Time next_repeat{0};
  Duration interval{0};
  bool fresh = true;  ///< the press began a hold (the screen showed no such hold before it)
};

/// The screen's model over the bench, fed as the program feeds it, and
/// what the operator and the client did, to judge what it shows.
class ScreenRig {
 public:
  ScreenRig(Shown what, ScreenBug bug, std::uint64_t seed, bool latched)
      : what_(what),
        bug_(bug),
        bench_(prop::PlantedBug::none, seed),
        control_(*this),
        model_(control_, config(latched)) {
    model_.start(now());
    bench_.settle();
    pump();
  }

  prop::Rig& bench() { return bench_; }
  Time now() const { return bench_.now(); }

  // ---- operator ----
  void key(int code, const std::string& name);
  void press_direction(int code, Duration delay, Duration interval);
  void let_go();
  void wait_until(Time until);

  // ---- what the screen shows ----
  void check();
  /// A car-side event on the bench, then what the program does after it.
  template <class F>
  void car(F&& f) {
    f(bench_);
    pump();
  }
  /// How often the checks met a raised stale warning, a direction held, and
  /// an emergency stop pressed while one was (rapidcheck prints the shares).
  std::size_t stale_seen = 0, held_seen = 0, estops_while_held = 0;
  std::set<std::string> modes_seen;  ///< the mode words the Mode line showed

  // ---- BenchSession's reports ----
  void pressed(Direction d, const logi::SubmitResult& r);
  void released();
  void mode_handed(Mode m) { mode_expected_ = m; }

 private:
  TuiModelConfig config(bool latched) {
    config_.connect_at_start = true;
    config_.latched = latched;
    return config_;
  }
  void pump();
  void observe(Time t, const logi::Event& e);
  bool passes_feed(const logi::Event& e);
  void repeat();
  void fail(const std::string& why, const Render& screen);
  void check_telemetry(const Render& r);
  void check_mode_and_direction(const Render& r);
  void note(const std::string& what) {
    if (keys_.size() < 400) keys_.push_back("  " + prop::ms(now()) + "  " + what);
  }

  Shown what_;
  ScreenBug bug_;
  TuiModelConfig config_;
  prop::Rig bench_;
  BenchSession control_;
  TuiModel model_;
  std::size_t events_fed_ = 0;
  std::uint64_t log_fed_ = 0;
  std::optional<proto::Status> fed_status_;  // what the planted STAT filter last let through
  std::vector<std::string> keys_;

  // What the client got and the operator did.
  std::optional<proto::Status> last_status_;
  Time last_status_at_{0};
  std::optional<Mode> mode_expected_;                 // the latest STAT's or MD sent, on this link
  std::optional<Direction> held_expected_;            // none after release, emergency stop, loss
  std::optional<KeyDown> down_;                       // hold driving: the key held down
  std::optional<std::pair<Direction, Time>> let_go_;  // a key let go, shown no longer from then
  std::vector<std::string> failures_;
};

void BenchSession::connect(const std::string&, std::uint16_t) {
  rig_.bench().session().connect();
}
void BenchSession::disconnect() {
  rig_.bench().session().disconnect();
}
logi::SubmitResult BenchSession::submit(const proto::Message& command) {
  const auto r =
      rig_.bench().session().call([&](auto& core, Time t) { return core.submit(t, command); });
  if (const auto* md = std::get_if<proto::SetMode>(&command); md != nullptr && r)
    rig_.mode_handed(md->mode);
  return r;
}
logi::SubmitResult BenchSession::press(Direction direction) {
  const auto r =
      rig_.bench().session().call([&](auto& core, Time t) { return core.press(t, direction); });
  rig_.pressed(direction, r);
  return r;
}
logi::SubmitResult BenchSession::release() {
  rig_.released();
  return rig_.bench().session().call([](auto& core, Time t) { return core.release(t); });
}
logi::SubmitResult BenchSession::emergency_stop() {
  return rig_.bench().session().call([](auto& core, Time t) { return core.emergency_stop(t); });
}
logi::SubmitResult BenchSession::confirm_resend(logi::RequestId request) {
  return rig_.bench().session().call(
      [&](auto& core, Time t) { return core.confirm_resend(t, request); });
}
bool BenchSession::busy() const {
  return rig_.bench().core().queued() > 0 || rig_.bench().core().in_flight() > 0;
}

void ScreenRig::pressed(Direction d, const logi::SubmitResult& r) {
  if (r) {
    held_expected_ = d;
  } else {
    held_expected_.reset();
  }
}

void ScreenRig::released() {
  // The key still down and repeating: its hold must go on.
  if (down_ && down_->fresh && held_expected_ == down_->direction)
    failures_.push_back("at " + prop::ms(now()) + " the screen released " +
                        dir_text(down_->direction) + " while its key was down (pressed at " +
                        prop::ms(down_->pressed) + ", last repeat at " +
                        prop::ms(down_->last_event) + ")");
  held_expected_.reset();
}

bool ScreenRig::passes_feed(const logi::Event& e) {
  if (bug_ == ScreenBug::stale_not_forwarded && std::holds_alternative<logi::StaleEvent>(e))
    return false;
  if (const auto* s = std::get_if<logi::StatusEvent>(&e);
      s != nullptr && bug_ == ScreenBug::stat_when_changed) {
    proto::Status without_distance = s->status;
    if (fed_status_) without_distance.distance_cm = fed_status_->distance_cm;
    if (fed_status_ == without_distance) return false;
    fed_status_ = s->status;
  }
  return true;
}

void ScreenRig::observe(Time t, const logi::Event& e) {
  if (const auto* c = std::get_if<logi::ConnectionEvent>(&e)) {
    if (c->state != logi::ConnectionState::connected) {
      mode_expected_.reset();
      held_expected_.reset();
    }
  } else if (const auto* s = std::get_if<logi::StatusEvent>(&e)) {
    last_status_ = s->status;
    last_status_at_ = t;
    mode_expected_ = s->status.mode;
  } else if (const auto* cmd = std::get_if<logi::CommandEvent>(&e)) {
    const auto* md = std::get_if<proto::SetMode>(&cmd->command);
    if (md != nullptr && cmd->state == logi::CommandState::sent) mode_expected_ = md->mode;
  }
}

// What the program does after anything happened: the events (posted, so
// after the call that caused them), the new log lines, the model's timer.
void ScreenRig::pump() {
  do {
    while (events_fed_ < bench_.events.size()) {
      const auto [t, e] = bench_.events[events_fed_++];  // a copy: feeding may add events
      observe(t, e);
      if (passes_feed(e)) model_.on_event(t, e);
    }
    const auto fresh = bench_.session().log()->since(log_fed_);
    log_fed_ += fresh.size();
    if (!fresh.empty()) model_.on_log(fresh);
    model_.on_time(now());
  } while (events_fed_ < bench_.events.size());
}

void ScreenRig::key(int code, const std::string& name) {
  down_.reset();  // a terminal repeats only the latest key pressed
  note("key " + name);
  if (code == ' ' || code == key::kEscape) {
    if (model_.held()) ++estops_while_held;
    held_expected_.reset();
    let_go_.reset();
    if (bug_ == ScreenBug::estop_past_the_screen) {
      control_.emergency_stop();
      pump();
      return;
    }
  }
  model_.on_key(now(), code);
  pump();
}

void ScreenRig::press_direction(int code, Duration delay, Duration interval) {
  const auto d = direction_for_key(code);
  const bool was_shown = model_.held() == d;
  key(code, std::string("direction ") + dir_text(d));
  let_go_.reset();
  if (model_.latched() || !d) return;  // latched driving: a tap
  down_ = KeyDown{code, *d, now(), now(), now() + delay, interval, !was_shown};
  note("  held down: repeats from " + prop::ms(now() + delay) + " every " + prop::ms(interval));
}

void ScreenRig::let_go() {
  if (!down_) return;
  note("let go of direction " + dir_text(down_->direction));
  // At the latest, the hold ends the longer window after the key's last event.
  let_go_ = std::pair{down_->direction, down_->last_event + config_.first_repeat_window};
  down_.reset();
}

void ScreenRig::repeat() {
  down_->last_event = now();
  down_->next_repeat = now() + down_->interval;
  model_.on_key(now(), down_->code);
  pump();
}

void ScreenRig::wait_until(Time until) {
  while (now() < until) {
    Time step = until;
    if (const auto w = model_.next_wakeup(); w && *w > now() && *w < step) step = *w;
    if (down_ && down_->next_repeat < step) step = down_->next_repeat;
    bench_.advance_to(step);
    pump();
    if (down_ && down_->next_repeat <= now()) repeat();
  }
}

void ScreenRig::fail(const std::string& why, const Render& screen) {
  std::ostringstream os;
  os << prop::ms(now()) << ": " << why << "\nthe screen:\n"
     << whole_screen(screen) << "the operator:\n";
  for (const auto& k : keys_)
    os << k << "\n";
  os << "the client:\n" << bench_.timeline();
  RC_FAIL(os.str());
}

void ScreenRig::check() {
  const Render r = model_.render(now(), 10);
  if (!failures_.empty()) fail(failures_.front(), r);
  if (what_ == Shown::telemetry) {
    check_telemetry(r);
  } else {
    check_mode_and_direction(r);
  }
}

void ScreenRig::check_telemetry(const Render& r) {
  const TuiLayout layout = layout_screen(kRows, kColumns, r);
  for (std::size_t i = 0; i < r.status.lines.size(); ++i) {
    if (const auto why = cut_off(layout.status, i, r.status.lines[i].text); !why.empty())
      fail("status panel: " + why, r);
  }
  std::string error;
  const auto fields = status_fields(r.status, error);
  if (!error.empty()) fail("status panel: " + error, r);
  if (!last_status_) {
    if (!fields.empty()) fail("the status panel shows fields before any STAT arrived", r);
  } else {
    if (const auto why = telemetry_mismatch(fields, *last_status_); !why.empty())
      fail("the status panel is not the last STAT (" + prop::ms(last_status_at_) + "): " + why, r);
    const std::string age = hil::seconds_text(now() - last_status_at_, 1) + " ago";
    if (!line_of(r.status, "updated " + age))
      fail("the status panel does not say the last STAT is " + age, r);
    if (r.stale && r.stale->find("(last " + age + ")") == std::string::npos)
      fail("the stale banner does not say the last STAT is " + age, r);
  }
  const bool raised = bench_.core().stale();
  if (raised) ++stale_seen;
  if (r.stale.has_value() != raised)
    fail(raised ? "the client raised the stale warning, the screen shows none"
                : "the screen shows a stale warning the client has not raised",
         r);
}

void ScreenRig::check_mode_and_direction(const Render& r) {
  const TuiLayout layout = layout_screen(kRows, kColumns, r);
  const auto mode_line = line_of(r.controls, "Mode ");
  const auto drive_line = line_of(r.controls, "Drive ");
  if (!mode_line || !drive_line) return fail("the controls panel has no Mode or no Drive line", r);
  for (const auto& [index, text] : {*mode_line, *drive_line}) {
    if (const auto why = cut_off(layout.controls, index, text); !why.empty())
      fail("controls panel: " + why, r);
  }
  const auto parts = columns_of(mode_line->second);
  const std::string mode_shown = parts.size() > 1 ? parts[1] : "";
  const std::string mode_want =
      mode_expected_ ? std::string(proto::to_string(*mode_expected_)) : std::string("?");
  modes_seen.insert(mode_shown);
  if (mode_shown != mode_want)
    fail("the screen shows mode '" + mode_shown + "', the latest STAT or MD sent says " + mode_want,
         r);

  const std::string& drive = drive_line->second;
  std::optional<Direction> shown;
  if (const auto at = drive.find("moving "); at != std::string::npos) {
    shown = proto::parse_direction(drive.substr(at + 7));
    if (!shown) return fail("the Drive line names no direction: '" + drive + "'", r);
  } else if (drive.find("stopped") == std::string::npos) {
    return fail("the Drive line says neither moving nor stopped: '" + drive + "'", r);
  }
  if (shown) ++held_seen;
  const auto driving = bench_.core().held();
  if (shown != driving)
    fail("the screen shows " + dir_text(shown) + " held, the client drives " + dir_text(driving),
         r);
  if (shown != held_expected_)
    fail("the screen shows " + dir_text(shown) + " held; after the operator's keys and the " +
             "link's events it should be " + dir_text(held_expected_),
         r);
  if (let_go_ && shown == let_go_->first && now() >= let_go_->second)
    fail("the screen still shows " + dir_text(shown) + " held, " +
             prop::ms(config_.first_repeat_window) + " after the last event of its key (let go)",
         r);
}

// ---- the random sessions ----

struct OpModel {
  bool down = false;  ///< a direction key is held down
  Duration elapsed{0};
};
using ScreenCommand = rc::state::Command<OpModel, ScreenRig>;
using ScreenCommandPtr = std::shared_ptr<const ScreenCommand>;

std::string key_name(int code) {
  switch (code) {
    case key::kEnter:
      return "Enter";
    case key::kEscape:
      return "Esc";
    case ' ':
      return "Space";
    case key::kUp:
      return "Up";
    case key::kDown:
      return "Down";
    case key::kLeft:
      return "Left";
    case key::kRight:
      return "Right";
    default:
      return std::string(1, static_cast<char>(code));
  }
}

/// A key other than a direction: mode, speed, station, run, stop, latch,
/// connection, resend, or the emergency stop.
struct Key final : ScreenCommand {
  int code = 0;
  explicit Key(int c) : code(c) {}
  void apply(OpModel& m) const override { m.down = false; }
  void run(const OpModel&, ScreenRig& r) const override {
    r.check();
    r.key(code, key_name(code));
  }
  void show(std::ostream& os) const override { os << "key " << key_name(code); }
};
/// A speed typed in digits, then Enter.
struct TypeSpeed final : ScreenCommand {
  int percent = 0;
  explicit TypeSpeed(int p) : percent(p) {}
  void apply(OpModel& m) const override { m.down = false; }
  void run(const OpModel&, ScreenRig& r) const override {
    r.check();
    for (const char c : std::to_string(percent))
      r.key(c, std::string(1, c));
    r.key(key::kEnter, "Enter");
  }
  void show(std::ostream& os) const override { os << "type speed " << percent << " Enter"; }
};
/// A direction key: held down in hold driving (the terminal repeats it), a
/// tap in latched driving.
struct DirectionKey final : ScreenCommand {
  int code = 0;
  Duration delay{0};
  Duration interval{0};
  DirectionKey(int c, Duration d, Duration i) : code(c), delay(d), interval(i) {}
  void apply(OpModel& m) const override { m.down = true; }
  void run(const OpModel&, ScreenRig& r) const override {
    r.check();
    r.press_direction(code, delay, interval);
  }
  void show(std::ostream& os) const override {
    os << "direction key " << key_name(code) << " (held: repeats after " << prop::ms(delay)
       << ", every " << prop::ms(interval) << ")";
  }
};
struct LetGo final : ScreenCommand {
  void apply(OpModel& m) const override { m.down = false; }
  void run(const OpModel&, ScreenRig& r) const override {
    r.check();
    r.let_go();
  }
  void show(std::ostream& os) const override { os << "let go of the direction key"; }
};
struct Wait final : ScreenCommand {
  Duration d{0};
  explicit Wait(Duration x) : d(x) {}
  void checkPreconditions(const OpModel& m) const override {
    RC_PRE(m.elapsed + d <= prop::kSessionLength);
  }
  void apply(OpModel& m) const override { m.elapsed += d; }
  void run(const OpModel&, ScreenRig& r) const override { r.wait_until(r.now() + d); }
  void show(std::ostream& os) const override { os << "wait " << prop::ms(d); }
};
struct CarMisbehaves final : ScreenCommand {
  test::Misbehaviour kind = test::Misbehaviour::mute_telemetry;
  Duration lasting{0};
  CarMisbehaves(test::Misbehaviour k, Duration l) : kind(k), lasting(l) {}
  void run(const OpModel&, ScreenRig& r) const override {
    r.car([&](prop::Rig& bench) { bench.car_arm(test::misbehaviour(kind, lasting)); });
  }
  void show(std::ostream& os) const override {
    static const char* names[] = {"answers nothing", "refuses the next request", "sends no STAT",
                                  "hangs up", "resets the connection"};
    os << "car: " << names[static_cast<int>(kind)];
    if (test::lasts(kind)) os << " for " << prop::ms(lasting);
  }
};
struct LinkFaults final : ScreenCommand {
  link::FaultProfile profile;
  explicit LinkFaults(link::FaultProfile p) : profile(std::move(p)) {}
  void run(const OpModel&, ScreenRig& r) const override {
    r.car([&](prop::Rig& bench) { bench.car_faults(profile); });
  }
  void show(std::ostream& os) const override {
    os << "link faults: " << profile.rules.size() << " rules";
  }
};

/// Faults on LOGI frames: checksums and bits corrupted, frames dropped,
/// split, stuck together, noise between them.
rc::Gen<link::FaultProfile> gen_faults() {
  return rc::gen::exec([] {
    test::RandomFaults faults(25);
    faults.maybe(link::Corrupt{link::CorruptTarget::checksum, {}, 1});
    faults.maybe(link::Corrupt{link::CorruptTarget::random, {}, 1});
    faults.maybe(link::Drop{});
    faults.maybe_fragment();
    if (test::RandomFaults::coin())
      faults.add_sometimes(link::Coalesce{*rc::gen::inRange<std::size_t>(2, 5),
                                          milliseconds(*rc::gen::inRange(1, 300))});
    faults.maybe(link::Garbage{{1, 8}, {}});
    return faults.take();
  });
}

/// How often each kind of command comes (0 leaves it out).
struct Weights {
  int keys = 4, speed = 1, direction = 6, let_go = 3, estop = 2, wait = 10, misbehave = 3, mute = 1,
      faults = 2;
};

Weights weights_for(Shown what) {
  if (what == Shown::telemetry)
    return {.direction = 3, .estop = 1, .misbehave = 4, .mute = 4, .faults = 4};
  return {.keys = 6, .speed = 2, .direction = 8, .let_go = 4, .estop = 3};
}

template <class C, class... Args>
ScreenCommandPtr make(Args&&... args) {
  return std::make_shared<const C>(std::forward<Args>(args)...);
}

std::function<rc::Gen<ScreenCommandPtr>(const OpModel&)> gen_command(Weights w) {
  return [w](const OpModel& m) {
    namespace g = rc::gen;
    std::vector<std::pair<std::size_t, rc::Gen<ScreenCommandPtr>>> entries;
    auto add = [&](int weight, rc::Gen<ScreenCommandPtr> gen) {
      if (weight > 0) entries.emplace_back(static_cast<std::size_t>(weight), std::move(gen));
    };
    // m and Enter twice as often: driving needs MD and SP on each connection.
    static const std::vector<int> kKeys = {'m', 'm', key::kEnter, key::kEnter, '+', '-', 't', 'g',
                                           'r', 'f', 's',         'l',         'o', 'y', 'M'};
    static const std::vector<int> kDirectionKeys = {
        'w', 'x', 'a', 'd',      'q',        'e',        'z',        'c',
        '[', ']', 'W', key::kUp, key::kDown, key::kLeft, key::kRight};
    add(w.keys, g::map(g::elementOf(kKeys), [](int c) { return make<Key>(c); }));
    add(w.speed, g::map(g::inRange(0, 121), [](int p) { return make<TypeSpeed>(p); }));
    // Auto-repeat starts 250..660 ms after the press and comes every 30..40 ms.
    add(w.direction,
        g::map(g::tuple(g::elementOf(kDirectionKeys), g::inRange(250, 661), g::inRange(30, 41)),
               [](const std::tuple<int, int, int>& k) {
                 return make<DirectionKey>(std::get<0>(k), milliseconds(std::get<1>(k)),
                                           milliseconds(std::get<2>(k)));
               }));
    add(m.down ? w.let_go * 3 : 0, g::lazy([] { return g::just(make<LetGo>()); }));
    add(w.estop, g::map(g::element<int>(' ', key::kEscape), [](int c) { return make<Key>(c); }));
    const auto left_ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(prop::kSessionLength - m.elapsed)
            .count();
    if (left_ms > 0) {
      const int top = static_cast<int>(std::min<long long>(left_ms, 3000));
      add(w.wait, g::map(g::oneOf(g::inRange(1, std::min(top, 50) + 1), g::inRange(1, top + 1),
                                  g::element(100, 200, 500, 800, 1000, 2000)),
                         [top](int x) { return make<Wait>(milliseconds(std::min(x, top))); }));
    }
    using Kind = test::Misbehaviour;
    add(w.misbehave, g::map(g::pair(g::element(Kind::ignore_all, Kind::reject_next,
                                               Kind::mute_telemetry, Kind::hang_up, Kind::reset),
                                    g::inRange(300, 4001)),
                            [](const std::pair<Kind, int>& p) {
                              return make<CarMisbehaves>(p.first, milliseconds(p.second));
                            }));
    // A car silent for long enough to raise the stale warning, or nearly.
    add(w.mute, g::map(g::inRange(1500, 5001), [](int x) {
          return make<CarMisbehaves>(Kind::mute_telemetry, milliseconds(x));
        }));
    add(w.faults,
        g::map(gen_faults(), [](link::FaultProfile p) { return make<LinkFaults>(std::move(p)); }));
    std::size_t total = 0;
    for (const auto& e : entries)
      total += e.first;
    return g::mapcat(g::inRange<std::size_t>(0, total), [entries](std::size_t x) {
      for (const auto& e : entries) {
        if (x < e.first) return e.second;
        x -= e.first;
      }
      return entries.back().second;
    });
  };
}

/// One random session of 60 s with the screen checked before every key
/// and at the end (RC_FAIL inside).
void run_screen_property(Shown what, ScreenBug bug) {
  const auto seed = *rc::gen::inRange<std::uint64_t>(1, 1u << 30);
  const bool latched = *rc::gen::arbitrary<bool>();
  // Half the sessions start with MD and SP sent, so that driving is allowed
  // early; the others find out that it is not.
  const bool mode_and_speed_first = *rc::gen::arbitrary<bool>();
  ScreenRig rig(what, bug, seed, latched);
  if (mode_and_speed_first) {
    rig.check();
    rig.key('m', "m");
    rig.key(key::kEnter, "Enter");
  }
  const OpModel model;
  const auto gen = gen_command(weights_for(what));
  const auto commands = *rc::gen::withSize([model, gen](int size) {
    return rc::gen::resize(std::max(40, size * 2), rc::state::gen::commands(model, gen));
  });
  rc::state::runAll(commands, model, rig);
  rig.wait_until(Time{prop::kSessionLength});
  rig.check();
  if (what == Shown::telemetry) {
    RC_TAG(rig.stale_seen > 0 ? "stale warning shown" : "no stale warning");
  } else {
    RC_TAG(rig.held_seen > 0 ? "a direction shown held" : "no direction held");
    RC_TAG(rig.estops_while_held > 0 ? "emergency stop while held" : "no emergency stop held");
    RC_TAG(rig.modes_seen.count("AUTO") > 0 && rig.modes_seen.count("MAN") > 0
               ? "AUTO and MAN shown"
               : "not both modes shown");
  }
}

RC_GTEST_PROP(LogiClientScreen, ShowsEveryFieldOfTheLastStatAndTheStaleWarning, ()) {
  run_screen_property(Shown::telemetry, ScreenBug::none);
}

RC_GTEST_PROP(LogiClientScreen, ShowsTheModeAndTheDirectionBeingDriven, ()) {
  run_screen_property(Shown::mode_and_direction, ScreenBug::none);
}

// ---- teeth: each planted feed bug is caught ----

struct Case {
  const char* name;
  ScreenBug bug;
  Shown catcher;
};

rc::detail::TestResult run(Shown what, ScreenBug bug, int sessions) {
  return run_planted(what == Shown::telemetry ? "screen telemetry" : "screen mode and direction",
                     sessions, [what, bug] { run_screen_property(what, bug); });
}

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name;
}

class PlantedScreenBugs : public ::testing::TestWithParam<Case> {};

TEST_P(PlantedScreenBugs, IsCaughtByTheScreenPropertyWhichPassesWithoutIt) {
  const Case& c = GetParam();
  expect_caught_and_clean("the screen property", c.name, [&c](bool planted, int sessions) {
    return run(c.catcher, planted ? c.bug : ScreenBug::none, sessions);
  });
}

INSTANTIATE_TEST_SUITE_P(
    Feed, PlantedScreenBugs,
    ::testing::Values(
        // The batch mode prints a STAT only when more than DIS changed; a
        // screen fed by that rule shows an old distance and age.
        Case{"StatOnlyWhenMoreThanDisChanged", ScreenBug::stat_when_changed, Shown::telemetry},
        Case{"StaleEventsNotForwarded", ScreenBug::stale_not_forwarded, Shown::telemetry},
        // The model never hears the stop: it keeps showing the direction.
        Case{"EmergencyStopPastTheScreen", ScreenBug::estop_past_the_screen,
             Shown::mode_and_direction}),
    [](const ::testing::TestParamInfo<Case>& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace hil::apps::logi_client
