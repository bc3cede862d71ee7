#pragma once
// What the runners of both WR8 vocabularies share (client/wr8/operator.hpp
// for the document's, svgui_operator.hpp for the real programs'): one
// action at a time with its timer, the result handed on from the executor,
// a batch run in order, and the words every dialect has (connect,
// disconnect, wait, wait-data) with the login events that end a connect.

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "client/common/operator_text.hpp"
#include "client/wr8/core.hpp"
#include "link/executor.hpp"

namespace hil::client::wr8 {

namespace op {
/// Opens the connection and logs in.
struct Connect {
  friend bool operator==(const Connect&, const Connect&) = default;
};
struct Disconnect {
  friend bool operator==(const Disconnect&, const Disconnect&) = default;
};
struct Wait {
  Duration duration{0};
  friend bool operator==(const Wait&, const Wait&) = default;
};
/// Waits for the next DATA packet.
struct WaitData {
  friend bool operator==(const WaitData&, const WaitData&) = default;
};
}  // namespace op

/// How one action ended (of either dialect's vocabulary).
template <class Action>
struct BasicActionResult {
  Action action;
  Time started{0};
  Time finished{0};
  bool ok = false;
  /// For a success what came back ("logged in: device 8, id 1, STOP",
  /// "P=1.5 I=0.25 ..."), for a failure the reason.
  std::string detail;
};

struct RunnerOptions {
  /// A `connect` that has not logged in this long after it was given fails.
  Duration connect_timeout = link::seconds(10);
  /// A `wait-data` without DATA this long fails.
  Duration data_timeout = link::seconds(5);
};

/// "refused: not connected": a core's refusal as an action's failure.
std::string refusal_text(Refusal refusal);

/// `Derived` carries out the words of its own dialect in execute() and
/// passes every session event to on_event(); `Pending` is what it keeps
/// about the request an action waits for.
template <class Derived, class Session, class Action, class Pending>
class ActionRunner {
 public:
  using Result = BasicActionResult<Action>;
  using Done = std::function<void(const Result&)>;

  ActionRunner(link::Executor& executor, Session& session, RunnerOptions options)
      : executor_(executor), session_(session), options_(options) {}
  ~ActionRunner() {
    *alive_ = false;
    if (current_ && current_->timer) executor_.cancel(*current_->timer);
  }
  ActionRunner(const ActionRunner&) = delete;
  ActionRunner& operator=(const ActionRunner&) = delete;

  /// Runs `actions` in order, each result to `each`; stops after the first
  /// failure unless `keep_going`. `finished(all_ok)` comes at the end.
  void run(std::vector<Action> actions, bool keep_going, Done each,
           std::function<void(bool all_ok)> finished) {
    queue_ = std::move(actions);
    next_ = 0;
    keep_going_ = keep_going;
    all_ok_ = true;
    each_ = std::move(each);
    finished_ = std::move(finished);
    run_next();
  }

  bool busy() const { return current_.has_value(); }

 protected:
  struct Current {
    Action action;
    Time started{0};
    Done done;
    std::optional<link::Executor::TimerId> timer;
    Pending pending{};
  };

  /// Makes `action` the current one and carries it out when it is a shared
  /// word; false when the dialect's own execute() must. Programmer error
  /// (std::logic_error) while another action runs.
  bool begin(Action action, Done done) {
    if (current_) throw std::logic_error("an operator runner was given an action while one runs");
    current_ = Current{std::move(action), executor_.now(), std::move(done), {}, {}};
    const auto& core = session_.core();
    if (std::holds_alternative<op::Connect>(current_->action)) {
      if (core.state() == ConnectionState::connected) {
        finish(true, "already logged in");
        return true;
      }
      session_.connect();
      arm_timer(options_.connect_timeout, [this] {
        session_.disconnect();
        finish(false, "not logged in within " + duration_text(options_.connect_timeout));
      });
      return true;
    }
    if (std::holds_alternative<op::Disconnect>(current_->action)) {
      session_.disconnect();
      finish(true, "disconnected");
      return true;
    }
    if (const auto* wait = std::get_if<op::Wait>(&current_->action)) {
      arm_timer(wait->duration, [this] { finish(true, ""); });
      return true;
    }
    if (std::holds_alternative<op::WaitData>(current_->action)) {
      if (core.state() == ConnectionState::disconnected) {
        finish(false, "not connected");
        return true;
      }
      arm_timer(options_.data_timeout, [this] {
        finish(false, "no DATA within " + duration_text(options_.data_timeout));
      });
      return true;
    }
    return false;
  }

  /// The events that end a shared word: a login, a failed login, a drop
  /// while waiting for DATA. `data` ends a wait-data with its text.
  void on_login(const LoginEvent& e) {
    if (!waits_for<op::Connect>()) return;
    finish(true, "logged in: device " + std::to_string(e.reply.device_code) + ", id " +
                     std::to_string(e.reply.device_id) + ", " +
                     std::string(proto::to_string(e.reply.state)));
  }
  void on_login_failed(const LoginFailedEvent& e) {
    if (!waits_for<op::Connect>()) return;
    // A failed login is the operator's answer: stop the retries.
    session_.disconnect();
    finish(false, e.reason);
  }
  void on_connection(const ConnectionEvent& e) {
    if (waits_for<op::WaitData>() && e.state == ConnectionState::disconnected)
      finish(false, "disconnected");
  }
  void on_data(const std::string& text) {
    if (waits_for<op::WaitData>()) finish(true, text);
  }
  /// Hands a session event to the action under way, if any: to `own` (the
  /// dialect's handlers, an Overloaded) when it takes the event's type,
  /// else a login, a failed login or a connection change to the shared
  /// words above; other events end nothing.
  template <class Event, class Own>
  void dispatch(const Event& event, Own own) {
    if (!current_) return;
    std::visit(
        [&](const auto& e) {
          using E = std::remove_cvref_t<decltype(e)>;
          if constexpr (std::is_invocable_v<Own&, const E&>) {
            own(e);
          } else if constexpr (std::is_same_v<E, LoginEvent>) {
            on_login(e);
          } else if constexpr (std::is_same_v<E, LoginFailedEvent>) {
            on_login_failed(e);
          } else if constexpr (std::is_same_v<E, ConnectionEvent>) {
            on_connection(e);
          }
        },
        event);
  }
  template <class Word>
  bool waits_for() const {
    return current_ && std::holds_alternative<Word>(current_->action);
  }

  void refuse(Refusal refusal) { finish(false, refusal_text(refusal)); }

  void finish(bool ok, std::string detail) {
    if (!current_) return;
    if (current_->timer) executor_.cancel(*current_->timer);
    Result result{std::move(current_->action), current_->started, executor_.now(), ok,
                  std::move(detail)};
    Done done = std::move(current_->done);
    current_.reset();
    // Handed on from the executor, not from inside the session's event
    // sink, so the next action never starts in the middle of the session's
    // work.
    std::weak_ptr<bool> alive = alive_;
    executor_.post([alive, done = std::move(done), result = std::move(result)] {
      if (const auto a = alive.lock(); !a || !*a) return;
      if (done) done(result);
    });
  }

  void arm_timer(Duration after, std::function<void()> fire) {
    std::weak_ptr<bool> alive = alive_;
    current_->timer = executor_.call_after(after, [this, alive, fire = std::move(fire)] {
      if (const auto a = alive.lock(); !a || !*a) return;
      if (!current_) return;
      current_->timer.reset();
      fire();
    });
  }

  link::Executor& executor_;
  Session& session_;
  RunnerOptions options_;
  std::optional<Current> current_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);

 private:
  void run_next() {
    if (next_ >= queue_.size() || (!all_ok_ && !keep_going_)) {
      auto finished = std::move(finished_);
      if (finished) finished(all_ok_);
      return;
    }
    static_cast<Derived*>(this)->execute(queue_[next_++], [this](const Result& r) {
      if (!r.ok) all_ok_ = false;
      if (each_) each_(r);
      run_next();
    });
  }

  std::vector<Action> queue_;
  std::size_t next_ = 0;
  bool keep_going_ = false;
  bool all_ok_ = true;
  Done each_;
  std::function<void(bool)> finished_;
};

}  // namespace hil::client::wr8
