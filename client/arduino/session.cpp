#include "client/arduino/session.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace hil::client::arduino {

namespace {

std::unique_ptr<ArduinoClientCore> checked(std::unique_ptr<ArduinoClientCore> core) {
  if (!core) throw std::invalid_argument("ArduinoSession: no client core given");
  return core;
}

}  // namespace

ArduinoSession::ArduinoSession(link::TransportContext& context, link::Endpoint endpoint,
                               ClientConfig config)
    : ArduinoSession(context, std::move(endpoint), std::make_unique<ArduinoClientCore>(config)) {}

ArduinoSession::ArduinoSession(link::TransportContext& context, link::Endpoint endpoint,
                               std::unique_ptr<ArduinoClientCore> core)
    : core_(checked(std::move(core))),
      wall_clock_([] { return link::wall_time_us(); }),
      binding_(context, std::move(endpoint),
               core_handlers(
                   *core_, [this] { return now(); }, [this] { drain(); })) {}

void ArduinoSession::open() {
  core_->open(now());
  drain();
}

void ArduinoSession::close() {
  core_->close(now());
  drain();
}

RequestId ArduinoSession::request(protocol::arduino::Body body, Callback done) {
  // Register the callback before the core can complete the request.
  const RequestId id = core_->request(now(), std::move(body));
  callbacks_.add(id, std::move(done));
  drain();
  return id;
}

RequestId ArduinoSession::raw(std::string_view token, Callback done) {
  const RequestId id = core_->raw(now(), token);
  callbacks_.add(id, std::move(done));
  drain();
  return id;
}

void ArduinoSession::drain() {
  // Callbacks may submit requests; the loop picks up what they cause.
  drain_core(*core_, draining_, [this](auto& actions, auto& events) {
    // Frames in are logged before the frames they caused go out, so the log
    // reads in wire order (a NACK BAD_CS, then its resend).
    for (auto& e : events) {
      if (auto* frame = std::get_if<FrameReceived>(&e)) {
        log_->add({LogKind::rx, wall_clock_(), std::string(frame->raw.begin(), frame->raw.end()),
                   frame->seq});
      }
    }
    for (auto& a : actions)
      perform(a);
    for (auto& e : events)
      dispatch(e);
  });
  binding_.schedule(core_->next_wakeup());
}

void ArduinoSession::perform(Action& action) {
  if (auto* send = std::get_if<SendFrame>(&action)) {
    log_->add({LogKind::tx, wall_clock_(), std::string(send->bytes.begin(), send->bytes.end()),
               send->seq});
    binding_.write(send->bytes);
  } else if (std::holds_alternative<ClosePort>(action)) {
    binding_.close();
  } else {
    binding_.open();
  }
}

void ArduinoSession::dispatch(Event& event) {
  if (auto* done = std::get_if<RequestDone>(&event)) callbacks_.complete(done->id, done->result);
  if (on_event_) on_event_(event);
}

}  // namespace hil::client::arduino
