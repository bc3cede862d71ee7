#include "client/logi/core.hpp"

#include <algorithm>
#include <utility>

#include "base/enum_names.hpp"

namespace hil::client::logi {

constexpr auto kLogiCommandStateNames = base::enum_names<CommandState>(
    {CommandState::sent, "sent"}, {CommandState::accepted, "accepted"},
    {CommandState::rejected, "rejected"}, {CommandState::uncertain, "uncertain"},
    {CommandState::cancelled, "cancelled"});

constexpr auto kLogiRefusalTexts =
    base::enum_names<Refusal>({Refusal::none, "none"}, {Refusal::not_connected, "not connected"},
                              {Refusal::mode_speed_unconfirmed,
                               "mode and speed not confirmed on this connection (send MD and SP)"},
                              {Refusal::not_held, "no direction held"},
                              {Refusal::unknown_request, "no such request awaits confirmation"},
                              {Refusal::not_a_command, "not a command"});

std::string_view to_string(CommandState s) {
  return kLogiCommandStateNames.name(s);
}

std::string_view to_string(Refusal r) {
  return kLogiRefusalTexts.name(r);
}

namespace {

ClientConfig with_reconnect_delays(ClientConfig config) {
  if (config.reconnect_delays.empty()) config.reconnect_delays = {link::seconds(1)};
  return config;
}

}  // namespace

LogiClientCore::LogiClientCore(ClientConfig config, std::shared_ptr<CommLog> log)
    : ConnectionCore(std::move(log),
                     Backoff::ladder(with_reconnect_delays(config).reconnect_delays)),
      config_(with_reconnect_delays(std::move(config))),
      decoder_(config_.decoder) {}

// ---- connection ----

void LogiClientCore::connect(Time now) {
  if (open_wanted(now, 0)) update_movement();
}

void LogiClientCore::disconnect(Time now) {
  close_unwanted();
  if (state() == ConnectionState::disconnected) return;
  note(now, "disconnect");
  lost(now, "disconnected by the operator");
  set_state(ConnectionState::disconnected);
}

void LogiClientCore::on_connected(Time now) {
  if (state() != ConnectionState::connecting) return;
  // The reconnect ladder starts again only once the car has sent a valid
  // frame (on_frame): a car that accepts and hangs up at once is a failed
  // attempt, not a reason to hammer it every second.
  decoder_ = proto::Decoder(config_.decoder);
  last_stat_ = now;
  mode_confirmed_ = false;
  speed_confirmed_ = false;
  mode_.reset();
  note(now, "connected");
  set_state(ConnectionState::connected);
}

void LogiClientCore::on_connect_failed(Time now) {
  if (state() != ConnectionState::connecting) return;
  note(now, "connect failed");
  reconnect_or_stop(now);
}

void LogiClientCore::on_closed(Time now) {
  if (state() != ConnectionState::connected) return;
  note(now, "connection lost");
  lost(now, "connection lost");
  reconnect_or_stop(now);
}

void LogiClientCore::reconnect_or_stop(Time now) {
  if (!connection_.wanted()) {
    set_state(ConnectionState::disconnected);
    return;
  }
  auto& reconnect = connection_.reconnect();
  const Duration delay = reconnect.next_delay();
  reconnect.schedule_at(reconnect_time(now, delay));
  note(now, "reconnect attempt " + std::to_string(reconnect.attempt()) + " in " +
                link::format_ms(delay));
  set_state(ConnectionState::reconnecting, reconnect.attempt());
}

void LogiClientCore::lost(Time now, std::string_view why) {
  // The safe state: nothing held, nothing queued, movement needs a fresh
  // confirmation of mode and speed on the next connection.
  held_.reset();
  keepalive_at_.reset();
  for (auto* list : {&flight_, &queue_}) {
    for (auto& p : *list) {
      emit(CommandEvent{p.id, p.command, CommandState::cancelled, p.attempt, false});
    }
    list->clear();
  }
  awaiting_confirm_.clear();
  mode_confirmed_ = false;
  speed_confirmed_ = false;
  mode_.reset();
  decoder_ = proto::Decoder(config_.decoder);
  note(now, std::string("safe state: ") + std::string(why));
}

void LogiClientCore::set_state(ConnectionState s, int attempt) {
  if (change_state(s, attempt)) update_movement();
}

bool LogiClientCore::movement_enabled() const {
  return state() == ConnectionState::connected && mode_confirmed_ && speed_confirmed_;
}

void LogiClientCore::update_movement() {
  const bool enabled = movement_enabled();
  if (movement_reported_ && movement_reported_value_ == enabled) return;
  movement_reported_ = true;
  movement_reported_value_ = enabled;
  std::string reason;
  if (!enabled) {
    reason = state() != ConnectionState::connected
                 ? std::string(to_string(Refusal::not_connected))
                 : std::string(to_string(Refusal::mode_speed_unconfirmed));
  }
  emit(MovementEvent{enabled, std::move(reason)});
}

// ---- operator requests ----

bool LogiClientCore::is_movement(const proto::Message& m) {
  if (const auto* mv = std::get_if<proto::Move>(&m)) return mv->direction != proto::Direction::stop;
  if (const auto* st = std::get_if<proto::SetRun>(&m)) return st->run;
  return false;
}

bool LogiClientCore::retryable(const proto::Message& m) const {
  if (std::holds_alternative<proto::SetSpeed>(m)) return true;
  if (std::holds_alternative<proto::SetMode>(m)) return true;
  const auto* mv = std::get_if<proto::Move>(&m);
  return mv != nullptr && mv->direction == proto::Direction::stop;
}

bool LogiClientCore::resend_on_confirm(const proto::Message& m) {
  if (const auto* st = std::get_if<proto::SetRun>(&m)) return st->run;
  return std::holds_alternative<proto::SetStation>(m);
}

SubmitResult LogiClientCore::submit(Time now, const proto::Message& command) {
  if (!proto::command_of(command)) return {0, Refusal::not_a_command};
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  if (is_movement(command) && !(mode_confirmed_ && speed_confirmed_)) {
    return {0, Refusal::mode_speed_unconfirmed};
  }
  if (std::holds_alternative<proto::SetMode>(command)) mode_confirmed_ = true;
  if (std::holds_alternative<proto::SetSpeed>(command)) speed_confirmed_ = true;
  update_movement();
  const RequestId id = enqueue(now, command);
  pump(now);
  return {id, Refusal::none};
}

SubmitResult LogiClientCore::press(Time now, proto::Direction direction) {
  auto result = submit(now, proto::Move{direction});
  if (result && direction != proto::Direction::stop) {
    held_ = direction;
    if (config_.keepalive) keepalive_at_ = now + config_.keepalive_period;
  }
  return result;
}

SubmitResult LogiClientCore::release(Time now) {
  if (!held_) return {0, Refusal::not_held};
  held_.reset();
  keepalive_at_.reset();
  if (!stop_on_release()) return {next_id_++, Refusal::none};
  return submit(now, proto::Move{proto::Direction::stop});
}

SubmitResult LogiClientCore::emergency_stop(Time now) {
  held_.reset();
  keepalive_at_.reset();
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  // Queued motion would undo the stop once its turn came.
  std::deque<Pending> kept;
  for (auto& p : queue_) {
    if (is_movement(p.command)) {
      emit(CommandEvent{p.id, p.command, CommandState::cancelled, p.attempt, false});
    } else {
      kept.push_back(std::move(p));
    }
  }
  queue_ = std::move(kept);
  // A newer emergency stop takes over the resending of an older one's ST:STOP.
  for (auto it = flight_.begin(); it != flight_.end();) {
    if (!it->until_answered) {
      ++it;
      continue;
    }
    emit(CommandEvent{it->id, it->command, CommandState::cancelled, it->attempt, false});
    it = flight_.erase(it);
  }
  note(now, "emergency stop");
  // Written at once, beside whatever is in flight: a stop must not wait up
  // to a feedback timeout (and its retries) behind an unanswered command.
  RequestId id = 0;  // the MV:STOP's
  for (auto& command : emergency_stop_commands()) {
    Pending p{next_id_++, std::move(command)};
    if (std::holds_alternative<proto::Move>(p.command)) {
      p.switch_mode_on_reject = false;
      if (id == 0) id = p.id;
    }
    p.until_answered = resend_until_answered(p.command);
    send(now, std::move(p));
  }
  return {id, Refusal::none};
}

std::vector<proto::Message> LogiClientCore::emergency_stop_commands() const {
  std::vector<proto::Message> commands{proto::Move{proto::Direction::stop}};
  if (mode_ != proto::Mode::manual) commands.emplace_back(proto::SetRun{false});
  return commands;
}

bool LogiClientCore::resend_until_answered(const proto::Message& m) const {
  const auto* st = std::get_if<proto::SetRun>(&m);
  return st != nullptr && !st->run;
}

bool LogiClientCore::stop_after_timeout(const proto::Message& m) const {
  const auto* mv = std::get_if<proto::Move>(&m);
  return mv != nullptr && mv->direction != proto::Direction::stop;
}

SubmitResult LogiClientCore::confirm_resend(Time now, RequestId request) {
  auto it = std::find_if(awaiting_confirm_.begin(), awaiting_confirm_.end(),
                         [&](const Pending& p) { return p.id == request; });
  if (it == awaiting_confirm_.end()) return {0, Refusal::unknown_request};
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  Pending p = std::move(*it);
  awaiting_confirm_.erase(it);
  note(now, "operator confirmed resend of request " + std::to_string(request));
  queue_.push_back(std::move(p));
  pump(now);
  return {request, Refusal::none};
}

// ---- dispatcher ----

RequestId LogiClientCore::enqueue(Time /*now*/, proto::Message command, bool front,
                                  bool switch_mode_on_reject) {
  Pending p{next_id_++, std::move(command)};
  p.switch_mode_on_reject = switch_mode_on_reject;
  const RequestId id = p.id;
  if (front) {
    queue_.push_front(std::move(p));
  } else {
    queue_.push_back(std::move(p));
  }
  return id;
}

void LogiClientCore::pump(Time now) {
  while (state() == ConnectionState::connected && flight_.empty() && !queue_.empty()) {
    Pending p = std::move(queue_.front());
    queue_.pop_front();
    send(now, std::move(p));
  }
}

void LogiClientCore::send(Time now, Pending p) {
  ++p.attempt;
  p.deadline = now + config_.feedback_timeout;
  const std::string text = proto::encode_text(p.command);
  actions_.emplace_back(SendBytes{text});
  std::string description = proto::describe(p.command) + " [request " + std::to_string(p.id);
  if (p.attempt > 1) description += ", attempt " + std::to_string(p.attempt);
  description += "]";
  log_->add(LogEntry{now, LogKind::tx, text, std::move(description)});
  emit(CommandEvent{p.id, p.command, CommandState::sent, p.attempt, false});
  flight_.push_back(std::move(p));
}

void LogiClientCore::on_feedback(Time now, const proto::Feedback& fb) {
  // Feedback comes in command order, so the oldest command of that code in
  // flight is the one answered.
  auto it = std::find_if(flight_.begin(), flight_.end(), [&](const Pending& p) {
    return proto::command_of(p.command) == fb.command;
  });
  if (it == flight_.end()) {
    emit(FeedbackEvent{0, fb});
    return;
  }
  Pending p = std::move(*it);
  flight_.erase(it);
  emit(FeedbackEvent{p.id, fb});
  if (fb.accepted) {
    if (const auto* md = std::get_if<proto::SetMode>(&p.command)) mode_ = md->mode;
    emit(CommandEvent{p.id, p.command, CommandState::accepted, p.attempt, false});
  } else if (std::holds_alternative<proto::Move>(p.command) && p.switch_mode_on_reject &&
             !p.mode_switch_done) {
    emit(NoticeEvent{"Not in manual mode, switching to MAN"});
    note(now, "Not in manual mode, switching to MAN");
    p.mode_switch_done = true;
    queue_.push_front(std::move(p));
    enqueue(now, proto::SetMode{proto::Mode::manual}, true);
  } else {
    emit(CommandEvent{p.id, p.command, CommandState::rejected, p.attempt, false});
  }
  pump(now);
}

void LogiClientCore::on_timeout(Time now, Pending p) {
  if (p.until_answered) {
    // ST:STOP is idempotent: repeating it until the car answers is safe.
    note(now, "no feedback for emergency stop request " + std::to_string(p.id) + ", resending");
    send(now, std::move(p));
    return;
  }
  if (retryable(p.command) && p.attempt <= config_.max_retries) {
    note(now, "no feedback for request " + std::to_string(p.id) + ", resending");
    send(now, std::move(p));
    return;
  }
  const bool confirm = resend_on_confirm(p.command);
  note(now, "no feedback for request " + std::to_string(p.id) + ": uncertain" +
                (confirm ? ", resent only when the operator confirms" : ""));
  emit(CommandEvent{p.id, p.command, CommandState::uncertain, p.attempt, confirm});
  if (stop_after_timeout(p.command)) {
    // The car may have taken the move and be driving: stop it, ahead of
    // anything queued. A refusal of this stop asks for no switch to MAN.
    note(now, "fail-safe after the uncertain move: MV:STOP");
    enqueue(now, proto::Move{proto::Direction::stop}, /*front=*/true,
            /*switch_mode_on_reject=*/false);
  }
  if (confirm) {
    p.attempt = 0;
    awaiting_confirm_.push_back(std::move(p));
  }
}

// ---- input ----

void LogiClientCore::on_bytes(Time now, protocol::ByteView bytes) {
  if (state() != ConnectionState::connected) return;
  decode(bytes, items_);
  auto items = std::exchange(items_, {});
  for (const auto& item : items) {
    if (const auto* frame = std::get_if<protocol::Frame<proto::Message>>(&item)) {
      on_frame(now, *frame);
    } else {
      const auto& error = std::get<protocol::DecodeError>(item);
      parse_error(now, std::string(error.raw.begin(), error.raw.end()), error);
    }
    if (state() != ConnectionState::connected) break;
  }
  pump(now);
}

void LogiClientCore::on_frame(Time now, const protocol::Frame<proto::Message>& frame) {
  connection_.reconnect().succeeded();
  log_->add(LogEntry{now, LogKind::rx, std::string(frame.raw.begin(), frame.raw.end()),
                     proto::describe(frame.message)});
  if (refreshes_status(frame.message)) {
    last_stat_ = now;
    if (stale_) {
      stale_ = false;
      note(now, "status fresh again");
      emit(StaleEvent{false});
    }
  }
  if (const auto* status = std::get_if<proto::Status>(&frame.message)) {
    status_ = *status;
    mode_ = status->mode;
    emit(StatusEvent{*status});
  } else if (const auto* fb = std::get_if<proto::Feedback>(&frame.message)) {
    on_feedback(now, *fb);
  } else {
    note(now, "the car sent a command frame; ignored");
  }
}

// ---- time ----

void LogiClientCore::on_timer(Time now) {
  if (reconnect_if_due(now)) update_movement();
  for (;;) {
    auto it = std::min_element(
        flight_.begin(), flight_.end(),
        [](const Pending& a, const Pending& b) { return a.deadline < b.deadline; });
    if (it == flight_.end() || it->deadline > now) break;
    Pending p = std::move(*it);
    flight_.erase(it);
    on_timeout(now, std::move(p));
  }
  if (state() == ConnectionState::connected && !stale_ && last_stat_ &&
      now >= stale_at(*last_stat_)) {
    stale_ = true;
    note(now, "stale: no STAT for " + link::format_ms(now - *last_stat_));
    emit(StaleEvent{true});
  }
  if (held_ && keepalive_at_ && now >= *keepalive_at_) {
    // Only when the line is idle: a keepalive never queues behind a command.
    if (state() == ConnectionState::connected && queue_.empty() && flight_.empty()) {
      enqueue(now, proto::Move{*held_});
    }
    while (*keepalive_at_ <= now)
      *keepalive_at_ += config_.keepalive_period;
  }
  pump(now);
}

std::optional<Time> LogiClientCore::next_wakeup() const {
  link::Earliest next;
  next.consider(connection_.reconnect().due());
  for (const auto& p : flight_)
    next.consider(p.deadline);
  if (state() == ConnectionState::connected && !stale_ && last_stat_) {
    next.consider(stale_at(*last_stat_));
  }
  if (held_) next.consider(keepalive_at_);
  return next.time();
}

void LogiClientCore::decode(protocol::ByteView bytes, std::vector<proto::Item>& items) {
  decoder_.feed(bytes, items);
}

}  // namespace hil::client::logi
