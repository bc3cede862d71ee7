#include "client/wr8/session.hpp"

#include <utility>

namespace hil::client::wr8 {

Wr8Session::Wr8Session(link::TransportContext& context, link::Endpoint endpoint,
                       ClientConfig config, EventSink sink, std::shared_ptr<CommLog> log)
    : context_(context),
      endpoint_(std::move(endpoint)),
      sink_(std::move(sink)),
      core_(std::move(config), std::move(log)) {}

Wr8Session::~Wr8Session() {
  *alive_ = false;
  if (timer_ != 0) context_.executor.cancel(timer_);
  if (pipe_) pipe_->close();
}

void Wr8Session::connect() {
  core_.connect(now());
  flush();
}

void Wr8Session::disconnect() {
  core_.disconnect(now());
  flush();
}

SubmitResult Wr8Session::task(proto::TaskCode code, std::vector<proto::Word> params) {
  auto r = core_.task(now(), code, std::move(params));
  flush();
  return r;
}

SubmitResult Wr8Session::drive(std::int32_t distance_cm) {
  auto r = core_.drive(now(), distance_cm);
  flush();
  return r;
}

SubmitResult Wr8Session::turn(std::int32_t angle_deg) {
  auto r = core_.turn(now(), angle_deg);
  flush();
  return r;
}

SubmitResult Wr8Session::get_settings() {
  auto r = core_.get_settings(now());
  flush();
  return r;
}

SubmitResult Wr8Session::set_settings(std::vector<proto::Setting> settings) {
  auto r = core_.set_settings(now(), std::move(settings));
  flush();
  return r;
}

void Wr8Session::open() {
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

void Wr8Session::flush() {
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
          pipe_->write(protocol::ByteView(send->bytes.data(), send->bytes.size()));
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

void Wr8Session::reschedule() {
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

}  // namespace hil::client::wr8
