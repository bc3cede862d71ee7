// Properties of the fault injector over every protocol: the fault events are
// a complete account of what happened to the stream, faults that keep frame
// boundaries lose exactly the frames the events name, reshaping faults lose
// nothing, and the seed alone decides the faults.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <map>
#include <set>

#include "link/faults/fault_injector.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"
#include "protocol/wr8/svgui.hpp"
#include "tests/link/faults/fault_test_support.hpp"
#include "tests/protocol/arduino/arduino_generators.hpp"
#include "tests/protocol/leka/leka_generators.hpp"
#include "tests/protocol/logi/logi_generators.hpp"
#include "tests/protocol/wr8/wr8_generators.hpp"

namespace hil::link {
namespace {

using namespace test;
namespace gen = rc::gen;

/// Which faults a generated profile may contain.
enum class Mix {
  lossless,    ///< fragment, coalesce, delay, stall, bandwidth, slow_close: the bytes arrive
               ///< unchanged
  frame_safe,  ///< also faults that keep frame boundaries: whole-frame drops, duplicates,
               ///< format-keeping corruption, garbage the decoder resynchronises past, breaks
  all,         ///< every kind, blind corruption, byte drops and limit_data included
};

/// "wr8/svgui-head" is WR8 in that profile; any other name the protocol's default.
std::shared_ptr<const ProtocolAdapter> adapter_for(const std::string& protocol) {
  const auto slash = protocol.find('/');
  if (slash == std::string::npos) return protocol_adapter(protocol);
  return protocol_adapter(protocol.substr(0, slash), protocol.substr(slash + 1));
}

/// A packet of the real WR8 programs of `version`, with its length byte.
Bytes gen_svgui_packet(protocol::wr8::svgui::Version version) {
  namespace svgui = protocol::wr8::svgui;
  const auto state = [] { return static_cast<protocol::wr8::State>(*gen::inRange(0, 4)); };
  const auto byte = [] { return *gen::arbitrary<std::uint8_t>(); };
  const auto real = [] { return *gen::arbitrary<double>(); };
  const auto u32 = [] { return *gen::arbitrary<std::uint32_t>(); };
  const auto i32 = [] { return *gen::arbitrary<std::int32_t>(); };
  svgui::Message m;
  const bool v2019 = version == svgui::Version::v2019;
  switch (*gen::inRange(0, v2019 ? 6 : 10)) {
    case 0:
      m = svgui::Auth{*gen::container<Bytes>(*gen::inRange<std::size_t>(0, 20),
                                             gen::arbitrary<std::uint8_t>())};
      break;
    case 1:
      m = svgui::AuthReply{byte(), byte(), state()};
      break;
    case 2:
      if (v2019) {
        m = svgui::Answer{byte(), byte()};
      } else {
        m = svgui::Answer{std::nullopt, byte()};
      }
      break;
    case 3:
      if (v2019) {
        m = svgui::Task{byte(), byte(),
                        *gen::container<std::vector<std::int32_t>>(*gen::inRange<std::size_t>(0, 6),
                                                                   gen::arbitrary<std::int32_t>())};
      } else {
        svgui::Set set;
        for (auto& v : set.values)
          v = real();
        m = set;
      }
      break;
    case 4:
      if (v2019) {
        m = svgui::Settings{byte(), {i32(), i32(), i32(), i32()}};
      } else {
        m = svgui::SetRequest{};
      }
      break;
    case 5:
      if (v2019) {
        m = svgui::Data{state(), u32(), i32(), real(), u32(), u32()};
      } else {
        m = svgui::HighFreqData{u32(), real(), real(), real(), real(), real()};
      }
      break;
    case 6:
      m = svgui::LowFreqData{state(), u32(), u32(), u32(), real()};
      break;
    case 7:
      m = svgui::Control{real(), real()};
      break;
    default: {
      const int width = *gen::inRange(0, 9);
      const int height = *gen::inRange(0, 7);
      svgui::Map map{static_cast<std::int8_t>(width), static_cast<std::int8_t>(height), {}};
      for (int r = 0; r < height; ++r) {
        map.rows.push_back(*gen::container<std::vector<std::int8_t>>(
            static_cast<std::size_t>(width), gen::arbitrary<std::int8_t>()));
      }
      m = map;
      break;
    }
  }
  return svgui::encode_prefixed(m, version);
}

rc::Gen<std::vector<Bytes>> gen_frames(const std::string& protocol) {
  if (protocol.starts_with("wr8/")) {
    const auto version = *protocol::wr8::svgui::version_of_profile(protocol.substr(4));
    return gen::exec([version] {
      std::vector<Bytes> frames(static_cast<std::size_t>(*gen::inRange(1, 41)));
      for (auto& f : frames)
        f = gen_svgui_packet(version);
      return frames;
    });
  }
  const auto encoded = [](auto message_gen, auto encode) {
    return gen::map(
        gen::resize(40, gen::nonEmpty(
                            gen::container<std::vector<typename decltype(message_gen)::ValueType>>(
                                message_gen))),
        [encode](const auto& ms) {
          std::vector<Bytes> frames;
          for (const auto& m : ms)
            frames.push_back(encode(m));
          return frames;
        });
  };
  if (protocol == "logi") {
    return encoded(gen::arbitrary<protocol::logi::Message>(),
                   [](const protocol::logi::Message& m) { return protocol::logi::encode(m); });
  }
  if (protocol == "arduino") {
    return encoded(
        gen::arbitrary<protocol::arduino::Message>(),
        [](const protocol::arduino::Message& m) { return protocol::arduino::encode(m); });
  }
  if (protocol == "wr8") {
    return encoded(gen::arbitrary<protocol::wr8::Message>(), [](const protocol::wr8::Message& m) {
      return protocol::wr8::encode(hil::test::fit(m, protocol::wr8::default_profile()));
    });
  }
  return encoded(gen::arbitrary<protocol::leka::Message>(),
                 [](const protocol::leka::Message& m) { return protocol::leka::encode(m); });
}

rc::Gen<Duration> gen_ms(int lo, int hi) {
  return gen::map(gen::inRange(lo, hi + 1),
                  [](int ms) { return Duration{std::chrono::milliseconds(ms)}; });
}

Trigger timed(Duration at) {
  Trigger t;
  t.at = at;
  return t;
}

Trigger nth_frame(std::uint64_t n) {
  Trigger t;
  t.at_frame = n;
  return t;
}

Trigger gen_frame_trigger(const std::vector<std::string>& kinds) {
  Trigger t;
  switch (*gen::inRange(0, 6)) {
    case 0:
      t.probability = *gen::inRange(1, 10) / 10.0;
      break;
    case 1:
      t.at_frame = *gen::inRange<std::uint64_t>(1, 20);
      break;
    case 2:
      t.first = *gen::inRange<std::uint64_t>(1, 5);
      break;
    case 3:
      t.every = *gen::inRange<std::uint64_t>(2, 5);
      break;
    default:
      break;  // every frame
  }
  if (!kinds.empty() && *gen::inRange(0, 4) == 0) t.match = *gen::elementOf(kinds);
  return t;
}

/// One rule of `mix` for frames of `protocol` (whose kinds are `kinds`).
FaultRule gen_rule(Mix mix, const std::string& protocol, const std::vector<std::string>& kinds) {
  std::vector<FaultKind> choices = {FaultKind::fragment,  FaultKind::coalesce,
                                    FaultKind::delay,     FaultKind::stall,
                                    FaultKind::bandwidth, FaultKind::slow_close};
  if (mix != Mix::lossless) {
    choices.insert(choices.end(), {FaultKind::drop, FaultKind::duplicate, FaultKind::corrupt,
                                   FaultKind::disconnect, FaultKind::reset});
    // WR8 has no resynchronisation: any byte may start a packet (or be
    // read as a length byte).
    if (mix == Mix::all || !protocol.starts_with("wr8")) choices.push_back(FaultKind::garbage);
  }
  if (mix == Mix::all) choices.insert(choices.end(), {FaultKind::refuse, FaultKind::limit_data});

  FaultRule r;
  r.trigger = gen_frame_trigger(kinds);
  if (*gen::inRange(0, 5) == 0) r.window.from = *gen_ms(0, 200);
  switch (*gen::elementOf(choices)) {
    case FaultKind::fragment: {
      Fragment f;
      f.piece_bytes.min = *gen::inRange<std::size_t>(1, 8);
      f.piece_bytes.max = f.piece_bytes.min + *gen::inRange<std::size_t>(0, 8);
      f.gap.min = *gen_ms(0, 2);
      f.gap.max = f.gap.min + *gen_ms(0, 3);
      r.action = f;
      break;
    }
    case FaultKind::coalesce: {
      Coalesce c;
      if (*gen::arbitrary<bool>()) c.count = *gen::inRange<std::size_t>(2, 5);
      if (c.count == 0 || *gen::arbitrary<bool>()) c.window = *gen_ms(1, 30);
      r.action = c;
      break;
    }
    case FaultKind::delay:
      r.action = Delay{*gen_ms(0, 20), *gen_ms(0, 20)};
      break;
    case FaultKind::stall:
      r.action = Stall{*gen_ms(1, 50)};
      if (!r.trigger.has_frame_condition() || *gen::arbitrary<bool>())
        r.trigger = timed(*gen_ms(0, 300));
      break;
    case FaultKind::bandwidth:
      r.trigger = {};
      r.action = Bandwidth{*gen::inRange<std::uint64_t>(1'000, 100'000)};
      break;
    case FaultKind::drop: {
      Drop d;
      if (mix == Mix::all && *gen::arbitrary<bool>()) {
        d.unit = DropUnit::bytes;
        d.count.min = *gen::inRange<std::size_t>(1, 4);
        d.count.max = d.count.min + *gen::inRange<std::size_t>(0, 4);
      }
      r.action = d;
      break;
    }
    case FaultKind::duplicate:
      r.action = Duplicate{*gen::inRange<std::size_t>(1, 3)};
      break;
    case FaultKind::corrupt: {
      Corrupt c;
      c.target = CorruptTarget::checksum;
      const bool text = protocol == "logi" || protocol == "arduino";
      if (mix == Mix::all) {
        c.target =
            *gen::element(CorruptTarget::checksum, CorruptTarget::field, CorruptTarget::random);
        c.bits = *gen::inRange<std::size_t>(1, 4);
      } else if (text && *gen::arbitrary<bool>()) {
        // One changed byte always breaks a sum or XOR checksum.
        c.target = CorruptTarget::field;
      }
      if (c.target == CorruptTarget::field) {
        c.field = *gen::elementOf(adapter_for(protocol)->field_names());
      }
      r.action = c;
      break;
    }
    case FaultKind::garbage: {
      Garbage g;
      g.length.min = *gen::inRange<std::size_t>(1, 8);
      g.length.max = g.length.min + *gen::inRange<std::size_t>(0, 8);
      r.action = g;
      break;
    }
    case FaultKind::disconnect:
    case FaultKind::reset: {
      const bool reset = *gen::arbitrary<bool>();
      r.action = reset ? FaultAction{Reset{}} : FaultAction{Disconnect{}};
      if (r.trigger == Trigger{} || r.trigger.probability)
        r.trigger = nth_frame(*gen::inRange<std::uint64_t>(1, 30));
      if (mix == Mix::all && *gen::arbitrary<bool>()) r.trigger = timed(*gen_ms(0, 400));
      break;
    }
    case FaultKind::slow_close:
      r.trigger = {};
      r.action = SlowClose{*gen_ms(0, 50)};
      break;
    case FaultKind::limit_data:
      r.trigger = {};
      r.action = LimitData{*gen::inRange<std::uint64_t>(1, 400)};
      break;
    default:
      r.trigger = timed(*gen_ms(0, 100));
      r.action = Refuse{*gen_ms(1, 100)};
      break;
  }
  return r;
}

struct Case {
  std::string protocol;
  std::vector<Bytes> frames;
  std::vector<Write> writes;
  FaultProfile profile;
  std::uint64_t seed = 0;
};

/// A frame stream of one protocol, written in random pieces at increasing
/// times, and a random profile of `mix`.
Case gen_case(Mix mix) {
  Case c;
  c.protocol = *gen::element<std::string>("logi", "arduino", "wr8", "leka", "wr8/svgui-2019",
                                          "wr8/svgui-head");
  c.frames = *gen_frames(c.protocol);
  const Bytes stream = concat(c.frames);
  std::vector<std::string> kinds;
  for (const auto& f : decode(*adapter_for(c.protocol), stream)) {
    RC_ASSERT(f.valid);
    kinds.push_back(f.kind);
  }
  RC_ASSERT(kinds.size() == c.frames.size());
  Time at{0};
  for (std::size_t pos = 0; pos < stream.size();) {
    const std::size_t n = std::min(stream.size() - pos, *gen::inRange<std::size_t>(1, 80));
    at += *gen_ms(0, 10);
    c.writes.push_back(Write{at, Bytes(stream.begin() + static_cast<std::ptrdiff_t>(pos),
                                       stream.begin() + static_cast<std::ptrdiff_t>(pos + n))});
    pos += n;
  }
  const int rules = *gen::inRange(1, 6);
  bool corrupting = false;
  for (int i = 0; i < rules; ++i) {
    FaultRule r = gen_rule(mix, c.protocol, kinds);
    // Two changes to one frame can cancel out in a sum or XOR checksum and
    // leave a valid, different frame: frame_safe corrupts with one rule only.
    const bool corrupt = r.kind() == FaultKind::corrupt;
    if (mix == Mix::frame_safe && corrupt && corrupting) continue;
    corrupting = corrupting || corrupt;
    c.profile.rules.push_back(std::move(r));
  }
  c.seed = *gen::arbitrary<std::uint64_t>();
  return c;
}

struct Outcome {
  Run run;
  std::uint64_t frames_seen = 0;
};

Outcome run_case(const Case& c) {
  std::vector<FaultEvent> events;
  auto injector = make_injector(adapter_for(c.protocol), c.profile, events, c.seed);
  Outcome o{drive(*injector, c.writes), injector->frames_seen()};
  o.run.events = std::move(events);
  return o;
}

void assert_one_break_at_the_end(const Run& run) {
  for (std::size_t i = 0; i < run.outputs.size(); ++i) {
    if (std::holds_alternative<LinkBreak>(run.outputs[i].what))
      RC_ASSERT(i + 1 == run.outputs.size());
  }
  for (std::size_t i = 1; i < run.outputs.size(); ++i)
    RC_ASSERT(run.outputs[i].at >= run.outputs[i - 1].at);
}

bool changes_bytes(FaultKind kind) {
  return kind == FaultKind::drop || kind == FaultKind::corrupt || kind == FaultKind::duplicate ||
         kind == FaultKind::garbage;
}

RC_GTEST_PROP(FaultProperties, EventsAccountForEveryDeliveredByte, ()) {
  const Case c = gen_case(Mix::all);
  const auto [run, frames_seen] = run_case(c);
  RC_TAG(c.protocol);
  RC_CLASSIFY(!run.events.empty(), "faults injected");
  RC_CLASSIFY(run.link_break() != nullptr, "link broken");
  assert_one_break_at_the_end(run);
  RC_ASSERT(frames_seen <= c.frames.size());

  // Replay the events on the input frames: each byte-changing event must
  // start from what the frame was at that point.
  std::vector<Bytes> now(c.frames.begin(),
                         c.frames.begin() + static_cast<std::ptrdiff_t>(frames_seen));
  std::optional<Bytes> lost_at_break;
  std::optional<FaultEvent> limit;  // the limit_data event that closed the link
  for (const auto& e : run.events) {
    RC_ASSERT(e.direction == Direction::to_car);
    if (changes_bytes(e.kind)) {
      RC_ASSERT(e.frame >= 1 && e.frame <= frames_seen);
      RC_ASSERT(e.before == now[e.frame - 1]);
      now[e.frame - 1] = e.after;
    } else if ((e.kind == FaultKind::disconnect || e.kind == FaultKind::reset) && e.frame == 0) {
      lost_at_break = e.before;
    } else if (e.kind == FaultKind::limit_data) {
      RC_ASSERT(!limit);
      RC_ASSERT(e.after.size() <= e.before.size());
      RC_ASSERT(std::equal(e.after.begin(), e.after.end(), e.before.begin()));
      limit = e;
    } else {
      RC_ASSERT(e.before == e.after);
    }
  }
  Bytes expected = concat(now);
  if (lost_at_break) {
    RC_ASSERT(expected.size() >= lost_at_break->size());
    RC_ASSERT(std::equal(lost_at_break->begin(), lost_at_break->end(),
                         expected.end() - static_cast<std::ptrdiff_t>(lost_at_break->size())));
    expected.resize(expected.size() - lost_at_break->size());
  }
  RC_CLASSIFY(limit.has_value(), "limit reached");
  if (limit) {
    // The stream is cut inside the write that reached the limit: what was
    // delivered ends with the part of it that passed, and the rest of the
    // write (and whatever came after it) is what the events leave unsent.
    RC_ASSERT(!lost_at_break);
    const Bytes delivered = run.delivered();
    RC_ASSERT(delivered.size() >= limit->after.size());
    const std::size_t write_begins = delivered.size() - limit->after.size();
    RC_ASSERT(expected.size() >= write_begins + limit->before.size());
    RC_ASSERT(std::equal(delivered.begin(), delivered.end(), expected.begin()));
    RC_ASSERT(std::equal(limit->before.begin(), limit->before.end(),
                         expected.begin() + static_cast<std::ptrdiff_t>(write_begins)));
    RC_ASSERT(run.link_break() != nullptr && !run.link_break()->reset);
    return;
  }
  RC_ASSERT(run.delivered() == expected);
  if (!run.link_break()) RC_ASSERT(frames_seen == c.frames.size());
}

RC_GTEST_PROP(FaultProperties, FarSideDecodesExactlyTheFramesTheEventsLeave, ()) {
  const Case c = gen_case(Mix::frame_safe);
  const auto [run, frames_seen] = run_case(c);
  RC_CLASSIFY(!run.events.empty(), "faults injected");
  std::set<std::uint64_t> gone;
  std::map<std::uint64_t, std::size_t> copies;  // a second duplicate rule copies the copies
  for (const auto& e : run.events) {
    if (e.kind == FaultKind::drop || e.kind == FaultKind::corrupt) gone.insert(e.frame);
    if (e.kind == FaultKind::duplicate) {
      auto [it, fresh] = copies.try_emplace(e.frame, 1);
      it->second *= e.after.size() / e.before.size();
    }
  }
  std::vector<Bytes> expected;
  for (std::uint64_t n = 1; n <= frames_seen; ++n) {
    if (gone.contains(n)) continue;
    const std::size_t count = copies.contains(n) ? copies[n] : 1;
    for (std::size_t k = 0; k < count; ++k)
      expected.push_back(c.frames[n - 1]);
  }
  std::vector<Bytes> decoded;
  for (const auto& f : decode(*adapter_for(c.protocol), run.delivered())) {
    if (f.valid) decoded.push_back(f.raw);
  }
  RC_ASSERT(decoded == expected);
}

RC_GTEST_PROP(FaultProperties, FragmentCoalesceDelayStallAndBandwidthLoseNothing, ()) {
  const Case c = gen_case(Mix::lossless);
  const auto [run, frames_seen] = run_case(c);
  RC_ASSERT(run.delivered() == concat(c.frames));
  RC_ASSERT(run.link_break() == nullptr);
  RC_ASSERT(frames_seen == c.frames.size());
  assert_one_break_at_the_end(run);
}

bool same_event(const FaultEvent& a, const FaultEvent& b) {
  return a.at == b.at && a.direction == b.direction && a.kind == b.kind && a.rule == b.rule &&
         a.frame == b.frame && a.before == b.before && a.after == b.after && a.detail == b.detail;
}

bool same_timeline(const Run& a, const Run& b) {
  if (a.events.size() != b.events.size() || a.outputs.size() != b.outputs.size()) return false;
  for (std::size_t i = 0; i < a.events.size(); ++i) {
    if (!same_event(a.events[i], b.events[i])) return false;
  }
  for (std::size_t i = 0; i < a.outputs.size(); ++i) {
    if (a.outputs[i].at != b.outputs[i].at ||
        a.outputs[i].what.index() != b.outputs[i].what.index())
      return false;
    const auto* da = std::get_if<Delivery>(&a.outputs[i].what);
    const auto* db = std::get_if<Delivery>(&b.outputs[i].what);
    if (da && da->bytes != db->bytes) return false;
  }
  return true;
}

RC_GTEST_PROP(FaultProperties, SameSeedSameTimeline, ()) {
  const Case c = gen_case(Mix::all);
  RC_ASSERT(same_timeline(run_case(c).run, run_case(c).run));
}

RC_GTEST_PROP(FaultProperties, DifferentSeedsGiveDifferentFaults,
              (std::uint64_t seed_a, std::uint64_t seed_b)) {
  RC_PRE(seed_a != seed_b);
  Case c;
  c.protocol = "raw";
  for (int i = 0; i < 100; ++i)
    c.writes.push_back(Write{Time{std::chrono::milliseconds(i)}, Bytes{std::uint8_t(i)}});
  FaultRule drop;
  drop.action = Drop{};
  drop.trigger.probability = 0.5;
  c.profile.rules = {drop};
  c.seed = seed_a;
  const auto a = run_case(c);
  c.seed = seed_b;
  const auto b = run_case(c);
  // Equal only if 100 fair coin flips all agree: probability 2^-100.
  RC_ASSERT(!same_timeline(a.run, b.run));
}

}  // namespace
}  // namespace hil::link
