// The Arduino property bench (arduino_rig.hpp): the rig, its frame log as
// the checks read it, and the random operator session that drives it.

#include "tests/property/arduino_rig.hpp"

#include <rapidcheck/state.h>

#include <algorithm>
#include <ostream>
#include <set>
#include <utility>
#include <variant>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "sim/differential.hpp"
#include "sim/presets.hpp"
#include "tests/property/random_faults.hpp"
#include "tests/property/session_commands.hpp"

namespace hil::client::arduino::prop {

using hil::test::RandomFaults;
using link::milliseconds;
using link::seconds;

rc::Gen<link::FaultProfile> gen_faults() {
  return rc::gen::exec([] {
    RandomFaults faults(30);
    faults.maybe(link::Drop{});
    if (RandomFaults::coin())
      faults.add_sometimes(
          link::Corrupt{.target = link::CorruptTarget::random, .field = "", .bits = 1});
    if (RandomFaults::coin())
      faults.add_sometimes(
          link::Corrupt{.target = link::CorruptTarget::checksum, .field = "", .bits = 1});
    faults.maybe(link::Duplicate{1});
    faults.maybe_delay(800);
    faults.maybe_fragment();
    if (RandomFaults::coin())
      faults.add_sometimes(link::Coalesce{2, milliseconds(*rc::gen::inRange(1, 200))});
    if (RandomFaults::coin()) faults.add_sometimes(link::Garbage{{1, 1}, {'\r', '\n', '~', '#'}});
    faults.add_stalls(6000);
    faults.add_breaks();
    return faults.take();
  });
}

rc::Gen<proto::Body> gen_request() {
  return rc::gen::oneOf(
      rc::gen::just<proto::Body>(proto::Ping{}), rc::gen::just<proto::Body>(proto::StatusRequest{}),
      rc::gen::map(rc::gen::inRange(0, 256),
                   [](int pwm) { return proto::Body{proto::SetSpeed{pwm}}; }),
      rc::gen::map(rc::gen::inRange(-40, 41), [](int cm) { return proto::Body{proto::Move{cm}}; }),
      rc::gen::map(rc::gen::inRange(-90, 91),
                   [](int deg) { return proto::Body{proto::Rotate{deg}}; }),
      rc::gen::just<proto::Body>(proto::Stop{}), rc::gen::just<proto::Body>(proto::SonarRead{}),
      rc::gen::just<proto::Body>(proto::IrRead{}),
      // What the protocol cannot carry: refused at once, no SEQ used.
      rc::gen::map(rc::gen::inRange(256, 1000),
                   [](int pwm) { return proto::Body{proto::SetSpeed{pwm}}; }));
}

bool is_valid_request(const proto::Body& body) {
  const auto* v = std::get_if<proto::SetSpeed>(&body);
  return v == nullptr || (v->pwm >= 0 && v->pwm <= 255);
}

ArduinoRig::ArduinoRig(link::FaultProfile faults, PlantedBug bug, Board board) {
  mocks::ServerOptions options = test::on_mem("arduino");
  options.faults = std::move(faults);
  options.observers.push_back(std::make_shared<Closes>(closes, car_opens));
  car.start_board(board, std::move(options));
  session = std::make_unique<ArduinoSession>(car.context, link::MemEndpoint{"arduino"},
                                             std::make_unique<PlantedBugCore>(bug, ClientConfig{}));
  // The log's clock is the virtual one in nanoseconds (not the microseconds
  // its name says): jittered delays fall between microseconds, and every
  // timing rule is checked to the nanosecond.
  session->set_wall_clock([this] { return car.executor.now().count(); });
  session->set_event_handler([this](const Event& e) {
    if (const auto* l = std::get_if<LinkChanged>(&e)) {
      links.push_back(*l);
      turned_away.push_back(car.server->turned_away());
    } else if (const auto* d = std::get_if<RequestDone>(&e)) {
      auto& chassis = dynamic_cast<sim::DifferentialChassis&>(car.firmware->vehicle().chassis());
      const bool moving = car.mock() != nullptr ? car.mock()->moving()
                                                : car.sketch()->state().left_pwm != 0 ||
                                                      car.sketch()->state().right_pwm != 0;
      done.push_back(
          {car.executor.now(), d->id, d->result, moving, chassis.left_pwm(), chassis.right_pwm()});
    }
  });
  session->open();
  car.executor.run_for(Duration::zero());
  RC_ASSERT(car.wait_until_listening());
}

std::vector<WireFrame> wire_of(const ArduinoRig& rig) {
  std::vector<WireFrame> out;
  for (const auto& e : rig.session->log().entries()) {
    WireFrame f;
    f.at = Time{e.utc_us};
    f.tx = e.kind == LogKind::tx;
    f.raw = e.raw;
    const protocol::Bytes bytes(e.raw.begin(), e.raw.end());
    const auto item = proto::decode_frame(bytes, rig.session->core().config().dialect);
    if (const auto* frame = std::get_if<protocol::Frame<proto::Message>>(&item))
      f.message = frame->message;
    out.push_back(std::move(f));
  }
  return out;
}

std::string dump(const ArduinoRig& rig, const std::vector<WireFrame>& wire) {
  std::string out;
  auto ms = [](Time t) { return std::to_string(static_cast<double>(t.count()) / 1e6); };
  for (const auto& f : wire)
    out += ms(f.at) + (f.tx ? " TX " : " RX ") + f.raw + (f.message ? "" : " (does not decode)") +
           "\n";
  for (const auto& l : rig.links)
    out += ms(l.at) + " LINK " + std::string(link_name(l.to)) + " (" + l.reason + ")\n";
  for (const auto& d : rig.done) {
    out += ms(d.at) + " DONE #" + std::to_string(d.id) + " " +
           proto::describe({0, rig.bodies.at(d.id)}) + " -> " +
           std::string(to_string(d.result.code)) + " " + d.result.info +
           " seq=" + (d.result.seq ? std::to_string(*d.result.seq) : std::string("-")) + "\n";
  }
  for (Time t : rig.closes)
    out += ms(t) + " CAR LINK CLOSED\n";
  return out;
}

void finish(ArduinoRig& rig, Duration limit) {
  if (rig.car.board == Board::mock) {
    rig.car.executor.run_for(limit);
    return;
  }
  const auto settled = [&rig] {
    const ArduinoClientCore& core = rig.session->core();
    const ConnectionState s = core.state();
    return !core.busy() && core.queued() == 0 &&
           (s == ConnectionState::connected || s == ConnectionState::disconnected ||
            s == ConnectionState::down);
  };
  test::run_until_done(rig.car.executor, settled, limit);
}

// ---- the random session: the operator, the robot's misbehaviour, time ----

namespace {

struct OperatorModel {
  bool closed = false;  ///< the operator closed the port and has not opened it again
  /// The robot is the emulated board: only the driver's misbehaviours act.
  bool emulated = false;
};

using ArduinoCommand = rc::state::Command<OperatorModel, ArduinoRig>;

struct Submit : ArduinoCommand {
  proto::Body body = *gen_request();
  void apply(OperatorModel&) const override {}
  void run(const OperatorModel& model, ArduinoRig& rig) const override {
    const std::size_t before = rig.done.size();
    const ConnectionState state = rig.session->state();
    const RequestId id = rig.session->request(body);
    rig.bodies[id] = body;
    const bool ended_at_once = rig.done.size() > before && rig.done.back().id == id;
    if (!is_valid_request(body)) {
      RC_ASSERT(ended_at_once);
      RC_ASSERT(rig.done.back().result.code == ResultCode::invalid_request);
    } else if (model.closed || state == ConnectionState::down) {
      // A closed or DOWN link takes no request; it says so at once.
      RC_ASSERT(ended_at_once);
      RC_ASSERT(rig.done.back().result.code == ResultCode::link_down);
    } else {
      RC_ASSERT(!ended_at_once);
      rig.queued.push_back(id);
    }
  }
  void show(std::ostream& os) const override { os << "request " << proto::describe({0, body}); }
};

using Advance = hil::test::AdvanceTime<ArduinoCommand, OperatorModel, ArduinoRig, 4000>;

struct CarMisbehaves : ArduinoCommand {
  // The first two kinds change the firmware's own answers, which the
  // emulated board does not let a script do.
  explicit CarMisbehaves(const OperatorModel& model)
      : kind(*rc::gen::inRange(model.emulated ? 2 : 0, 4)) {}
  int kind;
  int ms = *rc::gen::inRange(100, 30'000);
  void apply(OperatorModel&) const override {}
  using Kind = hil::test::Misbehaviour;
  static constexpr Kind kKinds[] = {Kind::ignore_all, Kind::reject_next, Kind::hang_up,
                                    Kind::reset};
  void run(const OperatorModel&, ArduinoRig& rig) const override {
    rig.car.firmware->arm(hil::test::misbehaviour(kKinds[kind], milliseconds(ms)));
  }
  void show(std::ostream& os) const override {
    static const char* names[] = {"ignores everything for", "rejects the next request", "hangs up",
                                  "resets the connection"};
    os << "robot " << names[kind];
    if (hil::test::lasts(kKinds[kind])) os << " " << ms << " ms";
  }
};

struct OperatorToggles : ArduinoCommand {
  bool close = *rc::gen::weightedElement<bool>({{1, true}, {2, false}});
  void apply(OperatorModel& model) const override { model.closed = close; }
  void run(const OperatorModel& model, ArduinoRig& rig) const override {
    const ConnectionState before = rig.session->state();
    if (close) {
      const std::size_t done_before = rig.done.size();
      const std::size_t waiting = [&] {
        std::set<RequestId> ended;
        for (const auto& d : rig.done)
          ended.insert(d.id);
        return static_cast<std::size_t>(std::count_if(
            rig.queued.begin(), rig.queued.end(), [&](RequestId id) { return !ended.count(id); }));
      }();
      rig.session->close();
      RC_ASSERT(rig.session->state() == ConnectionState::disconnected);
      // Everything still waiting ends link_down, at once.
      RC_ASSERT(rig.done.size() == done_before + waiting);
      for (std::size_t i = done_before; i < rig.done.size(); ++i)
        RC_ASSERT(rig.done[i].result.code == ResultCode::link_down);
    } else {
      rig.operator_opens.push_back(rig.now());
      rig.logged_at_operator_open.push_back(rig.session->log().entries().size());
      rig.session->open();
      rig.car.executor.run_for(Duration::zero());
      if (model.closed || before == ConnectionState::down) {
        // A mem:// port always opens; a robot still busy with the port the
        // operator closed in this very instant may hang up on it at once.
        const ConnectionState now = rig.session->state();
        RC_ASSERT(now == ConnectionState::connected || now == ConnectionState::degraded);
      }
    }
  }
  void show(std::ostream& os) const override { os << "operator " << (close ? "closes" : "opens"); }
};

}  // namespace

void after_a_random_session(SessionCheck check, PlantedBug bug, Board board) {
  ArduinoRig rig(*gen_faults(), bug, board);
  rc::state::check(OperatorModel{.closed = false, .emulated = board == Board::sketch}, rig,
                   rc::state::gen::execOneOfWithArgs<Submit, Submit, Submit, Advance, Advance,
                                                     Advance, CarMisbehaves, OperatorToggles>());
  finish(rig, seconds(60));
  const auto wire = wire_of(rig);
  RC_LOG() << dump(rig, wire);
  check(rig, wire);
}

}  // namespace hil::client::arduino::prop
