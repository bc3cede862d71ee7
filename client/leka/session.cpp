#include "client/leka/session.hpp"

#include <string>
#include <utility>

namespace hil::client::leka {

LekaSession::LekaSession(link::TransportContext& context, link::Endpoint endpoint,
                         ClientConfig config)
    : core_(config),
      wall_clock_([] { return link::wall_time_us(); }),
      binding_(context, std::move(endpoint), handlers()) {}

PipeBinding::Handlers LekaSession::handlers() {
  auto h = core_handlers(
      core_, [this] { return now(); }, [this] { drain(); });
  // The core has no notion of a failed open; the session keeps the reason.
  h.connect_failed = [this](std::error_code ec) { open_error_ = ec.message(); };
  auto connected = std::move(h.connected);
  h.connected = [this, connected] {
    open_error_.clear();
    connected();
  };
  return h;
}

void LekaSession::open() {
  binding_.open();
}

void LekaSession::close() {
  binding_.close();
  core_.on_closed(now());
  drain();
}

BuildResult LekaSession::send(const GroupBuilder& builder) {
  auto result = core_.send(now(), builder);
  drain();
  return result;
}

RequestId LekaSession::info(InfoCallback done) {
  const RequestId id = core_.info(now());
  callbacks_.add(id, std::move(done));
  drain();
  return id;
}

void LekaSession::drain() {
  drain_core(core_, draining_, [this](auto& actions, auto& events) {
    for (auto& e : events) {
      if (auto* line = std::get_if<LineReceived>(&e)) {
        log_->add({LogKind::rx, wall_clock_(),
                   protocol::Bytes(line->line.begin(), line->line.end()), line->line});
      }
    }
    for (auto& a : actions) {
      std::string note;
      if (auto item = proto::decode_frame(a.bytes);
          auto* frame = std::get_if<protocol::Frame<proto::Message>>(&item))
        note = proto::describe(frame->message);
      log_->add({LogKind::tx, wall_clock_(), a.bytes, std::move(note)});
      binding_.write(a.bytes);
    }
    for (auto& e : events) {
      if (auto* done = std::get_if<InfoDone>(&e)) callbacks_.complete(done->id, done->result);
    }
  });
  binding_.schedule(core_.next_wakeup());
}

}  // namespace hil::client::leka
