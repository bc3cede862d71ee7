#include "harness/scenario_parts.hpp"

#include "base/enum_names.hpp"
#include "protocol/wr8/profile.hpp"

namespace hil::harness::scenario_parts {
namespace {
/// The tests a field's map may hold: `speed_cmps: {at_least: 20, below: 40}`.
constexpr auto kFieldTestWords = base::enum_names<FieldTest::Op>(
    {FieldTest::Op::not_equals, "not"}, {FieldTest::Op::contains, "contains"},
    {FieldTest::Op::less, "below"}, {FieldTest::Op::greater, "above"},
    {FieldTest::Op::greater_equal, "at_least"}, {FieldTest::Op::less_equal, "at_most"});
/// How a matcher's text writes the comparisons among them.
constexpr auto kFieldTestSymbols = base::enum_names<FieldTest::Op>(
    {FieldTest::Op::less, " < "}, {FieldTest::Op::greater, " > "},
    {FieldTest::Op::greater_equal, " >= "}, {FieldTest::Op::less_equal, " <= "});

/// The names the cars' decoded messages give their fields (docs/timeline.md,
/// "The timeline"), to catch a misspelt one; a name far from all of them is
/// let through, for a firmware's extra keys and a WR8 profile's own DATA.
Keys known_frame_fields(mocks::CarKind car) {
  switch (car) {
    case mocks::CarKind::logi:
      return {"percent",     "station", "speed_percent", "running",  "mode", "manual",
              "distance_cm", "track",   "deviation",     "obstacle", "rpm"};
    case mocks::CarKind::wr8: {
      Keys names = {"text", "device_code", "device_id",  "state",        "coi",
                    "task", "distance_cm", "angle_deg",  "timestamp_ms", "p",
                    "i",    "d",           "servo_zero", "code",         "unparsed"};
      for (const auto& p : protocol::wr8::Profile::default_data_parameters())
        names.push_back(p.unit.empty() ? p.name : p.name + "_" + p.unit);
      return names;
    }
    case mocks::CarKind::arduino:
      return {"seq", "pwm", "distance_cm", "angle_deg", "info", "code", "text"};
    case mocks::CarKind::leka:
      return {"led", "leds", "rgb", "speed", "left", "right", "id"};
  }
  return {};
}

/// Matchers: which source a map matches, wire frames, and anchors.
class MatcherReader : public config::Reader {
 public:
  explicit MatcherReader(const ScenarioFacts& facts) : config::Reader(facts.file), facts_(facts) {}

  /// A matcher written alone (wait_until, schedule `when`).
  Matcher matcher_node(const YAML::Node& n, const std::string& where) const {
    if (!n.IsMap()) {
      fail(n, where +
                  " must be a map like {wire: {received: \"MV:STOP\"}}, {client: connected} "
                  "or {sim: at_rest}");
    }
    Keys allowed = kMatcherSources;
    allowed.insert(allowed.end(), kWireDirections.begin(), kWireDirections.end());
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    if (n["step"]) allowed.push_back("at");
    check_keys(n, allowed, where);
    return matcher(n, where);
  }

  /// Reads the matcher keys of a map whose other keys were checked by the caller.
  Matcher matcher(const YAML::Node& n, const std::string& where) const {
    const std::string source =
        one_key(n, kMatcherSources, [&](const std::string& first, const std::string& second) {
          return where + ": one source per matcher ('" + first + "' and '" + second + "')";
        });
    std::string shorthand;
    for (const auto& k : kWireDirections) {
      if (n[k]) {
        if (!source.empty() || !shorthand.empty()) {
          fail(n[k], where + ": '" + k + "' is a second thing to match");
        }
        shorthand = k;
      }
    }
    if (!shorthand.empty()) return wire_matcher(n, where);
    for (const auto& k : kFrameKeys) {
      if (n[k]) fail(n[k], where + ": '" + k + "' goes with a wire frame key");
    }
    if (source.empty()) {
      fail(n, where + ": nothing to match: give one of " + join(kMatcherSources) + " (or " +
                  join(kWireDirections) + ")");
    }
    if (n["at"] && source != "step" && n["at"].IsScalar() &&
        (n["at"].Scalar() == "start" || n["at"].Scalar() == "end")) {
      fail(n["at"], where + ": 'at: start|end' goes with a step matcher");
    }
    const YAML::Node v = n[source];
    if (source == "wire") return wire(v, where + ": 'wire'");
    if (source == "client") return read_client_matcher(facts_, v, where + ": 'client'");
    if (source == "sim") return read_sim_matcher(facts_, v, where + ": 'sim'");
    if (source == "fault") return read_fault_matcher(facts_, v, where + ": 'fault'");
    if (source == "car") return read_car_matcher(facts_, v, where + ": 'car'");
    std::string phase = "end";
    if (auto at = n["at"];
        at && at.IsScalar() && (at.Scalar() == "start" || at.Scalar() == "end")) {
      phase = at.Scalar();
    }
    return read_step_matcher(facts_, v, phase, where + ": 'step'");
  }

  Matcher wire(const YAML::Node& v, const std::string& where) const {
    if (v.IsScalar()) {
      if (v.Scalar() == "open" || v.Scalar() == "close") {
        Matcher m{Source::wire,
                  parse_record_kind(Source::wire, v.Scalar()),
                  {},
                  "link " + std::string(v.Scalar() == "open" ? "opened" : "closed")};
        return m;
      }
      fail(v, where + " must be open, close, or a map like {received: \"MV:STOP\"}");
    }
    if (!v.IsMap()) fail(v, where + " must be open, close, or a map like {received: \"MV:STOP\"}");
    Keys allowed = kWireDirections;
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    allowed.push_back("by");
    check_keys(v, allowed, where);
    if (v["by"])
      fail(v["by"], where + ": 'by' goes with {wire: close} events, write {wire: close}");
    return wire_matcher(v, where);
  }

  /// `n` holds one of the direction keys and maybe valid / error.
  Matcher wire_matcher(const YAML::Node& n, const std::string& where) const {
    std::string key;
    for (const auto& k : kWireDirections) {
      if (!n[k]) continue;
      if (!key.empty()) fail(n[k], where + ": one of " + join(kWireDirections) + ", not two");
      key = k;
    }
    if (key.empty()) fail(n, where + ": give one of " + join(kWireDirections));
    const std::string frame = trim(scalar(n[key], "'" + key + "'"));
    if (frame.empty())
      fail(n[key], "'" + key + "' must be a frame kind (MV:STOP, SP) or * for any");
    Matcher m;
    m.source = Source::wire;
    m.kind = WireKind::frame;
    const bool to_car = key == "received" || key == "sent_by_client";
    const bool delivered = key == "received" || key == "received_by_client";
    m.tests.push_back(field_test("dir", FieldTest::Op::equals, to_car ? "to_car" : "to_client"));
    m.tests.push_back(field_test("stage", FieldTest::Op::equals, delivered ? "delivered" : "sent"));
    std::optional<bool> valid;
    if (auto v = n["valid"]) valid = boolean(v, "'valid'");
    const std::string what = frame == "*" ? std::string("a frame") : frame;
    // A frame that did not decode is named only as far as the decoder got
    // (a damaged FB:SP may be "FB"), so asking for invalid frames of a kind
    // also counts those whose shorter name the kind starts with.
    const auto kind_op =
        valid == false ? FieldTest::Op::kind_either_prefix : FieldTest::Op::kind_prefix;
    if (frame != "*") m.tests.push_back(field_test("frame", kind_op, frame));
    if (key == "received") m.text = "car received " + what;
    if (key == "sent_by_client") m.text = "client sent " + what;
    if (key == "sent_by_car") m.text = "car sent " + what;
    if (key == "received_by_client") m.text = "client received " + what;
    if (valid) {
      m.tests.push_back(field_test("valid", FieldTest::Op::equals, *valid));
      m.text += *valid ? " (valid)" : " (invalid)";
    }
    if (auto error = n["error"]) {
      const std::string e = scalar(error, "'error'");
      // Contains, so "checksum" finds the decoder's "bad_checksum".
      m.tests.push_back(field_test("error", FieldTest::Op::contains, e));
      m.text += " with error " + e;
    }
    if (auto t = n["text"]) bytes_test(t, "text", where, m);
    if (auto h = n["hex"]) bytes_test(h, "hex", where, m);
    if (auto message = n["message"]) {
      const std::string text = scalar(message, "'message'");
      if (text.empty()) fail(message, where + ": 'message' must not be empty");
      m.tests.push_back(field_test("message", FieldTest::Op::contains, text));
      m.text += " with message containing '" + text + "'";
    }
    if (auto f = n["fields"]) fields_tests(f, where + ": 'fields'", m);
    return m;
  }

  /// `text: "..."` (the whole frame) or `text: {contains: "..."}`, and the
  /// same for `hex`, whose digits are written as the timeline writes them.
  void bytes_test(const YAML::Node& n, const std::string& key, const std::string& where,
                  Matcher& m) const {
    const std::string what = where + ": '" + key + "'";
    const std::string example = key == "text" ? "\"LOGI:SP:050:D7#\" or {contains: \"SP:050\"}"
                                              : "\"06 01\" or {contains: \"06 01\"}";
    bool whole = true;
    YAML::Node value = n;
    if (n.IsMap()) {
      check_keys(n, {"contains"}, what);
      if (!n["contains"]) fail(n, what + " must be " + example);
      value.reset(n["contains"]);
      whole = false;
    } else if (!n.IsScalar()) {
      fail(n, what + " must be " + example);
    }
    std::string wanted = scalar(value, what);
    if (wanted.empty()) fail(value, what + " must not be empty");
    if (key == "hex") wanted = hex_digits(value, wanted, what);
    m.tests.push_back(
        field_test(key, whole ? FieldTest::Op::equals : FieldTest::Op::contains, wanted));
    m.text += " with " + key + (whole ? " " : " containing ") + "'" + wanted + "'";
  }

  /// "0601ff", "06 01 FF" -> "06 01 FF", as the timeline writes bytes.
  std::string hex_digits(const YAML::Node& n, const std::string& text,
                         const std::string& what) const {
    std::string digits;
    for (const char c : text) {
      if (c == ' ' || c == '\t') continue;
      const bool hex = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
      if (!hex) fail(n, what + " must be hex digits like \"06 01 FF\", got '" + text + "'");
      digits += static_cast<char>(c >= 'a' ? c - 'a' + 'A' : c);
    }
    if (digits.size() % 2 != 0) fail(n, what + " must be whole bytes (two hex digits each)");
    std::string out;
    for (std::size_t i = 0; i < digits.size(); i += 2)
      out += (i == 0 ? "" : " ") + digits.substr(i, 2);
    return out;
  }

  /// `fields: {percent: 50, speed_cmps: {at_least: 20, below: 40}, code: BAD_V}`.
  void fields_tests(const YAML::Node& n, const std::string& where, Matcher& m) const {
    if (!n.IsMap() || n.size() == 0) {
      fail(n, where + " must be a map of field names to values, like {percent: 50}");
    }
    static const Keys kOps = kFieldTestWords.names();
    std::set<std::string> seen;
    std::string text;
    for (auto it : n) {
      const std::string name = scalar(it.first, "a field name");
      if (name.empty() || name.find('.') != std::string::npos) {
        fail(it.first, where + ": '" + name + "' is not a field name");
      }
      if (!seen.insert(name).second) fail(it.first, where + ": '" + name + "' is given twice");
      if (const Keys known = known_frame_fields(facts_.car); !contains(known, name)) {
        if (const auto likely = closest(name, known)) {
          fail(it.first, where + ": " + car_title(facts_.car) + " frames have no field '" + name +
                             "' (they have " + join(known) + "); did you mean '" + *likely + "'?");
        }
      }
      const std::string field = "fields." + name;
      const YAML::Node v = it.second;
      text += (text.empty() ? "" : ", ") + name;
      if (v.IsScalar()) {
        m.tests.push_back(field_test(field, FieldTest::Op::equals, field_value(v.Scalar())));
        text += " = " + v.Scalar();
        continue;
      }
      if (!v.IsMap() || v.size() == 0) {
        fail(v, where + ": '" + name + "' must be a value (50, BAD_V) or a map with " + join(kOps));
      }
      check_keys(v, kOps, where + ": '" + name + "'");
      for (auto op : v) {
        const std::string k = op.first.Scalar();
        const std::string what = where + ": '" + name + "': '" + k + "'";
        const FieldTest::Op op_of = *kFieldTestWords.parse(k);  // check_keys let only these in
        if (op_of == FieldTest::Op::not_equals) {
          m.tests.push_back(field_test(field, op_of, field_value(scalar(op.second, what))));
          text += " not " + op.second.Scalar();
        } else if (op_of == FieldTest::Op::contains) {
          m.tests.push_back(field_test(field, op_of, scalar(op.second, what)));
          text += " containing '" + op.second.Scalar() + "'";
        } else {
          m.tests.push_back(field_test(field, op_of, number(op.second, what)));
          text += std::string(kFieldTestSymbols.name(op_of)) + op.second.Scalar();
        }
      }
    }
    m.text += " with " + text;
  }

  /// An anchor written as a map: matcher keys, occurrence and offset.
  Anchor anchor_map(const YAML::Node& n, const std::string& where, bool allow_times) const {
    if (n.IsScalar()) {
      if (allow_times) {
        if (const auto d = parse_duration(n.Scalar())) return Anchor{std::nullopt, 1, *d};
      }
      Anchor a;
      a.event = read_step_matcher(facts_, n, "end", where);
      return a;
    }
    if (!n.IsMap()) fail(n, where + " must be a step's text or a matcher map");
    Keys allowed = kMatcherSources;
    allowed.insert(allowed.end(), kWireDirections.begin(), kWireDirections.end());
    allowed.insert(allowed.end(), kFrameKeys.begin(), kFrameKeys.end());
    allowed.insert(allowed.end(), {"occurrence", "offset"});
    if (n["step"]) allowed.push_back("at");
    check_keys(n, allowed, where);
    Anchor a;
    a.event = matcher(n, where);
    read_occurrence(n, a, where);
    return a;
  }

  void read_occurrence(const YAML::Node& n, Anchor& a, const std::string& where) const {
    if (auto o = n["occurrence"]) {
      if (o.IsScalar() && o.Scalar() == "last") {
        a.occurrence = -1;
      } else {
        const auto count = whole(o, where + ": 'occurrence'", 1);
        if (count > 1'000'000) fail(o, where + ": 'occurrence' is too large");
        a.occurrence = static_cast<int>(count);
      }
    }
    if (auto off = n["offset"]) a.offset = signed_duration(off, where + ": 'offset'");
  }

 private:
  const ScenarioFacts& facts_;
};

}  // namespace

Matcher read_matcher_node(const ScenarioFacts& facts, const YAML::Node& n,
                          const std::string& where) {
  return MatcherReader(facts).matcher_node(n, where);
}

Matcher read_matcher(const ScenarioFacts& facts, const YAML::Node& n, const std::string& where) {
  return MatcherReader(facts).matcher(n, where);
}

Anchor read_anchor(const ScenarioFacts& facts, const YAML::Node& n, const std::string& where,
                   bool allow_times) {
  return MatcherReader(facts).anchor_map(n, where, allow_times);
}

void read_anchor_occurrence(const ScenarioFacts& facts, const YAML::Node& n, Anchor& a,
                            const std::string& where) {
  MatcherReader(facts).read_occurrence(n, a, where);
}

}  // namespace hil::harness::scenario_parts
