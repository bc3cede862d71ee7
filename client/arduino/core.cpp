#include "client/arduino/core.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "base/enum_names.hpp"
#include "protocol/common/text.hpp"

namespace hil::client::arduino {

namespace proto = protocol::arduino;

namespace {

Result outcome(ResultCode code, std::string detail) {
  Result r;
  r.code = code;
  r.detail = std::move(detail);
  return r;
}

}  // namespace

constexpr auto kArduinoLinkNames = base::enum_names<ConnectionState>(
    {ConnectionState::disconnected, "CLOSED"}, {ConnectionState::connecting, "OPENING"},
    {ConnectionState::connected, "OPEN"}, {ConnectionState::degraded, "DEGRADED"},
    {ConnectionState::reconnecting, "RECONNECTING"}, {ConnectionState::down, "DOWN"});

constexpr auto kResultCodeNames = base::enum_names<ResultCode>(
    {ResultCode::ok, "ok"}, {ResultCode::nack, "nack"}, {ResultCode::timeout, "timeout"},
    {ResultCode::link_down, "link_down"}, {ResultCode::invalid_request, "invalid_request"});

std::string_view link_name(ConnectionState s) {
  return kArduinoLinkNames.name(s);
}

std::string_view to_string(ResultCode c) {
  return kResultCodeNames.name(c);
}

ArduinoClientCore::ArduinoClientCore(ClientConfig config)
    : config_(config), reconnect_(Backoff::doubling(config_.reconnect_base_delay)) {
  if (config_.base_timeout <= Duration::zero() || config_.max_retries < 0 ||
      config_.max_bad_cs_resends < 0 || config_.max_reconnect_attempts < 1 ||
      config_.reconnect_ping_retries < 0 || config_.reconnect_base_delay < Duration::zero() ||
      config_.health_check_interval < Duration::zero()) {
    throw std::invalid_argument("ArduinoClientCore: a ClientConfig value is out of range");
  }
}

Result ArduinoClientCore::lost_result(const Inflight& lost, ResultCode code,
                                      const std::string& detail) {
  Result r = outcome(code, detail);
  r.attempts = lost.attempt + 1;
  r.bad_cs_resends = lost.bad_cs_resends;
  r.seq = lost.seq;
  return r;
}

Duration ArduinoClientCore::timeout_of(int attempt) const {
  return config_.base_timeout * (std::int64_t{1} << attempt);
}

bool ArduinoClientCore::answers(std::uint8_t request_seq, const proto::Message& reply) const {
  return reply.seq == request_seq;
}

bool ArduinoClientCore::resend_on(const proto::Nack& nack) const {
  const auto* code = std::get_if<proto::NackCode>(&nack.error);
  return code != nullptr && *code == proto::NackCode::bad_cs;
}

Bytes ArduinoClientCore::frame_of(const Pending& pending, std::uint8_t seq) const {
  if (const auto* raw = std::get_if<proto::Envelope>(&pending.what)) {
    proto::Envelope e = *raw;
    e.seq = seq;
    return protocol::to_bytes(proto::frame_text(e));
  }
  return protocol::to_bytes(
      proto::encode_text({seq, std::get<proto::Body>(pending.what)}, config_.dialect));
}

void ArduinoClientCore::open(Time now) {
  if (state_ != ConnectionState::disconnected && state_ != ConnectionState::down) return;
  reconnect_.reset();
  set_state(now, ConnectionState::connecting, "open requested");
  actions_.push_back(OpenPort{});
}

void ArduinoClientCore::close(Time now) {
  if (connected_) actions_.push_back(ClosePort{});
  connected_ = false;
  reconnect_.cancel();
  fail_all(now, ResultCode::link_down, "the port was closed");
  if (state_ != ConnectionState::disconnected)
    set_state(now, ConnectionState::disconnected, "close requested");
}

RequestId ArduinoClientCore::request(Time now, proto::Body body) {
  const RequestId id = next_id_++;
  if (!proto::is_request(body)) {
    complete(id, outcome(ResultCode::invalid_request, "ACK and NACK are not requests"));
    return id;
  }
  try {
    (void)proto::encode_text({0, body}, config_.dialect);
  } catch (const std::invalid_argument& e) {
    complete(id, outcome(ResultCode::invalid_request, e.what()));
    return id;
  }
  queue_user(now, id, std::move(body));
  return id;
}

RequestId ArduinoClientCore::raw(Time now, std::string_view token) {
  proto::Envelope envelope;
  const auto colon = token.find(':');
  envelope.cmd = protocol::ascii_upper(token.substr(0, colon));
  if (colon != std::string_view::npos) envelope.payload = std::string(token.substr(colon + 1));
  auto typed = proto::to_message(envelope);
  if (auto* message = std::get_if<proto::Message>(&typed)) return request(now, message->body);
  // Not a request hil types (a value out of range, an unknown command): it
  // goes out as given, and the board's answer is the result.
  const RequestId id = next_id_++;
  const auto framable = [](const std::string& field) {
    return std::all_of(field.begin(), field.end(), proto::is_field_char);
  };
  if (envelope.cmd.empty() || !framable(envelope.cmd) || !framable(envelope.payload)) {
    complete(id, outcome(ResultCode::invalid_request,
                         "'" + std::string(token) +
                             "' cannot be framed: a command, then ':' and a payload, "
                             "of printable characters but ^ $ * |"));
    return id;
  }
  if (envelope.payload.empty())
    envelope.payload = std::string(proto::empty_payload(config_.dialect));
  queue_user(now, id, std::move(envelope));
  return id;
}

void ArduinoClientCore::queue_user(Time now, RequestId id, Payload what) {
  if (state_ == ConnectionState::disconnected || state_ == ConnectionState::down) {
    complete(id, outcome(ResultCode::link_down,
                         std::string("the link is ") + std::string(link_name(state_))));
    return;
  }
  queue_.push_back({id, Purpose::user, std::move(what)});
  pump(now);
}

void ArduinoClientCore::on_connected(Time now) {
  connected_ = true;
  decoder_ = proto::Decoder{};
  if (state_ == ConnectionState::connecting) {
    last_exchange_ = now;
    set_state(now, ConnectionState::connected, "port open");
    pump(now);
  } else if (state_ == ConnectionState::reconnecting) {
    // The reopened port must answer a PING before requests flow again.
    inflight_ = Inflight{};
    inflight_->pending = {0, Purpose::reconnect_check, proto::Ping{}};
    inflight_->max_retries = config_.reconnect_ping_retries;
    inflight_->seq = next_seq_++;
    inflight_->frame = frame_of(inflight_->pending, inflight_->seq);
    send_current(now);
  }
}

void ArduinoClientCore::on_connect_failed(Time now, std::string_view why) {
  connected_ = false;
  if (state_ == ConnectionState::connecting) {
    set_state(now, ConnectionState::down, "the port did not open: " + std::string(why));
    fail_all(now, ResultCode::link_down, "the port did not open");
  } else if (state_ == ConnectionState::reconnecting) {
    reconnect_failed(now, "the port did not reopen: " + std::string(why));
  }
}

void ArduinoClientCore::on_closed(Time now) {
  if (!connected_) return;
  connected_ = false;
  if (inflight_ && inflight_->pending.purpose == Purpose::reconnect_check) {
    inflight_.reset();
    reconnect_failed(now, "the port closed during the reconnect check");
    return;
  }
  if (inflight_) {
    const Inflight lost = *std::exchange(inflight_, std::nullopt);
    if (lost.pending.purpose == Purpose::user) {
      complete(lost.pending.id,
               lost_result(lost, ResultCode::link_down, "the port closed before the answer"));
    }
  }
  if (state_ == ConnectionState::connected) link_failed(now, "the port closed");
}

void ArduinoClientCore::on_bytes(Time now, ByteView bytes) {
  if (!connected_) return;
  items_.clear();
  decoder_.feed(bytes, items_);
  for (auto& item : items_) {
    if (auto* frame = std::get_if<protocol::Frame<proto::Message>>(&item)) {
      events_.push_back(FrameReceived{frame->raw, frame->message.seq, true});
      handle_message(now, frame->message);
    } else {
      auto& error = std::get<protocol::DecodeError>(item);
      // Line noise between frames is not an answer; anything frame-shaped
      // that fails to decode is a parse error the timeout will retry.
      if (error.kind != protocol::ErrorKind::garbage) ++parse_errors_;
      events_.push_back(FrameReceived{error.raw, proto::sequence_of(error.raw), false});
    }
  }
}

void ArduinoClientCore::handle_message(Time now, const proto::Message& m) {
  if (!inflight_ || proto::is_request(m.body) || !answers(inflight_->seq, m)) {
    ++stale_frames_;
    return;
  }
  if (const auto* ack = std::get_if<proto::Ack>(&m.body)) {
    Result r = outcome(ResultCode::ok, "");
    r.info = ack->info;
    if (const auto* body = std::get_if<proto::Body>(&inflight_->pending.what)) {
      r.reply = proto::parse_reply(config_.dialect, *body, ack->info);
    }
    finish(now, std::move(r));
    return;
  }
  const auto& nack = std::get<proto::Nack>(m.body);
  if (resend_on(nack) && inflight_->bad_cs_resends < config_.max_bad_cs_resends) {
    ++inflight_->bad_cs_resends;
    send_current(now);
    return;
  }
  Result r = outcome(ResultCode::nack, "the robot refused the request");
  r.nack = nack;
  finish(now, std::move(r));
}

void ArduinoClientCore::on_timer(Time now) {
  if (inflight_ && now >= inflight_->deadline) {
    if (inflight_->attempt < inflight_->max_retries) {
      ++inflight_->attempt;
      send_current(now);
    } else {
      finish(now, outcome(ResultCode::timeout, "no answer after every attempt"));
    }
  }
  if (reconnect_.take_due(now)) {
    if (state_ != ConnectionState::reconnecting) {
      set_state(now, ConnectionState::reconnecting, "reopening the port");
    }
    actions_.push_back(OpenPort{});
  }
  if (state_ == ConnectionState::connected && connected_ && !inflight_ && queue_.empty() &&
      config_.health_check_interval > Duration::zero() &&
      now >= last_exchange_ + config_.health_check_interval) {
    queue_.push_back({0, Purpose::health_check, proto::Ping{}});
  }
  pump(now);
}

std::optional<Time> ArduinoClientCore::next_wakeup() const {
  link::Earliest due;
  if (inflight_) due.consider(inflight_->deadline);
  due.consider(reconnect_.due());
  if (state_ == ConnectionState::connected && connected_ && !inflight_ && queue_.empty() &&
      config_.health_check_interval > Duration::zero()) {
    due.consider(last_exchange_ + config_.health_check_interval);
  }
  return due.time();
}

std::vector<Action> ArduinoClientCore::take_actions() {
  return std::exchange(actions_, {});
}
std::vector<Event> ArduinoClientCore::take_events() {
  return std::exchange(events_, {});
}

void ArduinoClientCore::pump(Time now) {
  if (inflight_ || state_ != ConnectionState::connected || !connected_ || queue_.empty()) return;
  Pending next = std::move(queue_.front());
  queue_.pop_front();
  inflight_ = Inflight{};
  inflight_->pending = std::move(next);
  inflight_->max_retries = config_.max_retries;
  inflight_->seq = next_seq_++;  // wraps FF -> 00 as an 8-bit value
  inflight_->frame = frame_of(inflight_->pending, inflight_->seq);
  send_current(now);
}

void ArduinoClientCore::send_current(Time now) {
  inflight_->deadline = now + timeout_of(inflight_->attempt);
  actions_.push_back(SendFrame{inflight_->frame, inflight_->seq});
}

void ArduinoClientCore::finish(Time now, Result result) {
  const Inflight done = *std::exchange(inflight_, std::nullopt);
  result.attempts = done.attempt + 1;
  result.bad_cs_resends = done.bad_cs_resends;
  result.seq = done.seq;
  const bool answered = result.code != ResultCode::timeout;
  switch (done.pending.purpose) {
    case Purpose::user:
      last_exchange_ = now;
      complete(done.pending.id, result);
      if (!answered) link_failed(now, "no answer to a request");
      break;
    case Purpose::health_check:
      last_exchange_ = now;
      if (!answered) link_failed(now, "no answer to the health check");
      break;
    case Purpose::reconnect_check:
      if (result.code == ResultCode::ok) {
        reconnect_.reset();
        last_exchange_ = now;
        set_state(now, ConnectionState::connected, "the reopened port answered PING");
      } else {
        reconnect_failed(now, "no ACK to PING on the reopened port");
      }
      break;
  }
  pump(now);
}

void ArduinoClientCore::set_state(Time now, ConnectionState to, std::string reason) {
  if (to == state_) return;
  events_.push_back(LinkChanged{state_, to, now, std::move(reason)});
  state_ = to;
}

void ArduinoClientCore::link_failed(Time now, std::string reason) {
  if (state_ != ConnectionState::connected) return;
  set_state(now, ConnectionState::degraded, std::move(reason));
  if (connected_) actions_.push_back(ClosePort{});
  connected_ = false;
  reconnect_.reset();
  reconnect_.schedule(now);  // reconnect_base_delay
}

void ArduinoClientCore::reconnect_failed(Time now, std::string reason) {
  if (connected_) actions_.push_back(ClosePort{});
  connected_ = false;
  // The attempts scheduled so far all failed.
  if (reconnect_.attempt() >= config_.max_reconnect_attempts) {
    set_state(now, ConnectionState::down, std::move(reason));
    fail_all(now, ResultCode::link_down, "the link is DOWN");
    return;
  }
  reconnect_.schedule(now);  // twice the last wait
}

void ArduinoClientCore::fail_all(Time /*now*/, ResultCode code, const std::string& detail) {
  if (inflight_) {
    const Inflight lost = *std::exchange(inflight_, std::nullopt);
    if (lost.pending.purpose == Purpose::user) {
      complete(lost.pending.id, lost_result(lost, code, detail));
    }
  }
  for (auto& p : std::exchange(queue_, {})) {
    if (p.purpose == Purpose::user) complete(p.id, outcome(code, detail));
  }
}

void ArduinoClientCore::complete(RequestId id, Result result) {
  events_.push_back(RequestDone{id, std::move(result)});
}

}  // namespace hil::client::arduino
