#include "client/logi/session.hpp"

#include <utility>

namespace hil::client::logi {

LogiSession::LogiSession(link::TransportContext& context, link::Endpoint endpoint,
                         ClientConfig config, EventSink sink, std::shared_ptr<CommLog> log)
    : context_(context),
      endpoint_(std::move(endpoint)),
      sink_(std::move(sink)),
      core_(std::move(config), std::move(log)) {}

LogiSession::~LogiSession() {
  *alive_ = false;
  if (timer_ != 0) context_.executor.cancel(timer_);
  if (pipe_) pipe_->close();
}

void LogiSession::connect() {
  core_.connect(now());
  flush();
}

void LogiSession::disconnect() {
  core_.disconnect(now());
  flush();
}

SubmitResult LogiSession::submit(const proto::Message& command) {
  auto r = core_.submit(now(), command);
  flush();
  return r;
}

SubmitResult LogiSession::press(proto::Direction direction) {
  auto r = core_.press(now(), direction);
  flush();
  return r;
}

SubmitResult LogiSession::release() {
  auto r = core_.release(now());
  flush();
  return r;
}

SubmitResult LogiSession::emergency_stop() {
  auto r = core_.emergency_stop(now());
  flush();
  return r;
}

SubmitResult LogiSession::confirm_resend(RequestId request) {
  auto r = core_.confirm_resend(now(), request);
  flush();
  return r;
}

void LogiSession::open() {
  const std::uint64_t generation = ++generation_;
  std::weak_ptr<bool> alive = alive_;
  link::connect(context_, endpoint_,
                [this, alive, generation](std::error_code ec, link::BytePipePtr pipe) {
                  if (const auto a = alive.lock(); !a || !*a) {
                    if (pipe) pipe->close();
                    return;
                  }
                  if (generation != generation_) {  // the operator gave up on this attempt
                    if (pipe) pipe->close();
                    return;
                  }
                  if (ec || !pipe) {
                    core_.on_connect_failed(now());
                    flush();
                    return;
                  }
                  pipe_ = pipe;
                  pipe->start({[this, alive, generation](protocol::ByteView bytes) {
                                 if (const auto a = alive.lock(); !a || !*a) return;
                                 if (generation != generation_) return;
                                 core_.on_bytes(now(), bytes);
                                 flush();
                               },
                               [this, alive, generation](std::error_code) {
                                 if (const auto a = alive.lock(); !a || !*a) return;
                                 if (generation != generation_) return;
                                 pipe_.reset();
                                 core_.on_closed(now());
                                 flush();
                               }});
                  core_.on_connected(now());
                  flush();
                });
}

void LogiSession::flush() {
  // Actions may complete synchronously in a driver; never re-enter.
  if (flushing_) return;
  flushing_ = true;
  for (;;) {
    auto actions = core_.take_actions();
    auto events = core_.take_events();
    if (actions.empty() && events.empty()) break;
    for (const auto& action : actions) {
      if (std::holds_alternative<OpenConnection>(action)) {
        open();
      } else if (const auto* send = std::get_if<SendBytes>(&action)) {
        if (pipe_) {
          pipe_->write(protocol::ByteView(reinterpret_cast<const std::uint8_t*>(send->text.data()),
                                          send->text.size()));
        }
      } else if (std::holds_alternative<CloseConnection>(action)) {
        ++generation_;  // what the old connection still reports is not news
        if (pipe_) pipe_->close();
        pipe_.reset();
      }
    }
    if (sink_) {
      for (const auto& event : events)
        sink_(now(), event);
    }
  }
  flushing_ = false;
  reschedule();
}

void LogiSession::reschedule() {
  const std::optional<Time> next = core_.next_wakeup();
  if (next == timer_due_ && (timer_ != 0 || !next)) return;
  if (timer_ != 0) context_.executor.cancel(timer_);
  timer_ = 0;
  timer_due_ = next;
  if (!next) return;
  std::weak_ptr<bool> alive = alive_;
  timer_ = context_.executor.call_at(*next, [this, alive] {
    if (const auto a = alive.lock(); !a || !*a) return;
    timer_ = 0;
    timer_due_.reset();
    core_.on_timer(now());
    flush();
  });
}

}  // namespace hil::client::logi
