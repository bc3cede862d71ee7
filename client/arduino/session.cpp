#include "client/arduino/session.hpp"

#include <string>
#include <utility>

namespace hil::client::arduino {

ArduinoSession::ArduinoSession(link::TransportContext& context, link::Endpoint endpoint,
                               ClientConfig config)
    : context_(context),
      endpoint_(std::move(endpoint)),
      core_(config),
      wall_clock_([] { return link::wall_time_us(); }) {}

ArduinoSession::~ArduinoSession() {
  *alive_ = false;
  if (timer_ != 0) context_.executor.cancel(timer_);
  drop_pipe();
}

void ArduinoSession::open() {
  core_.open(now());
  drain();
}

void ArduinoSession::close() {
  core_.close(now());
  drain();
}

RequestId ArduinoSession::request(protocol::arduino::Body body, Callback done) {
  // Register the callback before the core can complete the request.
  const RequestId id = core_.request(now(), std::move(body));
  if (done) callbacks_[id] = std::move(done);
  drain();
  return id;
}

RequestId ArduinoSession::raw(std::string_view token, Callback done) {
  const RequestId id = core_.raw(now(), token);
  if (done) callbacks_[id] = std::move(done);
  drain();
  return id;
}

void ArduinoSession::drain() {
  // Callbacks may submit requests; the outer loop picks up what they cause.
  if (draining_) return;
  draining_ = true;
  for (;;) {
    auto actions = core_.take_actions();
    auto events = core_.take_events();
    if (actions.empty() && events.empty()) break;
    // Frames in are logged before the frames they caused go out, so the log
    // reads in wire order (a NACK BAD_CS, then its resend).
    for (auto& e : events) {
      if (auto* frame = std::get_if<FrameReceived>(&e)) {
        log_->rx(wall_clock_(), std::string(frame->raw.begin(), frame->raw.end()), frame->seq);
      }
    }
    for (auto& a : actions)
      perform(a);
    for (auto& e : events)
      dispatch(e);
  }
  draining_ = false;
  reschedule();
}

void ArduinoSession::perform(Action& action) {
  if (std::holds_alternative<SendFrame>(action)) {
    auto& send = std::get<SendFrame>(action);
    log_->tx(wall_clock_(), std::string(send.bytes.begin(), send.bytes.end()), send.seq);
    if (pipe_) pipe_->write(send.bytes);
    return;
  }
  if (std::holds_alternative<ClosePort>(action)) {
    drop_pipe();
    return;
  }
  drop_pipe();
  const std::uint64_t generation = ++generation_;
  link::connect(context_, endpoint_,
                [this, alive = alive_, generation](std::error_code ec, link::BytePipePtr pipe) {
                  if (!*alive || generation != generation_) {
                    if (pipe) pipe->close();
                    return;
                  }
                  if (ec || !pipe) {
                    core_.on_connect_failed(now(), ec ? ec.message() : "no connection");
                    drain();
                    return;
                  }
                  pipe_ = pipe;
                  pipe->start({[this, alive, generation](protocol::ByteView bytes) {
                                 if (!*alive || generation != generation_) return;
                                 core_.on_bytes(now(), bytes);
                                 drain();
                               },
                               [this, alive, generation](std::error_code) {
                                 if (!*alive || generation != generation_) return;
                                 pipe_.reset();
                                 core_.on_closed(now());
                                 drain();
                               }});
                  core_.on_connected(now());
                  drain();
                });
}

void ArduinoSession::dispatch(Event& event) {
  if (auto* done = std::get_if<RequestDone>(&event)) {
    auto it = callbacks_.find(done->id);
    if (it != callbacks_.end()) {
      Callback callback = std::move(it->second);
      callbacks_.erase(it);
      callback(done->result);
    }
  }
  if (on_event_) on_event_(event);
}

void ArduinoSession::reschedule() {
  const auto due = core_.next_wakeup();
  if (due == timer_due_) return;
  if (timer_ != 0) context_.executor.cancel(timer_);
  timer_ = 0;
  timer_due_ = due;
  if (!due) return;
  timer_ = context_.executor.call_at(*due, [this, alive = alive_] {
    if (!*alive) return;
    timer_ = 0;
    timer_due_.reset();
    core_.on_timer(now());
    drain();
  });
}

void ArduinoSession::drop_pipe() {
  ++generation_;
  if (pipe_) {
    auto pipe = std::exchange(pipe_, nullptr);
    pipe->close();
  }
}

}  // namespace hil::client::arduino
