// The rapidcheck side of the LOGI property bench: the commands a random
// session is made of (operator actions, car-side events, time), their
// generator, and the body every named property runs.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tests/property/logi_rig.hpp"

namespace hil::client::logi::prop {

namespace proto = protocol::logi;
using proto::Direction;
using proto::Mode;

namespace {

struct Connect final : Command {
  void apply(Model& m) const override { m.want_connected = true; }
  void run(const Model&, Rig& r) const override { r.op_connect(); }
  void show(std::ostream& os) const override { os << "connect"; }
};
struct Disconnect final : Command {
  void apply(Model& m) const override {
    m.want_connected = false;
    m.pressed = false;
  }
  void run(const Model&, Rig& r) const override { r.op_disconnect(); }
  void show(std::ostream& os) const override { os << "disconnect"; }
};
/// An operator request the client submits as it is: SP, MD, GS, ST.
struct Submit final : Command {
  OpRecord::Kind kind = OpRecord::Kind::speed;
  proto::Message message;
  int value = 0;
  std::string text;  ///< as the operator would type it
  Submit(OpRecord::Kind k, proto::Message m, int v, std::string t)
      : kind(k), message(std::move(m)), value(v), text(std::move(t)) {}
  void run(const Model&, Rig& r) const override { r.op_submit(kind, message, value); }
  void show(std::ostream& os) const override { os << text; }
};
struct Press final : Command {
  Direction dir = Direction::fwd;
  explicit Press(Direction d) : dir(d) {}
  void apply(Model& m) const override { m.pressed = true; }
  void run(const Model&, Rig& r) const override { r.op_press(dir); }
  void show(std::ostream& os) const override { os << "press " << dir_word(dir); }
};
struct Release final : Command {
  void apply(Model& m) const override { m.pressed = false; }
  void run(const Model&, Rig& r) const override { r.op_release(); }
  void show(std::ostream& os) const override { os << "release"; }
};
struct EStop final : Command {
  void apply(Model& m) const override { m.pressed = false; }
  void run(const Model&, Rig& r) const override { r.op_estop(); }
  void show(std::ostream& os) const override { os << "emergency-stop"; }
};
struct Advance final : Command {
  Duration d{0};
  explicit Advance(Duration x) : d(x) {}
  void checkPreconditions(const Model& m) const override {
    RC_PRE(m.elapsed + d <= kSessionLength);
  }
  void apply(Model& m) const override { m.elapsed += d; }
  void run(const Model&, Rig& r) const override { r.advance_to(r.now() + d); }
  void show(std::ostream& os) const override { os << "wait " << ms(d); }
};
struct DropLink final : Command {
  bool reset = true;
  explicit DropLink(bool x) : reset(x) {}
  void run(const Model&, Rig& r) const override { r.car_drop_link(reset); }
  void show(std::ostream& os) const override {
    os << "car: drop the link (" << (reset ? "reset" : "close") << ")";
  }
};
struct RejectCmd final : Command {
  std::string kind;
  std::uint64_t count = 1;
  RejectCmd(std::string k, std::uint64_t c) : kind(std::move(k)), count(c) {}
  void run(const Model&, Rig& r) const override {
    r.car_arm(mocks::Behaviour{"reject", {}, mocks::Reject{kind, count}});
  }
  void show(std::ostream& os) const override {
    os << "car: reject the next " << count << " " << kind;
  }
};
struct IgnoreCmd final : Command {
  std::string kind;
  std::uint64_t count = 1;
  IgnoreCmd(std::string k, std::uint64_t c) : kind(std::move(k)), count(c) {}
  void run(const Model&, Rig& r) const override {
    r.car_arm(mocks::Behaviour{"ignore", {}, mocks::Ignore{kind, count, std::nullopt}});
  }
  void show(std::ostream& os) const override {
    os << "car: ignore the next " << count << " " << kind;
  }
};
struct Mute final : Command {
  Duration d{0};
  explicit Mute(Duration x) : d(x) {}
  void run(const Model&, Rig& r) const override {
    r.car_arm(mocks::Behaviour{"mute", {}, mocks::MuteTelemetry{d}});
  }
  void show(std::ostream& os) const override { os << "car: no STAT for " << ms(d); }
};

/// Fault rules by bit: what the link does to the frames from now on. All
/// eight rules are always there, in the same order, and the ones left out
/// never fire, so a rule keeps its index (and its place in the seeded
/// random draws) whichever others are switched on.
link::FaultProfile profile_of(unsigned mask) {
  using namespace link;
  FaultProfile p;
  int bit = 0;
  auto add = [&](const char* name, DirectionFilter d, FaultAction a, std::optional<double> prob) {
    const bool on = (mask >> bit++) & 1u;
    FaultRule r;
    r.name = name;
    r.direction = d;
    r.trigger.probability = on ? prob : std::optional<double>(0.0);
    r.action = std::move(a);
    p.rules.push_back(std::move(r));
  };
  add("corrupt-in", DirectionFilter::to_client, Corrupt{CorruptTarget::checksum, {}, 1}, 0.2);
  add("drop-in", DirectionFilter::to_client, Drop{}, 0.2);
  add("split-in", DirectionFilter::to_client, Fragment{{1, 5}, {milliseconds(0), milliseconds(2)}},
      std::nullopt);
  add("stick-in", DirectionFilter::to_client, Coalesce{3, milliseconds(200)}, std::nullopt);
  add("noise-in", DirectionFilter::to_client, Garbage{{1, 8}, {}}, 0.25);
  add("drop-out", DirectionFilter::to_car, Drop{}, 0.3);
  add("corrupt-out", DirectionFilter::to_car, Corrupt{CorruptTarget::checksum, {}, 1}, 0.2);
  add("split-out", DirectionFilter::to_car, Fragment{{1, 4}, {milliseconds(0), milliseconds(0)}},
      std::nullopt);
  return p;
}

struct Faults final : Command {
  unsigned mask = 0;
  explicit Faults(unsigned m) : mask(m) {}
  void run(const Model&, Rig& r) const override { r.car_faults(profile_of(mask)); }
  void show(std::ostream& os) const override {
    os << "link faults:";
    for (const auto& rule : profile_of(mask).rules) {
      if (rule.trigger.probability != 0.0) os << " " << rule.name;
    }
    if (mask == 0) os << " none";
  }
};

template <class C, class... Args>
CommandPtr make(Args&&... args) {
  return std::make_shared<const C>(std::forward<Args>(args)...);
}

const std::vector<std::string>& car_kinds() {
  // Stops are never swallowed or refused by the car: the safety property
  // is about faults on the link, which the client can see and retry.
  static const std::vector<std::string> kinds = {"SP",     "MD",      "GS",   "ST:RUN",
                                                 "MV:FWD", "MV:LEFT", "MV:CW"};
  return kinds;
}

}  // namespace

std::function<rc::Gen<CommandPtr>(const Model&)> gen_command(Focus f) {
  return [f](const Model& m) {
    namespace g = rc::gen;
    using Entry = std::pair<std::size_t, rc::Gen<CommandPtr>>;
    std::vector<Entry> entries;
    auto add = [&](int w, rc::Gen<CommandPtr> gen) {
      if (w > 0) entries.emplace_back(static_cast<std::size_t>(w), std::move(gen));
    };
    add(m.want_connected ? 1 : f.connect * 4, g::lazy([] { return g::just(make<Connect>()); }));
    add(m.want_connected ? f.disconnect : 0, g::lazy([] { return g::just(make<Disconnect>()); }));
    add(f.speed, g::map(g::element(0, 30, 50, 80, 100, 7), [](int p) {
          return make<Submit>(OpRecord::Kind::speed, proto::SetSpeed{p}, p,
                              "speed " + std::to_string(p));
        }));
    add(f.mode, g::map(g::arbitrary<bool>(), [](bool manual) {
          return make<Submit>(OpRecord::Kind::mode,
                              proto::SetMode{manual ? Mode::manual : Mode::automatic},
                              manual ? 1 : 0, manual ? "mode MAN" : "mode AUTO");
        }));
    add(m.pressed ? 1 : f.press,
        g::map(g::inRange(1, 11), [](int d) { return make<Press>(static_cast<Direction>(d)); }));
    add(m.pressed ? f.release * 3 : 1, g::lazy([] { return g::just(make<Release>()); }));
    add(f.station, g::map(g::element(1, 2, 3), [](int s) {
          return make<Submit>(OpRecord::Kind::station, proto::SetStation{s}, s,
                              "station " + std::to_string(s));
        }));
    add(f.run, g::lazy([] {
          return g::just(make<Submit>(OpRecord::Kind::run, proto::SetRun{true}, 1, "run"));
        }));
    add(f.stop, g::lazy([] {
          return g::just(make<Submit>(OpRecord::Kind::stop, proto::SetRun{false}, 0, "stop"));
        }));
    add(f.estop, g::lazy([] { return g::just(make<EStop>()); }));
    const auto left_ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(kSessionLength - m.elapsed).count();
    if (left_ms > 0) {
      const int top = static_cast<int>(std::min<long long>(left_ms, 3000));
      add(f.advance,
          g::map(g::oneOf(g::inRange(1, std::min(top, 50) + 1), g::inRange(1, top + 1),
                          g::element(100, 200, 500, 800, 1000, 2000)),
                 [top](int x) { return make<Advance>(milliseconds(std::min(x, top))); }));
    }
    add(f.drop_link, g::map(g::arbitrary<bool>(), [](bool b) { return make<DropLink>(b); }));
    add(f.reject, g::map(g::pair(g::elementOf(car_kinds()), g::inRange<std::uint64_t>(1, 3)),
                         [](const std::pair<std::string, std::uint64_t>& p) {
                           return make<RejectCmd>(p.first, p.second);
                         }));
    add(f.ignore, g::map(g::pair(g::elementOf(car_kinds()), g::inRange<std::uint64_t>(1, 4)),
                         [](const std::pair<std::string, std::uint64_t>& p) {
                           return make<IgnoreCmd>(p.first, p.second);
                         }));
    add(f.mute, g::map(g::inRange(500, 4001), [](int x) { return make<Mute>(milliseconds(x)); }));
    add(f.faults, g::map(g::inRange(0u, 256u), [](unsigned x) { return make<Faults>(x); }));
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

namespace {
/// HIL_LOGI_PLANTED_BUG=<name> plants a bug in every session of the
/// properties program, to watch a property catch it and replay the failure.
PlantedBug bug_from_environment() {
  static const PlantedBug bug = [] {
    const char* name = std::getenv("HIL_LOGI_PLANTED_BUG");
    if (name == nullptr) return PlantedBug::none;
    for (const auto& entry : kPlantedBugs) {
      if (entry.name == name) return entry.bug;
    }
    // A misspelt name would otherwise test the shipped client unnoticed.
    std::string known;
    for (const auto& entry : kPlantedBugs)
      known += " " + std::string(entry.name);
    std::fprintf(stderr, "HIL_LOGI_PLANTED_BUG=%s: no such planted bug; expected one of:%s\n", name,
                 known.c_str());
    std::exit(2);
  }();
  return bug;
}
}  // namespace

void run_property(Prop p, PlantedBug bug) {
  if (bug == PlantedBug::none) bug = bug_from_environment();
  const auto seed = *rc::gen::inRange<std::uint64_t>(1, 1u << 30);
  Rig rig(bug, seed);
  // Every session starts with the operator connecting, and holds at least
  // 40 actions (rapidcheck's early, small sizes would leave most of the
  // 60 s idle).
  rig.op_connect();
  Model model;
  model.want_connected = true;
  const auto gen = gen_command(focus_for(p));
  const auto commands = *rc::gen::withSize([model, gen](int size) {
    return rc::gen::resize(std::max(40, size * 2), rc::state::gen::commands(model, gen));
  });
  rc::state::runAll(commands, model, rig);
  if (rig.now() < kSessionLength) rig.advance_to(kSessionLength);
  RC_TAG(exercised(p, rig) ? "exercised" : "not exercised");
  const std::string why = check(p, rig);
  if (!why.empty()) RC_FAIL(std::string(name_of(p)) + ": " + why + "\n" + rig.timeline());
}

}  // namespace hil::client::logi::prop
