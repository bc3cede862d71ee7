#include "harness/scenario_parts.hpp"

#include "client/common/connection.hpp"
#include "link/faults/profile.hpp"

namespace hil::harness::scenario_parts {
namespace {
// "degraded" and "down" are the Arduino link's own states.
const Keys kClientStates = client::kConnectionStateNames.names();

/// Matchers of what the client, the simulation, the fault injector, the car and the steps report.
class EventMatcherReader : public config::Reader {
 public:
  explicit EventMatcherReader(const ScenarioFacts& facts)
      : config::Reader(facts.file), facts_(facts) {}

  Matcher client_matcher(const YAML::Node& v, const std::string& where) const {
    if (v.IsScalar()) return client_word_matcher(v, where);
    if (!v.IsMap()) {
      fail(v, where + " must be a state (connected, stale, ...) or a map like {notice: \"text\"}");
    }
    static const Keys kKinds = {"notice",     "command", "exit",     "output",     "action",
                                "connection", "login",   "movement", "parse_error"};
    Keys allowed = kKinds;
    allowed.insert(allowed.end(), {"state", "ok", "reason"});
    check_keys(v, allowed, where);
    std::string kind;
    for (const auto& k : kKinds) {
      if (!v[k]) continue;
      if (!kind.empty()) fail(v[k], where + ": one of " + join(kKinds) + ", not two");
      kind = k;
    }
    if (kind.empty()) fail(v, where + ": give one of " + join(kKinds));
    // Which of state, ok and reason go with each kind.
    static const std::map<std::string, Keys, std::less<>> kExtras = {{"movement", {"reason"}},
                                                                     {"login", {"reason"}},
                                                                     {"command", {"state"}},
                                                                     {"action", {"ok", "reason"}}};
    const auto extras = kExtras.find(kind);
    for (const char* k : {"state", "ok", "reason"}) {
      if (v[k] && (extras == kExtras.end() || !contains(extras->second, k)))
        fail(v[k], where + ": '" + std::string(k) + "' does not go with '" + kind + "'");
    }
    Matcher m;
    m.source = Source::client;
    m.kind = parse_record_kind(Source::client, kind);
    client_kind_tests(kind, v, where, m);
    return m;
  }

  /// `client: connected`, `client: stale`, `client: parse_error`.
  Matcher client_word_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::client;
    const std::string& word = v.Scalar();
    if (word == "stale" || word == "fresh") {
      m.kind = parse_record_kind(Source::client, word);
      m.text =
          word == "stale" ? "client warned of stale telemetry" : "client telemetry fresh again";
      return m;
    }
    if (word == "parse_error") {
      m.kind = ClientKind::parse_error;
      m.text = "client reported a frame it could not parse";
      return m;
    }
    if (!contains(kClientStates, word)) {
      Keys known = kClientStates;
      known.insert(known.end(), {"stale", "fresh", "parse_error"});
      fail(v, where + ": unknown client state '" + word + "' (expected " + join(known) + ")" +
                  config::did_you_mean(word, known));
    }
    m.kind = ClientKind::connection;
    m.tests.push_back(field_test("state", FieldTest::Op::equals, word));
    m.text = "client " + word;
    return m;
  }

  /// The tests and the text of a client matcher map whose kind is `kind`.
  void client_kind_tests(const std::string& kind, const YAML::Node& v, const std::string& where,
                         Matcher& m) const {
    const YAML::Node x = v[kind];
    const auto contains_test = [&](const char* field, const std::string& what) {
      const std::string text = scalar(x, "'" + kind + "'");
      m.tests.push_back(field_test(field, FieldTest::Op::contains, text));
      m.text = what + " '" + text + "'";
    };
    const auto equals_flag = [&](const char* field, const char* yes, const char* no) {
      const bool value = boolean(x, "'" + kind + "'");
      m.tests.push_back(field_test(field, FieldTest::Op::equals, value));
      m.text = value ? yes : no;
    };
    if (kind == "notice") {
      contains_test("text", "client notice containing");
    } else if (kind == "output") {
      contains_test("line", "client printed a line containing");
    } else if (kind == "parse_error") {
      contains_test("text", "client could not parse a frame:");
    } else if (kind == "exit") {
      m.text = "client exited";
      if (!x.IsNull()) {
        const auto code = static_cast<std::int64_t>(whole(x, "'exit'", 0));
        m.tests.push_back(field_test("code", FieldTest::Op::equals, code));
        m.text += " with " + std::to_string(code);
      }
    } else if (kind == "movement") {
      equals_flag("enabled", "client enabled movement", "client disabled movement");
    } else if (kind == "login") {
      equals_flag("ok", "client logged in", "client login refused");
    } else if (kind == "connection") {
      const std::string word = scalar(x, "'connection'");
      if (!contains(kClientStates, word)) {
        fail(x, where + ": unknown connection state '" + word + "' (expected " +
                    join(kClientStates) + ")" + config::did_you_mean(word, kClientStates));
      }
      m.tests.push_back(field_test("state", FieldTest::Op::equals, word));
      m.text = "client " + word;
    } else if (kind == "command") {
      const std::string command = scalar(x, "'command'");
      m.text = "client command " + command;
      if (command != "*")
        m.tests.push_back(field_test("command", FieldTest::Op::kind_prefix, command));
      if (auto state = v["state"]) {
        const std::string s = scalar(state, "'state'");
        m.tests.push_back(field_test("state", FieldTest::Op::equals, s));
        m.text += " " + s;
      }
    } else {
      const std::string text = trim(scalar(x, "'action'"));
      m.text = "action '" + text + "'";
      if (text != "*") m.tests.push_back(field_test("text", FieldTest::Op::equals, text));
      if (auto ok = v["ok"]) {
        const bool b = boolean(ok, "'ok'");
        m.tests.push_back(field_test("ok", FieldTest::Op::equals, b));
        m.text += b ? " succeeded" : " failed";
      }
    }
    if (auto reason = v["reason"]) {
      const std::string r = scalar(reason, "'reason'");
      m.tests.push_back(field_test("reason", FieldTest::Op::contains, r));
      m.text += " because of '" + r + "'";
    }
  }

  Matcher sim_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::sim;
    static const Keys kWords = {"at_rest", "moving", "collision"};
    if (v.IsScalar()) {
      const std::string& word = v.Scalar();
      if (!contains(kWords, word)) {
        fail(v, where + ": unknown '" + word +
                    "' (expected at_rest, moving, collision, or a map "
                    "with station, speed_below, speed_above, near)" +
                    config::did_you_mean(word, kWords));
      }
      m.kind = parse_record_kind(Source::sim, word);
      m.text = word == "at_rest"  ? "chassis at rest"
               : word == "moving" ? "chassis moving"
                                  : "collision";
      return m;
    }
    if (!v.IsMap()) fail(v, where + " must be at_rest, moving, collision or a map");
    static const Keys kKeys = {"station",     "collision", "speed_below",
                               "speed_above", "near",      "radius"};
    check_keys(v, kKeys, where);
    if (auto s = v["station"]) {
      check_keys(v, {"station"}, where);
      const auto station = whole(s, "'station'", 0);
      m.kind = SimKind::station;
      m.tests.push_back(field_test("station", FieldTest::Op::equals, station));
      m.text = "car reached station " + std::to_string(station);
      return m;
    }
    if (auto c = v["collision"]) {
      check_keys(v, {"collision"}, where);
      const std::string with = scalar(c, "'collision'");
      m.kind = SimKind::collision;
      m.tests.push_back(field_test("with", FieldTest::Op::contains, with));
      m.text = "collision with '" + with + "'";
      return m;
    }
    m.kind = SimKind::sample;
    if (auto s = v["speed_below"]) {
      const double speed = number(s, "'speed_below'");
      m.tests.push_back(field_test("speed_mps", FieldTest::Op::less, speed));
      m.text = "speed below " + s.Scalar() + " m/s";
    }
    if (auto s = v["speed_above"]) {
      const double speed = number(s, "'speed_above'");
      m.tests.push_back(field_test("speed_mps", FieldTest::Op::greater, speed));
      m.text += std::string(m.text.empty() ? "" : " and ") + "speed above " + s.Scalar() + " m/s";
    }
    if (auto near = v["near"]) {
      if (!near.IsSequence() || near.size() != 2) {
        fail(near, where + ": 'near' must be [x, y] in metres");
      }
      const double x = number(near[0], "x");
      const double y = number(near[1], "y");
      const auto r = v["radius"];
      if (!r) fail(near, where + ": 'near' needs 'radius' (metres)");
      const double radius = number(r, "'radius'");
      if (radius <= 0) fail(r, where + ": 'radius' must be above 0");
      m.tests.push_back(field_test("x_m", FieldTest::Op::greater_equal, x - radius));
      m.tests.push_back(field_test("x_m", FieldTest::Op::less_equal, x + radius));
      m.tests.push_back(field_test("y_m", FieldTest::Op::greater_equal, y - radius));
      m.tests.push_back(field_test("y_m", FieldTest::Op::less_equal, y + radius));
      m.text += std::string(m.text.empty() ? "" : " and ") + "within " + r.Scalar() + " m of (" +
                near[0].Scalar() + ", " + near[1].Scalar() + ")";
    } else if (auto r = v["radius"]) {
      fail(r, where + ": 'radius' goes with 'near'");
    }
    if (m.tests.empty()) fail(v, where + ": give station, speed_below, speed_above or near");
    return m;
  }

  /// A fault rule's kind: drop, corrupt, ...
  RecordKind fault_kind(const YAML::Node& n, const std::string& where) const {
    const std::string word = scalar(n, where);
    const auto kind = link::parse_fault_kind(word);
    if (!kind) {
      fail(n, where + ": unknown fault kind '" + word +
                  "' (known: " + link::kFaultKindNames.list() + ")" +
                  config::did_you_mean(word, link::kFaultKindNames.names()));
    }
    return *kind;
  }

  Matcher fault_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::fault;
    if (v.IsScalar()) {
      if (v.Scalar() != "*") m.kind = fault_kind(v, where);
      m.text = "fault " + v.Scalar();
      return m;
    }
    if (!v.IsMap()) fail(v, where + " must be a rule kind (drop) or a map {kind, rule, dir}");
    check_keys(v, {"kind", "rule", "dir"}, where);
    m.text = "fault";
    if (auto k = v["kind"]) {
      m.kind = fault_kind(k, where + ": 'kind'");
      m.text += " " + k.Scalar();
    }
    if (auto r = v["rule"]) {
      const std::string rule = scalar(r, "'rule'");
      m.tests.push_back(field_test("rule", FieldTest::Op::equals, rule));
      m.text += " by rule '" + rule + "'";
    }
    if (auto d = v["dir"]) {
      const std::string dir = scalar(d, "'dir'");
      if (dir != "to_car" && dir != "to_client")
        fail(d, where + ": 'dir' must be to_car or to_client");
      m.tests.push_back(field_test("dir", FieldTest::Op::equals, dir));
      m.text += " " + dir;
    }
    return m;
  }

  Matcher car_matcher(const YAML::Node& v, const std::string& where) const {
    Matcher m;
    m.source = Source::car;
    if (v.IsScalar() && v.Scalar() == "fault_state") {
      m.kind = CarEventKind::fault_state;
      m.tests.push_back(field_test("on", FieldTest::Op::equals, true));
      m.text = "car entered its fault state";
      return m;
    }
    if (!v.IsMap()) {
      fail(v, where + " must be fault_state, {fault_state: false} or {behaviour: NAME}");
    }
    check_keys(v, {"behaviour", "fault_state"}, where);
    if (auto b = v["behaviour"]) {
      if (v["fault_state"]) fail(v["fault_state"], where + ": one of behaviour, fault_state");
      const std::string name = scalar(b, "'behaviour'");
      m.kind = CarEventKind::behaviour;
      if (name != "*") m.tests.push_back(field_test("name", FieldTest::Op::equals, name));
      m.text = "car behaviour " + name + " fired";
      return m;
    }
    const bool on = boolean(v["fault_state"], "'fault_state'");
    m.kind = CarEventKind::fault_state;
    m.tests.push_back(field_test("on", FieldTest::Op::equals, on));
    m.text = on ? "car entered its fault state" : "car left its fault state";
    return m;
  }

  Matcher step_matcher(const YAML::Node& v, const std::string& phase,
                       const std::string& where) const {
    std::string wanted;
    std::string chosen_phase = phase;
    if (v.IsMap()) {
      check_keys(v, {"text", "at"}, where);
      if (!v["text"]) fail(v, where + ": 'text' is missing (the step as written, like release)");
      wanted = trim(scalar(v["text"], "'text'"));
      if (auto at = v["at"]) {
        chosen_phase = scalar(at, "'at'");
        if (chosen_phase != "start" && chosen_phase != "end") {
          fail(at, where + ": 'at' must be start or end");
        }
      }
    } else {
      wanted = trim(scalar(v, where));
    }
    const std::string text = resolve_step(v.IsMap() ? v["text"] : v, wanted, where);
    Matcher m;
    m.source = Source::step;
    m.kind = parse_record_kind(Source::step, chosen_phase);
    m.tests.push_back(field_test("text", FieldTest::Op::equals, text));
    m.text = "step '" + text + "' " + (chosen_phase == "start" ? "started" : "ended");
    return m;
  }

  /// The step text `wanted` names: a step's whole text, or the start of
  /// exactly one distinct text (whole words).
  std::string resolve_step(const YAML::Node& at, const std::string& wanted,
                           const std::string& where) const {
    if (contains(facts_.step_texts, wanted)) return wanted;
    std::set<std::string> found;
    for (const auto& t : facts_.step_texts) {
      if (t.starts_with(wanted + " ")) found.insert(t);
    }
    if (found.size() == 1) return *found.begin();
    if (found.size() > 1) {
      fail(at, where + ": '" + wanted + "' starts several steps (" +
                   join(Keys(found.begin(), found.end())) + "); write the whole text");
    }
    fail(at, where + ": no step reads '" + wanted + "' (steps: " + join(facts_.step_texts) + ")" +
                 config::did_you_mean(wanted, facts_.step_texts));
  }

 private:
  const ScenarioFacts& facts_;
};

}  // namespace

Matcher read_client_matcher(const ScenarioFacts& facts, const YAML::Node& v,
                            const std::string& where) {
  return EventMatcherReader(facts).client_matcher(v, where);
}

Matcher read_sim_matcher(const ScenarioFacts& facts, const YAML::Node& v,
                         const std::string& where) {
  return EventMatcherReader(facts).sim_matcher(v, where);
}

Matcher read_fault_matcher(const ScenarioFacts& facts, const YAML::Node& v,
                           const std::string& where) {
  return EventMatcherReader(facts).fault_matcher(v, where);
}

Matcher read_car_matcher(const ScenarioFacts& facts, const YAML::Node& v,
                         const std::string& where) {
  return EventMatcherReader(facts).car_matcher(v, where);
}

Matcher read_step_matcher(const ScenarioFacts& facts, const YAML::Node& v, const std::string& phase,
                          const std::string& where) {
  return EventMatcherReader(facts).step_matcher(v, phase, where);
}

}  // namespace hil::harness::scenario_parts
