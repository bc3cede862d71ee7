#include "client/wr8/svgui_core.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "base/enum_names.hpp"
#include "client/common/operator_text.hpp"

namespace hil::client::wr8 {

namespace {

using svgui::Version;

}  // namespace

// The operator's words for the tasks a smart_vehicle_gui vehicle takes.
constexpr auto kSvguiTaskWords = base::enum_names<proto::TaskCode>(
    {proto::TaskCode::drive, "forward"}, {proto::TaskCode::turn, "wheels"},
    {proto::TaskCode::blink, "signals"}, {proto::TaskCode::get_settings, "set-request"});

std::string svgui_request_name(const RequestEvent& r) {
  if (r.kind == RequestKind::settings) return r.coi == 0 ? "set" : "settings";
  if (const auto word = kSvguiTaskWords.find(r.task)) return std::string(*word);
  return "task " + std::to_string(static_cast<int>(r.task));
}

protocol::Bytes svgui_auth_text(svgui::Version version) {
  protocol::Bytes text = {'k', 'o', 'n', 'n', 'i', 'c', 'h', 'i', 'w', 'a'};
  if (version == Version::head) text.push_back(0);
  return text;
}

std::string describe(const SvguiEvent& event) {
  return std::visit(
      Overloaded{
          [](const ConnectionEvent& e) {
            return "connection " + std::string(to_string(e.state)) +
                   (e.attempt > 0 ? " (attempt " + std::to_string(e.attempt) + ")" : "");
          },
          [](const LoginEvent& e) {
            return "logged in: device " + std::to_string(e.reply.device_code) + ", id " +
                   std::to_string(e.reply.device_id) + ", " +
                   std::string(proto::to_string(e.reply.state));
          },
          [](const LoginFailedEvent& e) { return "login failed: " + e.reason; },
          [](const StaleEvent& e) {
            return std::string(to_string(e.stream)) + (e.stale ? " stale" : " flowing again");
          },
          [](const RequestEvent& e) {
            std::string s = svgui_request_name(e);
            if (e.coi != 0) s += " (COI " + std::to_string(e.coi) + ")";
            s += " " + std::string(to_string(e.state));
            if (!e.note.empty()) s += " (" + e.note + ")";
            return s;
          },
          [](const ParseErrorEvent& e) {
            return "bad bytes received (" + std::string(protocol::to_string(e.error.kind)) +
                   "): " + e.error.detail;
          },
          [](const DataEvent& e) { return svgui::describe(e.data); },
          [](const HighFreqEvent& e) { return svgui::describe(e.data); },
          [](const LowFreqEvent& e) { return svgui::describe(e.data); },
          [](const MapEvent& e) { return svgui::describe(e.map); },
          [](const SetReadEvent& e) { return "settings read back: " + svgui::describe(e.set); },
          [](const PacketIgnoredEvent& e) {
            return "ignored " + svgui::describe(e.message) + " (" + e.why + ")";
          },
      },
      event);
}

SvguiClientCore::SvguiClientCore(SvguiConfig config, std::shared_ptr<CommLog> log)
    : LoginCore(std::move(log), Backoff::ladder(config.reconnect_delays)),
      config_(std::move(config)),
      decoder_(config_.version) {
  if (config_.control_period <= Duration{0})
    throw std::invalid_argument("wr8 client: control_period must be positive");
}

Duration SvguiClientCore::stale_after(DataStream s) const {
  switch (s) {
    case DataStream::data:
      return config_.data_stale_after;
    case DataStream::high_freq:
      return config_.high_freq_stale_after;
    case DataStream::low_freq:
      return config_.low_freq_stale_after;
  }
  return config_.data_stale_after;
}

// ---- connection ----

void SvguiClientCore::connect(Time now) {
  open_wanted(now, connection_.reconnect().attempt());
}

void SvguiClientCore::disconnect(Time now) {
  drop_login_deadline();
  if (state() == ConnectionState::connected) {
    if (control_) release_control(now);
    // What waits goes out now, before the close, and the release last.
    for (const auto& m : outbox_)
      write(now, m);
  }
  close_unwanted();
  end_connection(now);
  note(now, "disconnect");
  change_state(ConnectionState::disconnected);
}

void SvguiClientCore::on_connected(Time now) {
  if (state() != ConnectionState::connecting) return;
  decoder_ = svgui::Decoder(config_.version);
  outbox_.clear();
  last_sent_.reset();
  logged_in_ = false;
  if (!config_.wait_for_login) {
    send(now, svgui::Auth{svgui_auth_text(config_.version)});
    note(now, "AUTH sent; the connection is used without waiting for AUTH-REPLY");
    become_connected(now);
    return;
  }
  await_login(now, config_.login_timeout);
  send(now, svgui::Auth{svgui_auth_text(config_.version)});
}

void SvguiClientCore::become_connected(Time /*now*/) {
  login_done();
  for (auto& s : streams_)
    s.last.reset();
  change_state(ConnectionState::connected);
}

void SvguiClientCore::on_closed(Time now) {
  if (state() == ConnectionState::authenticating) {
    login_failed(now, "closed before AUTH-REPLY");
  } else if (state() == ConnectionState::connected) {
    note(now, "connection closed by the vehicle");
    end_connection(now);
    retry_later(now);
  }
}

void SvguiClientCore::end_connection(Time) {
  for (std::size_t coi = 0; coi < pending_.size(); ++coi)
    finish(pending_[coi], static_cast<std::uint8_t>(coi), RequestState::cancelled);
  finish(set_pending_, 0, RequestState::cancelled);
  finish(set_request_pending_, 0, RequestState::cancelled);
  control_.reset();
  next_control_.reset();
  outbox_.clear();
}

// ---- receiving ----

void SvguiClientCore::on_bytes(Time now, protocol::ByteView bytes) {
  receive(
      now, bytes, decoder_, items_, [](const svgui::Message& m) { return svgui::describe(m); },
      [this](Time t, const svgui::Message& m) { handle(t, m); });
}

void SvguiClientCore::handle(Time now, const svgui::Message& message) {
  if (const auto* reply = std::get_if<svgui::AuthReply>(&message)) {
    const bool awaited = state() == ConnectionState::authenticating;
    const bool late =
        state() == ConnectionState::connected && !config_.wait_for_login && !logged_in_;
    if (!awaited && !late) {
      ignored(now, message, "AUTH-REPLY after login");
      return;
    }
    if (*reply != svgui::kProgramAuthReply)
      note(now, "AUTH-REPLY differs from the real vehicles' fixed 1 2 WAIT");
    if (awaited) become_connected(now);
    logged_in_ = true;
    emit(LoginEvent{*reply});
    return;
  }
  if (state() != ConnectionState::connected) {
    ignored(now, message, "before login");
    return;
  }
  std::visit(Overloaded{
                 [&](const svgui::Data& d) {
                   data_ = Received<svgui::Data>{d, now};
                   emit(DataEvent{d});
                   fresh(now, DataStream::data);
                 },
                 [&](const svgui::HighFreqData& d) {
                   high_freq_ = Received<svgui::HighFreqData>{d, now};
                   emit(HighFreqEvent{d});
                   fresh(now, DataStream::high_freq);
                 },
                 [&](const svgui::LowFreqData& d) {
                   low_freq_ = Received<svgui::LowFreqData>{d, now};
                   emit(LowFreqEvent{d});
                   fresh(now, DataStream::low_freq);
                 },
                 [&](const svgui::Map& m) {
                   map_ = m;
                   emit(MapEvent{m});
                 },
                 [&](const svgui::Set& s) {
                   // The GUI shows a SET whenever one comes; it answers an
                   // open SET-REQUEST if there is one.
                   read_settings_ = s;
                   emit(SetReadEvent{s});
                   finish(set_request_pending_, 0, RequestState::completed);
                 },
                 [&](const svgui::Answer& a) { on_answer(now, a, message); },
                 [&](const auto&) { ignored(now, message, "a packet only the GUI sends"); },
             },
             message);
}

void SvguiClientCore::on_answer(Time now, const svgui::Answer& a, const svgui::Message& message) {
  if (config_.version == Version::head) {
    if (!set_pending_) {
      ignored(now, message, "ANSWER with no SET open");
      return;
    }
    if (a.code == 1) {
      finish(set_pending_, 0, RequestState::completed);
    } else if (a.code == 0) {
      finish(set_pending_, 0, RequestState::error, "the vehicle could not apply the settings");
    } else {
      ignored(now, message, "ANSWER code " + std::to_string(a.code) + " is neither 0 nor 1");
    }
    return;
  }
  const std::uint8_t coi = a.coi.value_or(0);
  auto& p = pending_[coi];
  if (!p) {
    ignored(now, message,
            "no open task has this COI: late, or another GUI's (the vehicle sends ANSWER to every "
            "connection)");
    return;
  }
  switch (a.code) {
    case 0:
      finish(p, coi, RequestState::error);
      return;
    case 1:  // the real vehicle never sends it; the deadline stays the task's
      emit(RequestEvent{coi, p->kind, p->task, RequestState::started, {}});
      return;
    case 2:
      finish(p, coi, RequestState::completed);
      return;
    default:
      ignored(now, message, "ANSWER code " + std::to_string(a.code) + " is none of 0, 1, 2");
      return;
  }
}

void SvguiClientCore::fresh(Time now, DataStream stream) {
  Stream& s = streams_[index(stream)];
  s.last = now;
  if (s.stale) {
    s.stale = false;
    emit(StaleEvent{false, stream});
  }
}

void SvguiClientCore::finish(std::optional<Pending>& slot, std::uint8_t coi, RequestState state,
                             std::string note) {
  if (!slot) return;
  emit(RequestEvent{coi, slot->kind, slot->task, state, std::move(note)});
  slot.reset();
}

void SvguiClientCore::ignored(Time now, const svgui::Message& message, std::string why) {
  note(now, "ignored (" + why + "): " + svgui::describe(message));
  emit(PacketIgnoredEvent{message, std::move(why)});
}

// ---- sending ----

void SvguiClientCore::send(Time now, const svgui::Message& message) {
  if (outbox_.empty() && may_send(now)) {
    write(now, message);
    return;
  }
  // Only the newest axes matter; the vehicle need not hear the old ones.
  if (std::holds_alternative<svgui::Control>(message) && !outbox_.empty() &&
      std::holds_alternative<svgui::Control>(outbox_.back())) {
    outbox_.back() = message;
    return;
  }
  outbox_.push_back(message);
}

bool SvguiClientCore::may_send(Time now) const {
  return !last_sent_ || now >= *last_sent_ + config_.send_gap;
}

void SvguiClientCore::write(Time now, const svgui::Message& message) {
  protocol::Bytes bytes = svgui::encode_prefixed(message, config_.version);
  log_->add({now, LogKind::tx, protocol::to_hex(bytes), svgui::describe(message)});
  actions_.push_back(SendBytes{std::move(bytes)});
  last_sent_ = now;
}

void SvguiClientCore::flush_outbox(Time now) {
  while (!outbox_.empty() && may_send(now)) {
    write(now, outbox_.front());
    outbox_.pop_front();
  }
}

std::optional<std::uint8_t> SvguiClientCore::free_coi() const {
  constexpr int kCount = kLastSvguiCoi - kFirstSvguiCoi + 1;
  for (int i = 0; i < kCount; ++i) {
    const int c = kFirstSvguiCoi + (next_coi_ - kFirstSvguiCoi + i) % kCount;
    if (!pending_[static_cast<std::size_t>(c)]) return static_cast<std::uint8_t>(c);
  }
  return std::nullopt;
}

std::size_t SvguiClientCore::open_requests() const {
  const auto tasks = static_cast<std::size_t>(
      std::count_if(pending_.begin(), pending_.end(), [](const auto& p) { return p.has_value(); }));
  return tasks + (set_pending_ ? 1U : 0U) + (set_request_pending_ ? 1U : 0U);
}

SubmitResult SvguiClientCore::send_task(Time now, proto::TaskCode type,
                                        std::vector<std::int32_t> params) {
  if (config_.version != Version::v2019) return {0, Refusal::bad_request};
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  const auto coi = free_coi();
  if (!coi) return {0, Refusal::busy};
  std::string busy_note;
  if (open_requests() > 0)
    busy_note = "another task is open: a busy v2019 vehicle drops this one without a word";
  send(now, svgui::Task{*coi, static_cast<std::uint8_t>(type), std::move(params)});
  next_coi_ = static_cast<std::uint8_t>(*coi == kLastSvguiCoi ? kFirstSvguiCoi : *coi + 1);
  pending_[*coi] =
      Pending{RequestKind::task, type, now + config_.task_timeout[static_cast<std::size_t>(type)]};
  emit(RequestEvent{*coi, RequestKind::task, type, RequestState::sent, std::move(busy_note)});
  return {*coi, Refusal::none};
}

SubmitResult SvguiClientCore::forward(Time now, std::int32_t distance_cm) {
  return send_task(now, proto::TaskCode::drive, {distance_cm});
}

SubmitResult SvguiClientCore::wheels(Time now, std::int32_t angle_deg) {
  return send_task(now, proto::TaskCode::turn, {angle_deg});
}

SubmitResult SvguiClientCore::signals(Time now) {
  return send_task(now, proto::TaskCode::blink, {});
}

SubmitResult SvguiClientCore::settings(Time now, const std::array<std::int32_t, 4>& values) {
  if (config_.version != Version::v2019) return {0, Refusal::bad_request};
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  const auto coi = free_coi();
  if (!coi) return {0, Refusal::busy};
  std::string why = "the v2019 vehicle never answers SETTINGS, and counts them as a running task";
  if (open_requests() > 0) why += "; a task is open, so a busy vehicle drops these without a word";
  send(now, svgui::Settings{*coi, values});
  next_coi_ = static_cast<std::uint8_t>(*coi == kLastSvguiCoi ? kFirstSvguiCoi : *coi + 1);
  emit(RequestEvent{*coi, RequestKind::settings, proto::TaskCode::check, RequestState::sent,
                    std::move(why)});
  return {*coi, Refusal::none};
}

SubmitResult SvguiClientCore::send_head_request(Time now, RequestKind kind, proto::TaskCode task,
                                                const svgui::Message& message) {
  if (config_.version != Version::head) return {0, Refusal::bad_request};
  if (state() != ConnectionState::connected) return {0, Refusal::not_connected};
  auto& slot = kind == RequestKind::settings ? set_pending_ : set_request_pending_;
  if (slot) return {0, Refusal::busy};
  send(now, message);
  slot = Pending{kind, task, now + config_.answer_timeout};
  emit(RequestEvent{0, kind, task, RequestState::sent, {}});
  return {0, Refusal::none};
}

SubmitResult SvguiClientCore::set(Time now, const svgui::Set& values) {
  for (const double v : values.values) {
    if (!std::isfinite(v)) return {0, Refusal::bad_request};
  }
  return send_head_request(now, RequestKind::settings, proto::TaskCode::check, values);
}

SubmitResult SvguiClientCore::set_request(Time now) {
  return send_head_request(now, RequestKind::task, proto::TaskCode::get_settings,
                           svgui::SetRequest{});
}

Refusal SvguiClientCore::control(Time now, double x_axis, double y_axis) {
  if (config_.version != Version::head) return Refusal::bad_request;
  const auto in_range = [](double v) { return std::isfinite(v) && v >= -1.0 && v <= 1.0; };
  if (!in_range(x_axis) || !in_range(y_axis)) return Refusal::bad_request;
  if (state() != ConnectionState::connected) return Refusal::not_connected;
  control_ = svgui::Control{x_axis, y_axis};
  send(now, *control_);
  // A change goes out at once; the repetition keeps its 100 ms grid.
  if (!next_control_) next_control_ = now + config_.control_period;
  return Refusal::none;
}

Refusal SvguiClientCore::release_control(Time now) {
  if (config_.version != Version::head) return Refusal::bad_request;
  if (state() != ConnectionState::connected) return Refusal::not_connected;
  if (!control_) return Refusal::none;
  control_.reset();
  next_control_.reset();
  send(now, svgui::Control{0.0, 0.0});
  return Refusal::none;
}

// ---- time ----

void SvguiClientCore::on_timer(Time now) {
  reconnect_if_due(now);
  check_login_deadline(now);
  if (state() != ConnectionState::connected) return;
  flush_outbox(now);
  for (std::size_t coi = 0; coi < pending_.size(); ++coi) {
    auto& p = pending_[coi];
    if (!p || now < p->deadline) continue;
    const Duration limit = config_.task_timeout[static_cast<std::size_t>(p->task)];
    note(now, "COI " + std::to_string(coi) + " timed out");
    finish(p, static_cast<std::uint8_t>(coi), RequestState::timed_out,
           "no ANSWER within " + duration_text(limit) +
               ": the v2019 vehicle sends no \"started\" and drops a task without a word while "
               "another task or SETTINGS keeps it busy, so a timeout is the only sign");
  }
  if (set_pending_ && now >= set_pending_->deadline) {
    note(now, "SET timed out");
    finish(set_pending_, 0, RequestState::timed_out,
           "no ANSWER within " + duration_text(config_.answer_timeout) +
               ": the head vehicle programs answer no SET; set-request reads the settings back");
  }
  if (set_request_pending_ && now >= set_request_pending_->deadline) {
    note(now, "SET-REQUEST timed out");
    finish(set_request_pending_, 0, RequestState::timed_out,
           "no SET within " + duration_text(config_.answer_timeout) +
               " (the head test vehicle does not answer SET-REQUEST)");
  }
  for (const DataStream stream : {DataStream::data, DataStream::high_freq, DataStream::low_freq}) {
    Stream& s = streams_[index(stream)];
    if (!s.stale && s.last && now >= *s.last + stale_after(stream)) {
      s.stale = true;
      note(now, std::string(to_string(stream)) + " stale");
      emit(StaleEvent{true, stream});
    }
  }
  if (control_ && next_control_ && now >= *next_control_) {
    send(now, *control_);
    while (*next_control_ <= now)
      *next_control_ += config_.control_period;
  }
}

std::optional<Time> SvguiClientCore::next_wakeup() const {
  link::Earliest next = connection_wakeup();
  if (state() != ConnectionState::connected) return next.time();
  for (const auto& p : pending_) {
    if (p) next.consider(p->deadline);
  }
  if (set_pending_) next.consider(set_pending_->deadline);
  if (set_request_pending_) next.consider(set_request_pending_->deadline);
  for (const DataStream stream : {DataStream::data, DataStream::high_freq, DataStream::low_freq}) {
    const Stream& s = streams_[index(stream)];
    if (!s.stale && s.last) next.consider(*s.last + stale_after(stream));
  }
  if (control_) next.consider(next_control_);
  if (!outbox_.empty() && last_sent_) next.consider(*last_sent_ + config_.send_gap);
  return next.time();
}

}  // namespace hil::client::wr8
