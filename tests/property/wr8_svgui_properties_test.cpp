// Properties of hil's client for the real smart_vehicle_gui programs
// (client/wr8/svgui_core.hpp) against their vehicle (mocks/wr8_svgui.hpp)
// on mem:// in virtual time, either version, under random faults that cut,
// join, delay, duplicate and drop whole packets and break the link, with a
// random operator session. Checked on the whole run against a tap on the
// mock server's links (what reached the client, framed by the length
// byte):
//   - the length byte frames every packet: however the stream was cut or
//     joined, the client reads exactly the DATA packets that reached it, in
//     order, from its login on, and never reads a byte as a packet of its
//     own (no parse error, no phantom login);
//   - every login the client reports is an AUTH-REPLY that reached it at
//     that instant.
// The property was seen to fail with the client broken on purpose in a copy
// of client/wr8/svgui_core.cpp (never in this tree), at 300 sessions: the
// decoder started afresh on every read, so a packet split across two reads
// is lost (falsified after 12 sessions); an AUTH-REPLY taken as a login in
// any state, so a duplicated one starts a second login (after 66).
// RC_PARAMS="seed=..." printed with a failure replays it.

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "client/wr8/svgui_session.hpp"
#include "link/link.hpp"
#include "mocks/wr8_svgui.hpp"
#include "protocol/wr8/svgui.hpp"
#include "sim/presets.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/property/random_faults.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;
using svgui::Version;

/// One connection as the mock server's link delivered it to the client.
struct Connection {
  Time opened{0};
  std::optional<Time> closed;
  std::vector<std::pair<Time, svgui::Message>> to_client;
  std::optional<svgui::Decoder> decoder;
  bool undecodable = false;
};

struct Tap : link::LinkObserver {
  Tap(std::vector<Connection>& out, Version version) : out_(out), version_(version) {}
  void on_open(Time at, const std::string&, const std::string&) override {
    out_.emplace_back();
    out_.back().opened = at;
    out_.back().decoder.emplace(version_);
  }
  void on_delivered(Time at, link::Direction d, protocol::ByteView bytes) override {
    if (d != link::Direction::to_client) return;
    Connection& c = out_.back();
    items_.clear();
    c.decoder->feed(bytes, items_);
    for (auto& item : items_) {
      if (auto* f = std::get_if<protocol::Frame<svgui::Message>>(&item)) {
        c.to_client.emplace_back(at, f->message);
      } else {
        c.undecodable = true;
      }
    }
  }
  void on_close(Time at, const link::LinkClose&) override {
    if (!out_.back().closed) out_.back().closed = at;
  }

 private:
  std::vector<Connection>& out_;
  Version version_;
  std::vector<svgui::Item> items_;
};

struct Rig {
  Rig(Version version, link::FaultProfile faults) : version(version) {
    mocks::ServerOptions options = test::on_mem("svgui");
    options.faults = std::move(faults);
    options.observers.push_back(std::make_shared<Tap>(connections, version));
    mocks::SvguiConfig car_config;
    car_config.version = version;
    car.start_car(sim::wr8_vehicle(), std::move(options), car_config);
    SvguiConfig config;
    config.version = version;
    session = std::make_unique<SvguiSession>(
        car.context, link::MemEndpoint{"svgui"}, config,
        [this](Time now, const SvguiEvent& e) { events.emplace_back(now, e); });
  }

  Version version;
  std::vector<Connection> connections;
  std::vector<std::pair<Time, SvguiEvent>> events;
  test::VirtualCar<mocks::SvguiFirmware> car;
  std::unique_ptr<SvguiSession> session;
};

/// A random operator session: connects, disconnects, and the version's
/// requests, over about a minute of virtual time.
void run_session(Rig& rig) {
  rig.session->connect();
  const int steps = *rc::gen::inRange(5, 40);
  for (int i = 0; i < steps; ++i) {
    rig.car.executor.run_for(milliseconds(*rc::gen::inRange(10, 3000)));
    switch (*rc::gen::inRange(0, 8)) {
      case 0:
        rig.session->disconnect();
        break;
      case 1:
        rig.session->connect();
        break;
      default:
        if (rig.version == Version::v2019) {
          (void)(*rc::gen::arbitrary<bool>() ? rig.session->forward(*rc::gen::inRange(-50, 50))
                                             : rig.session->wheels(*rc::gen::inRange(-30, 30)));
        } else if (*rc::gen::arbitrary<bool>()) {
          (void)rig.session->control(*rc::gen::inRange(-10, 11) / 10.0,
                                     *rc::gen::inRange(-10, 11) / 10.0);
        } else {
          (void)rig.session->set_request();
        }
        break;
    }
  }
  rig.car.executor.run_for(seconds(2));
  rig.session->disconnect();
  rig.car.executor.run_for(milliseconds(100));
}

/// The connection open at `t` (the newest, when one closes as the next opens).
const Connection* connection_at(const Rig& rig, Time t) {
  const Connection* found = nullptr;
  for (const auto& c : rig.connections) {
    if (c.opened <= t && (!c.closed || *c.closed >= t)) found = &c;
  }
  return found;
}

/// A DATA packet of either version as (its code, its timestamp).
std::optional<std::pair<int, std::uint32_t>> data_of(const svgui::Message& m) {
  if (const auto* d = std::get_if<svgui::Data>(&m)) return std::pair{6, d->timestamp_ms};
  if (const auto* l = std::get_if<svgui::LowFreqData>(&m)) return std::pair{8, l->timestamp_ms};
  if (const auto* h = std::get_if<svgui::HighFreqData>(&m)) return std::pair{9, h->timestamp_ms};
  return std::nullopt;
}
std::optional<std::pair<int, std::uint32_t>> data_of(const SvguiEvent& e) {
  if (const auto* d = std::get_if<DataEvent>(&e)) return data_of(svgui::Message{d->data});
  if (const auto* l = std::get_if<LowFreqEvent>(&e)) return data_of(svgui::Message{l->data});
  if (const auto* h = std::get_if<HighFreqEvent>(&e)) return data_of(svgui::Message{h->data});
  return std::nullopt;
}

/// One logged-in stretch of the client: from its login to the end of that
/// connection as the client saw it.
struct Stretch {
  Time login{0};
  std::optional<Time> end;
  std::vector<std::pair<Time, std::pair<int, std::uint32_t>>> data;  ///< as the client read it
};

/// Rules: every login is an AUTH-REPLY that reached the client on that
/// connection at that instant; from it on, the client reads exactly the
/// DATA packets that reached it, in order, each at the instant it arrived;
/// no byte is ever a parse error.
void check_framing(const Rig& rig) {
  for (const auto& c : rig.connections)
    RC_ASSERT(!c.undecodable);
  std::vector<Stretch> stretches;
  for (const auto& [t, e] : rig.events) {
    RC_ASSERT(!std::holds_alternative<ParseErrorEvent>(e));
    if (std::holds_alternative<LoginEvent>(e)) {
      stretches.push_back(Stretch{t, {}, {}});
    } else if (const auto* c = std::get_if<ConnectionEvent>(&e)) {
      if (!stretches.empty() && !stretches.back().end && c->state != ConnectionState::connected)
        stretches.back().end = t;
    } else if (const auto d = data_of(e)) {
      RC_ASSERT(!stretches.empty() && !stretches.back().end);  // no DATA read before a login
      stretches.back().data.emplace_back(t, *d);
    }
  }
  for (const Stretch& s : stretches) {
    const Connection* c = connection_at(rig, s.login);
    RC_ASSERT(c != nullptr);
    std::size_t at = 0;
    while (at < c->to_client.size() &&
           !(c->to_client[at].first == s.login &&
             std::holds_alternative<svgui::AuthReply>(c->to_client[at].second)))
      ++at;
    RC_ASSERT(at < c->to_client.size());  // the login's AUTH-REPLY
    // Packets and reads at the very instant the stretch ends may fall on
    // either side of the close; both lists stop short of it.
    const Time end = s.end.value_or(Time::max());
    std::vector<std::pair<Time, std::pair<int, std::uint32_t>>> delivered;
    for (std::size_t k = at + 1; k < c->to_client.size() && c->to_client[k].first < end; ++k) {
      if (const auto d = data_of(c->to_client[k].second))
        delivered.emplace_back(c->to_client[k].first, *d);
    }
    std::vector<std::pair<Time, std::pair<int, std::uint32_t>>> read;
    for (const auto& r : s.data) {
      if (r.first < end) read.push_back(r);
    }
    RC_ASSERT(read == delivered);
  }
}

RC_GTEST_PROP(Wr8SvguiClientProperties, TheLengthByteFramesEveryPacketWhateverTheSegments, ()) {
  const Version version = *rc::gen::element(Version::v2019, Version::head);
  // Faults that keep the oracle sound: whole packets cut, joined, delayed,
  // duplicated or dropped, stalls and breaks. No byte is changed, since a
  // changed byte of a length-prefixed stream is another valid stream.
  Rig rig(version, *hil::test::gen_faults_without_corruption(30, 200, 3000));
  run_session(rig);
  check_framing(rig);
}

}  // namespace
}  // namespace hil::client::wr8
