#include "client/leka/session.hpp"

#include <string>
#include <utility>

namespace hil::client::leka {

LekaSession::LekaSession(link::TransportContext& context, link::Endpoint endpoint,
                         ClientConfig config)
    : context_(context),
      endpoint_(std::move(endpoint)),
      core_(config),
      wall_clock_([] { return link::wall_time_us(); }) {}

LekaSession::~LekaSession() {
  *alive_ = false;
  if (timer_ != 0) context_.executor.cancel(timer_);
  drop_pipe();
}

void LekaSession::open() {
  drop_pipe();
  const std::uint64_t generation = ++generation_;
  link::connect(context_, endpoint_,
                [this, alive = alive_, generation](std::error_code ec, link::BytePipePtr pipe) {
                  if (!*alive || generation != generation_) {
                    if (pipe) pipe->close();
                    return;
                  }
                  if (ec || !pipe) return;
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

void LekaSession::close() {
  drop_pipe();
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
  if (done) callbacks_[id] = std::move(done);
  drain();
  return id;
}

void LekaSession::drain() {
  if (draining_) return;
  draining_ = true;
  for (;;) {
    auto actions = core_.take_actions();
    auto events = core_.take_events();
    if (actions.empty() && events.empty()) break;
    for (auto& e : events) {
      if (auto* line = std::get_if<LineReceived>(&e)) {
        log_->add({LogDirection::rx, wall_clock_(),
                   protocol::Bytes(line->line.begin(), line->line.end()), line->line});
      }
    }
    for (auto& a : actions) {
      std::string note;
      if (auto item = proto::decode_frame(a.bytes);
          auto* frame = std::get_if<protocol::Frame<proto::Message>>(&item))
        note = proto::describe(frame->message);
      log_->add({LogDirection::tx, wall_clock_(), a.bytes, std::move(note)});
      if (pipe_) pipe_->write(a.bytes);
    }
    for (auto& e : events) {
      if (auto* done = std::get_if<InfoDone>(&e)) {
        auto it = callbacks_.find(done->id);
        if (it != callbacks_.end()) {
          auto callback = std::move(it->second);
          callbacks_.erase(it);
          callback(done->result);
        }
      }
    }
  }
  draining_ = false;
  reschedule();
}

void LekaSession::reschedule() {
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

void LekaSession::drop_pipe() {
  ++generation_;
  if (pipe_) std::exchange(pipe_, nullptr)->close();
}

}  // namespace hil::client::leka
