#include "client/wr8/core.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <variant>

#include "base/enum_names.hpp"
#include "link/capture/wire_log.hpp"

namespace hil::client::wr8 {

constexpr auto kWr8RequestStateNames = base::enum_names<RequestState>(
    {RequestState::sent, "sent"}, {RequestState::started, "started"},
    {RequestState::completed, "completed"}, {RequestState::error, "error"},
    {RequestState::timed_out, "timed_out"}, {RequestState::cancelled, "cancelled"});

constexpr auto kWr8DataStreamNames = base::enum_names<DataStream>(
    {DataStream::data, "DATA"}, {DataStream::high_freq, "HIGH-FREQ DATA"},
    {DataStream::low_freq, "LOW-FREQ DATA"});

constexpr auto kWr8RefusalNames =
    base::enum_names<Refusal>({Refusal::none, "none"}, {Refusal::not_connected, "not_connected"},
                              {Refusal::bad_request, "bad_request"}, {Refusal::busy, "busy"});

std::string_view to_string(RequestState s) {
  return kWr8RequestStateNames.name(s);
}

std::string_view to_string(DataStream s) {
  return kWr8DataStreamNames.name(s);
}

std::string_view to_string(Refusal r) {
  return kWr8RefusalNames.name(r);
}

namespace {

proto::DecoderOptions decoder_options(const proto::Profile& profile) {
  proto::DecoderOptions o;
  o.profile = profile;
  o.sender = proto::Sender::vehicle;
  return o;
}

// The live state's field for each DATA code it shows.
constexpr std::pair<std::uint8_t, std::optional<double> LiveState::*> kLiveFields[] = {
    {proto::data_code::odometry, &LiveState::odometry_cm},
    {proto::data_code::speed, &LiveState::speed_mps},
    {proto::data_code::wheel_angle, &LiveState::wheel_angle_deg},
    {proto::data_code::battery, &LiveState::battery_percent},
};

bool is_final(RequestState s) {
  return s != RequestState::sent && s != RequestState::started;
}

// What the log shows of a packet the client sends. Logs end up in bug
// reports, so an AUTH never shows its string: its type byte stays, each
// byte of the string reads "**", and the text is masked as the mock's wire
// log masks it.
LogEntry tx_entry(Time now, const proto::Message& message, protocol::ByteView bytes,
                  const proto::Profile& profile) {
  std::string description = proto::describe(message, profile);
  if (!std::holds_alternative<proto::Auth>(message) || bytes.empty())
    return {now, LogKind::tx, protocol::to_hex(bytes), std::move(description)};
  std::string raw = protocol::to_hex(bytes.first(1));
  for (std::size_t i = 1; i < bytes.size(); ++i)
    raw += " **";
  return {now, LogKind::tx, std::move(raw),
          link::masked_frame_text("AUTH", std::move(description))};
}

}  // namespace

Wr8ClientCore::Wr8ClientCore(ClientConfig config, std::shared_ptr<CommLog> log)
    : LoginCore(std::move(log), Backoff::ladder(config.reconnect_delays)),
      config_(std::move(config)),
      decoder_(decoder_options(config_.profile)) {}

void Wr8ClientCore::connect(Time now) {
  open_wanted(now, connection_.reconnect().attempt());
}

void Wr8ClientCore::disconnect(Time now) {
  drop_login_deadline();
  close_unwanted();
  cancel_all();
  note(now, "disconnect");
  change_state(ConnectionState::disconnected);
}

void Wr8ClientCore::on_connected(Time now) {
  if (state() != ConnectionState::connecting) return;
  decoder_ = proto::Decoder(decoder_options(config_.profile));
  await_login(now, config_.auth_timeout);
  send(now, proto::Auth{config_.profile.auth_text});
  if (!login_awaits_reply()) logged_in(proto::AuthReply{});
}

void Wr8ClientCore::on_closed(Time now) {
  if (state() == ConnectionState::authenticating) {
    login_failed(now, "closed before AUTH-REPLY");
  } else if (state() == ConnectionState::connected) {
    lost(now, "connection closed by the vehicle");
  }
}

void Wr8ClientCore::lost(Time now, std::string_view why) {
  note(now, std::string(why));
  cancel_all();
  retry_later(now);
}

void Wr8ClientCore::cancel_all() {
  for (std::size_t coi = 0; coi < pending_.size(); ++coi) {
    if (pending_[coi]) finish(static_cast<std::uint8_t>(coi), RequestState::cancelled);
  }
}

void Wr8ClientCore::on_bytes(Time now, protocol::ByteView bytes) {
  // A login failure or close inside handle() ends this connection's bytes.
  receive(
      now, bytes, decoder_, items_,
      [this](const proto::Message& m) { return proto::describe(m, config_.profile); },
      [this](Time t, const proto::Message& m) { handle(t, m); });
}

void Wr8ClientCore::handle(Time now, const proto::Message& message) {
  if (const auto* reply = std::get_if<proto::AuthReply>(&message)) {
    if (state() == ConnectionState::authenticating) logged_in(*reply);
    return;
  }
  if (state() != ConnectionState::connected) {
    note(now, "ignored before login");
    return;
  }
  if (const auto* data = std::get_if<proto::Data>(&message)) {
    LiveState live;
    live.state = data->state;
    live.timestamp_ms = data->timestamp_ms;
    live.received = now;
    for (const auto& v : data->values) {
      for (const auto& [code, field] : kLiveFields) {
        if (v.code == code) live.*field = value_of(v);
      }
    }
    live_ = live;
    last_data_ = now;
    emit(TelemetryEvent{live});
    if (stale_) {
      stale_ = false;
      emit(StaleEvent{false});
    }
  } else if (const auto* r = std::get_if<proto::Response>(&message)) {
    on_response(now, *r);
  } else if (const auto* s = std::get_if<proto::Settings>(&message)) {
    auto& p = pending_[s->coi];
    if (!p || p->kind != RequestKind::task || p->task != proto::TaskCode::get_settings) {
      ignored(now, message);
      return;
    }
    settings_ = s->params;
    emit(SettingsEvent{s->coi, s->params});
    if (!p->started) {
      // SETTINGS is the first answer; completion must follow as for a started task.
      p->started = true;
      p->deadline = now + config_.completion_timeout[static_cast<std::size_t>(p->task)];
    }
  }
}

void Wr8ClientCore::logged_in(const proto::AuthReply& reply) {
  login_done();
  last_data_.reset();
  change_state(ConnectionState::connected);
  emit(LoginEvent{reply});
}

void Wr8ClientCore::on_response(Time now, const proto::Response& r) {
  const std::uint8_t coi = answered_coi(r);
  auto& p = pending_[coi];
  if (!p) {
    ignored(now, r);
    return;
  }
  switch (r.code) {
    case proto::ResponseCode::started:
      if (p->started) {
        ignored(now, r);
        return;
      }
      p->started = true;
      p->deadline = now + (p->kind == RequestKind::task
                               ? config_.completion_timeout[static_cast<std::size_t>(p->task)]
                               : config_.answer_timeout);
      emit(RequestEvent{coi, p->kind, p->task, RequestState::started});
      break;
    case proto::ResponseCode::completed:
      finish(coi, RequestState::completed);
      break;
    case proto::ResponseCode::error:
      finish(coi, RequestState::error);
      break;
  }
}

void Wr8ClientCore::finish(std::uint8_t coi, RequestState state) {
  auto& p = pending_[coi];
  if (!p || !is_final(state)) return;
  emit(RequestEvent{coi, p->kind, p->task, state});
  p.reset();
}

void Wr8ClientCore::ignored(Time now, const proto::Message& message) {
  note(now, "ignored (late or unknown COI): " + proto::describe(message, config_.profile));
  emit(IgnoredEvent{message});
}

double Wr8ClientCore::value_of(const proto::DataValue& v) const {
  const auto* row = config_.profile.data_parameter(v.code);
  if (!row) return static_cast<double>(v.value.as_i32());
  switch (row->type) {
    case proto::ValueType::float32:
      return static_cast<double>(v.value.as_f32());
    case proto::ValueType::unsigned_int:
      return static_cast<double>(v.value.bits);
    case proto::ValueType::signed_int: {
      // Narrow values sit in the low bits: shift up and back to extend the sign.
      const int shift = 32 - 8 * row->size_bytes;
      return static_cast<double>(static_cast<std::int32_t>(v.value.bits << shift) >> shift);
    }
  }
  return 0;
}

void Wr8ClientCore::send(Time now, const proto::Message& message) {
  protocol::Bytes bytes = proto::encode(message, config_.profile);
  log_->add(tx_entry(now, message, bytes, config_.profile));
  actions_.push_back(SendBytes{std::move(bytes)});
}

SubmitResult Wr8ClientCore::send_request(Time now, RequestKind kind, proto::TaskCode task,
                                         const proto::Message& message) {
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  // The next free COI after the last one used, wrapping FF -> 00.
  std::optional<std::uint8_t> coi;
  for (int i = 0; i < 256; ++i) {
    const auto c = static_cast<std::uint8_t>(next_coi_ + i);
    if (!pending_[c]) {
      coi = c;
      break;
    }
  }
  if (!coi) return {0, Refusal::busy};
  proto::Message m = message;
  if (auto* t = std::get_if<proto::Task>(&m)) t->coi = *coi;
  if (auto* s = std::get_if<proto::Settings>(&m)) s->coi = *coi;
  protocol::Bytes bytes;
  try {
    bytes = proto::encode(m, config_.profile);
  } catch (const std::invalid_argument&) {
    return {0, Refusal::bad_request};
  }
  log_->add(tx_entry(now, m, bytes, config_.profile));
  actions_.push_back(SendBytes{std::move(bytes)});
  next_coi_ = static_cast<std::uint8_t>(*coi + 1);
  pending_[*coi] = Pending{kind, task, false, now + config_.answer_timeout, requests_sent_++};
  emit(RequestEvent{*coi, kind, task, RequestState::sent});
  return {*coi, Refusal::none};
}

SubmitResult Wr8ClientCore::task(Time now, proto::TaskCode code, std::vector<proto::Word> params) {
  return send_request(now, RequestKind::task, code, proto::Task{0, code, std::move(params)});
}

SubmitResult Wr8ClientCore::drive(Time now, std::int32_t distance_cm) {
  return task(now, proto::TaskCode::drive, {proto::Word::from_i32(distance_cm)});
}

SubmitResult Wr8ClientCore::turn(Time now, std::int32_t angle_deg) {
  return task(now, proto::TaskCode::turn, {proto::Word::from_i32(angle_deg)});
}

SubmitResult Wr8ClientCore::get_settings(Time now) {
  return task(now, proto::TaskCode::get_settings);
}

SubmitResult Wr8ClientCore::set_settings(Time now, std::vector<proto::Setting> settings) {
  return send_request(now, RequestKind::settings, proto::TaskCode::check,
                      proto::Settings{0, std::move(settings)});
}

std::size_t Wr8ClientCore::open_requests() const {
  return static_cast<std::size_t>(
      std::count_if(pending_.begin(), pending_.end(), [](const auto& p) { return p.has_value(); }));
}

std::optional<std::uint8_t> Wr8ClientCore::newest_open_coi() const {
  std::optional<std::uint8_t> newest;
  for (std::size_t coi = 0; coi < pending_.size(); ++coi) {
    if (pending_[coi] && (!newest || pending_[coi]->order > pending_[*newest]->order))
      newest = static_cast<std::uint8_t>(coi);
  }
  return newest;
}

void Wr8ClientCore::on_timer(Time now) {
  reconnect_if_due(now);
  check_login_deadline(now);
  if (state() != ConnectionState::connected) return;
  for (std::size_t coi = 0; coi < pending_.size(); ++coi) {
    if (pending_[coi] && now >= pending_[coi]->deadline) {
      note(now, "COI " + std::to_string(coi) + " timed out");
      finish(static_cast<std::uint8_t>(coi), RequestState::timed_out);
    }
  }
  if (!stale_ && last_data_ && now >= *last_data_ + config_.stale_after) {
    stale_ = true;
    note(now, "DATA stale");
    emit(StaleEvent{true});
  }
}

std::optional<Time> Wr8ClientCore::next_wakeup() const {
  link::Earliest next = connection_wakeup();
  if (state() == ConnectionState::connected) {
    for (const auto& p : pending_) {
      if (p) next.consider(p->deadline);
    }
    if (!stale_ && last_data_) next.consider(*last_data_ + config_.stale_after);
  }
  return next.time();
}

}  // namespace hil::client::wr8
