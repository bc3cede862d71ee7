#include "client/logi/operator.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>

#include "client/common/operator_text.hpp"

namespace hil::client::logi {

namespace {

/// Blanks between words; a line break is not one (an action is one line).
constexpr std::string_view kLineBlanks = " \t\r\v\f";

/// Digits only, at most three of them (stations are written 001 as well).
std::optional<int> parse_whole(std::string_view s, std::int64_t max) {
  const auto v = parse_integer(s, 0, max, {.plus = false, .minus = false, .max_digits = 3});
  if (!v) return std::nullopt;
  return static_cast<int>(v.value);
}

constexpr std::string_view kVerbs =
    "connect, disconnect, speed, mode, press, release, station, run, stop, estop, wait, confirm";

std::string direction_list() {
  std::string out;
  for (auto d : proto::kAllDirections) {
    if (!out.empty()) out += ", ";
    out += proto::to_string(d);
  }
  return out;
}

OperatorParseResult fail(int column, std::string message) {
  OperatorParseResult r;
  r.error = OperatorSyntaxError{static_cast<std::size_t>(column), std::move(message)};
  return r;
}

}  // namespace

std::optional<link::Duration> parse_duration(std::string_view text) {
  return client::parse_duration(text, link::seconds(24 * 3600));
}

std::string to_string(const OperatorAction& action) {
  return std::visit(
      Overloaded{
          [](const op::Connect&) -> std::string { return "connect"; },
          [](const op::Disconnect&) -> std::string { return "disconnect"; },
          [](const op::Speed& a) { return "speed " + std::to_string(a.percent); },
          [](const op::SetMode& a) { return "mode " + std::string(proto::to_string(a.mode)); },
          [](const op::Press& a) { return "press " + std::string(proto::to_string(a.direction)); },
          [](const op::Release&) -> std::string { return "release"; },
          [](const op::Station& a) { return "station " + std::to_string(a.station); },
          [](const op::Run&) -> std::string { return "run"; },
          [](const op::Stop&) -> std::string { return "stop"; },
          [](const op::EmergencyStop&) -> std::string { return "estop"; },
          [](const op::Wait& a) { return "wait " + format_duration(a.duration); },
          [](const op::Confirm&) -> std::string { return "confirm"; },
      },
      action);
}

OperatorParseResult parse_operator_action(std::string_view line) {
  const auto split = split_words(line, kLineBlanks);
  const auto& tokens = split.words;
  const int end_column = static_cast<int>(split.end_column);
  if (tokens.empty()) return {};
  const Word& verb_token = tokens[0];
  const std::string verb = to_lower(verb_token.text);

  // Verbs without an argument.
  std::optional<OperatorAction> bare;
  if (verb == "connect") bare = op::Connect{};
  if (verb == "disconnect") bare = op::Disconnect{};
  if (verb == "release") bare = op::Release{};
  if (verb == "run") bare = op::Run{};
  if (verb == "stop") bare = op::Stop{};
  if (verb == "estop") bare = op::EmergencyStop{};
  if (verb == "confirm") bare = op::Confirm{};

  std::string expected;  // what the argument must be, for the messages
  if (bare) {
    if (tokens.size() > 1) {
      return fail(static_cast<int>(tokens[1].column), "unexpected '" + std::string(tokens[1].text) +
                                                          "' after '" + verb +
                                                          "' (it takes no argument)");
    }
    OperatorParseResult r;
    r.action = *bare;
    return r;
  }
  if (verb == "speed") {
    expected = "a speed 0..100";
  } else if (verb == "mode") {
    expected = "MAN or AUTO";
  } else if (verb == "press") {
    expected = "a direction (" + direction_list() + ")";
  } else if (verb == "station") {
    expected = "a station number 1..999 (the car has 1 and 2; 001 and 002 also do)";
  } else if (verb == "wait") {
    expected = "a duration with a unit (500ms, 1s, 1.5s, 2m)";
  } else {
    return fail(static_cast<int>(verb_token.column),
                "unknown action '" + std::string(verb_token.text) + "' (expected one of " +
                    std::string(kVerbs) + ")");
  }
  if (tokens.size() < 2) return fail(end_column, "expected " + expected + " after '" + verb + "'");
  if (tokens.size() > 2) {
    return fail(static_cast<int>(tokens[2].column), "unexpected '" + std::string(tokens[2].text) +
                                                        "' after '" + verb + " " +
                                                        std::string(tokens[1].text) + "'");
  }
  const Word& arg = tokens[1];
  const auto bad = [&] {
    return fail(static_cast<int>(arg.column),
                "expected " + expected + ", got '" + std::string(arg.text) + "'");
  };
  OperatorParseResult r;
  if (verb == "speed") {
    const auto v = parse_whole(arg.text, 100);
    if (!v) return bad();
    r.action = op::Speed{*v};
  } else if (verb == "mode") {
    const auto m = proto::parse_mode(to_upper(arg.text));
    if (!m) return bad();
    r.action = op::SetMode{*m};
  } else if (verb == "press") {
    const auto d = proto::parse_direction(to_upper(arg.text));
    if (!d) return bad();
    r.action = op::Press{*d};
  } else if (verb == "station") {
    const auto v = parse_whole(arg.text, 999);
    if (!v || *v < 1) return bad();
    r.action = op::Station{*v};
  } else {  // wait
    const auto d = parse_duration(arg.text);
    if (!d) return bad();
    r.action = op::Wait{*d};
  }
  return r;
}

OperatorScript parse_operator_script(std::string_view text, std::string_view file_name) {
  OperatorScript script;
  int line_number = 0;
  for (const std::string_view line : split_lines(text)) {
    ++line_number;
    auto parsed = parse_operator_action(line);
    if (parsed.error) {
      script.errors.push_back({std::string(file_name), static_cast<std::size_t>(line_number),
                               parsed.error->column, parsed.error->message});
      continue;
    }
    if (parsed.action) {
      const std::string_view body = trim(line.substr(0, line.find('#')), kLineBlanks);
      script.steps.push_back(OperatorStep{line_number, std::string(body), *parsed.action});
    }
  }
  return script;
}

// ---- runner ----

OperatorRunner::OperatorRunner(LogiSession& session, link::Executor& executor,
                               std::vector<OperatorStep> steps, OperatorRunnerOptions options,
                               ResultSink on_result, DoneSink on_done)
    : session_(session),
      executor_(executor),
      steps_(std::move(steps)),
      options_(options),
      on_result_(std::move(on_result)),
      on_done_(std::move(on_done)),
      last_confirmable_(options_.confirmable) {}

OperatorRunner::~OperatorRunner() {
  *alive_ = false;
  stop_timer();
}

std::optional<std::size_t> OperatorRunner::current() const {
  if (!active_) return std::nullopt;
  return next_;
}

void OperatorRunner::start() {
  if (started_) return;
  started_ = true;
  due_ = 0;
  std::weak_ptr<bool> alive = alive_;
  executor_.post([this, alive] {
    if (const auto a = alive.lock(); !a || !*a) return;
    begin(0);
  });
}

void OperatorRunner::start_timer(link::Duration d, std::function<void()> then) {
  stop_timer();
  std::weak_ptr<bool> alive = alive_;
  timer_ = executor_.call_after(d, [this, alive, then = std::move(then)] {
    if (const auto a = alive.lock(); !a || !*a) return;
    timer_ = 0;
    then();
  });
}

void OperatorRunner::stop_timer() {
  if (timer_ != 0) executor_.cancel(timer_);
  timer_ = 0;
}

std::string OperatorRunner::refused(Refusal r) const {
  if (r == Refusal::mode_speed_unconfirmed) {
    return "refused: movement needs a 'mode' and a 'speed' on this connection first";
  }
  return "refused: " + std::string(to_string(r));
}

void OperatorRunner::begin(std::size_t index) {
  if (finished_) return;
  due_.reset();
  next_ = index;
  if (next_ >= steps_.size()) {
    finish_run(false);
    return;
  }
  active_ = true;
  action_started_ = executor_.now();
  outcomes_.clear();
  awaited_.clear();
  await_ = Await::none;
  last_connect_problem_.clear();

  const auto submitted = [this](SubmitResult r) {
    if (!r) {
      finish_action(false, refused(r.refusal));
      return;
    }
    await(r.request);
  };
  std::visit(
      Overloaded{
          [&](const op::Connect&) {
            if (session_.core().state() == ConnectionState::connected) {
              finish_action(true, {});
              return;
            }
            await_ = Await::connected;
            session_.connect();
            if (!active_ || await_ != Await::connected) return;  // connected at once
            if (session_.core().state() == ConnectionState::connected) {
              finish_action(true, {});
              return;
            }
            start_timer(options_.connect_timeout, [this] {
              await_ = Await::none;
              std::string reason =
                  "not connected after " + format_duration(options_.connect_timeout);
              if (!last_connect_problem_.empty()) reason += " (" + last_connect_problem_ + ")";
              // Stop retrying: what comes next is the script's decision.
              session_.disconnect();
              finish_action(false, reason);
            });
          },
          [&](const op::Disconnect&) {
            session_.disconnect();
            finish_action(true, {});
          },
          [&](const op::Speed& a) { submitted(session_.submit(proto::SetSpeed{a.percent})); },
          [&](const op::SetMode& a) { submitted(session_.submit(proto::SetMode{a.mode})); },
          [&](const op::Press& a) { submitted(session_.press(a.direction)); },
          [&](const op::Release&) { submitted(session_.release()); },
          [&](const op::Station& a) { submitted(session_.submit(proto::SetStation{a.station})); },
          [&](const op::Run&) { submitted(session_.submit(proto::SetRun{true})); },
          [&](const op::Stop&) { submitted(session_.submit(proto::SetRun{false})); },
          [&](const op::EmergencyStop&) {
            collect_sent_ = true;
            const auto r = session_.emergency_stop();
            collect_sent_ = false;
            if (!r) {
              finish_action(false, refused(r.refusal));
              return;
            }
            if (std::find(awaited_.begin(), awaited_.end(), r.request) == awaited_.end()) {
              awaited_.push_back(r.request);
            }
            await_ = Await::requests;
            check_requests();
          },
          [&](const op::Wait& a) { start_timer(a.duration, [this] { finish_action(true, {}); }); },
          [&](const op::Confirm&) {
            if (!last_confirmable_) {
              finish_action(false, "nothing to confirm: no ST:RUN or GS awaits a resend");
              return;
            }
            const RequestId id = *last_confirmable_;
            last_confirmable_.reset();
            submitted(session_.confirm_resend(id));
          },
      },
      steps_[index].action);
}

void OperatorRunner::await(RequestId id) {
  awaited_ = {id};
  await_ = Await::requests;
  check_requests();
}

void OperatorRunner::on_event(Time /*now*/, const Event& event) {
  if (const auto* c = std::get_if<CommandEvent>(&event)) {
    if (c->state == CommandState::uncertain && c->resend_on_confirm) {
      last_confirmable_ = c->request;
    }
    if (c->state == CommandState::sent) {
      if (collect_sent_ &&
          std::find(awaited_.begin(), awaited_.end(), c->request) == awaited_.end()) {
        awaited_.push_back(c->request);
      }
      return;
    }
    if (!active_) return;
    outcomes_.push_back(*c);
    check_requests();
    return;
  }
  if (const auto* c = std::get_if<ConnectionEvent>(&event)) {
    if (c->state != ConnectionState::connected) last_confirmable_.reset();
    if (c->state == ConnectionState::reconnecting) {
      last_connect_problem_ =
          "the connection failed; reconnect attempt " + std::to_string(c->attempt) + " pending";
    }
    if (active_ && await_ == Await::connected && c->state == ConnectionState::connected) {
      await_ = Await::none;
      finish_action(true, {});
    }
  }
}

void OperatorRunner::check_requests() {
  if (!active_ || await_ != Await::requests || awaited_.empty()) return;
  std::vector<const CommandEvent*> ends;
  for (RequestId id : awaited_) {
    auto it = std::find_if(outcomes_.begin(), outcomes_.end(),
                           [&](const CommandEvent& e) { return e.request == id; });
    if (it == outcomes_.end()) return;  // still under way
    ends.push_back(&*it);
  }
  std::string reasons;
  bool any_accepted = false;
  for (const auto* e : ends) {
    const auto code = proto::command_of(e->command);
    const std::string name = code ? std::string(proto::to_string(*code)) : "?";
    std::string reason;
    switch (e->state) {
      case CommandState::accepted:
        any_accepted = true;
        continue;
      case CommandState::rejected:
        reason = "rejected by the car (FB:" + name + ":0)";
        break;
      case CommandState::uncertain:
        reason = "no feedback to " + proto::kind_of(e->command) + " within " +
                 format_duration(session_.core().config().feedback_timeout) + " (" +
                 std::to_string(e->attempt) + (e->attempt == 1 ? " send" : " sends") +
                 "), uncertain";
        if (e->resend_on_confirm) reason += "; 'confirm' sends it again";
        break;
      case CommandState::cancelled:
        reason = session_.core().state() == ConnectionState::connected
                     ? "cancelled by an emergency stop"
                     : "cancelled: the connection was lost";
        break;
      case CommandState::sent:
        break;
    }
    if (!reasons.empty()) reasons += "; ";
    reasons += reason;
  }
  // One request: it must be accepted. An emergency stop's MV:STOP and
  // ST:STOP: the car has stopped if either was accepted (in AUTO the car
  // refuses every MV, MV:STOP included).
  if (any_accepted) {
    finish_action(true, {});
  } else {
    finish_action(false, reasons);
  }
}

void OperatorRunner::finish_action(bool ok, std::string reason) {
  if (!active_) return;
  stop_timer();
  active_ = false;
  await_ = Await::none;
  awaited_.clear();
  ActionResult result;
  result.index = next_;
  result.line = steps_[next_].line;
  result.text = steps_[next_].text.empty() ? to_string(steps_[next_].action) : steps_[next_].text;
  result.ok = ok;
  result.reason = std::move(reason);
  result.started = action_started_;
  result.ended = executor_.now();
  results_.push_back(result);
  if (!ok) any_failed_ = true;
  if (on_result_) on_result_(result);
  if (finished_) return;  // the sink cancelled the run
  if (!ok && !options_.continue_on_error) {
    finish_run(false);
    return;
  }
  const std::size_t following = next_ + 1;
  due_ = following;
  std::weak_ptr<bool> alive = alive_;
  executor_.post([this, alive, following] {
    if (const auto a = alive.lock(); !a || !*a) return;
    begin(following);
  });
}

void OperatorRunner::finish_run(bool cancelled) {
  if (finished_) return;
  finished_ = true;
  RunSummary summary;
  summary.cancelled = cancelled;
  summary.ran = results_.size();
  summary.failed = static_cast<std::size_t>(
      std::count_if(results_.begin(), results_.end(), [](const auto& r) { return !r.ok; }));
  summary.ok = !cancelled && summary.failed == 0 && results_.size() == steps_.size();
  if (on_done_) on_done_(summary);
}

void OperatorRunner::cancel() {
  if (finished_) return;
  // The action under way, or the one whose first turn is still to come
  // (it was started or the previous one ended, on a turn of its own).
  std::optional<std::size_t> interrupted;
  if (active_) {
    interrupted = next_;
  } else if (due_ && *due_ < steps_.size()) {
    interrupted = *due_;
    action_started_ = executor_.now();
  }
  due_.reset();
  if (interrupted) {
    // Report the interrupted action, then end without starting another.
    finished_ = true;  // keeps finish_action from scheduling the next one
    stop_timer();
    active_ = false;
    const std::size_t i = *interrupted;
    ActionResult result;
    result.index = i;
    result.line = steps_[i].line;
    result.text = steps_[i].text.empty() ? to_string(steps_[i].action) : steps_[i].text;
    result.ok = false;
    result.reason = "cancelled";
    result.started = action_started_;
    result.ended = executor_.now();
    results_.push_back(result);
    any_failed_ = true;
    if (on_result_) on_result_(result);
    finished_ = false;
  }
  finish_run(true);
}

}  // namespace hil::client::logi
