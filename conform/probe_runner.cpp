#include "conform/probe_runner.hpp"

#include <memory>
#include <utility>

#include "link/transport.hpp"

namespace hil::conform {

namespace {

// The pause between closing a connection and opening it again in a
// connect exchange, so the car sees the close before the new connection.
constexpr Duration kReconnectGap = std::chrono::milliseconds(200);

class ProbeRunner {
 public:
  ProbeRunner(harness::RunDriver& driver, link::Endpoint target, const Probe& probe,
              CaptureRecorder& recorder, const ProbeHooks& hooks)
      : driver_(driver),
        target_(std::move(target)),
        probe_(probe),
        recorder_(recorder),
        hooks_(hooks) {}

  ~ProbeRunner() {
    *alive_ = false;
    if (pipe_) pipe_->close();
  }

  std::optional<std::string> run() {
    executor().call_at(executor().now(), guarded([this] { start_exchange(0); }));
    const Time deadline = executor().now() + probe_.duration() * 2 + std::chrono::seconds(30);
    if (auto stuck = driver_.drive([this] { return done_; }, deadline)) {
      if (!error_) error_ = *stuck;
    }
    if (!done_ && !error_) error_ = "the probe did not finish in time";
    close_here();
    return error_;
  }

 private:
  link::Executor& executor() { return driver_.executor(); }

  template <class F>
  link::Executor::Task guarded(F f) {
    return [alive = alive_, f = std::move(f)] {
      if (*alive) f();
    };
  }

  void start_exchange(std::size_t index) {
    if (index >= probe_.exchanges.size()) {
      close_here();
      done_ = true;
      return;
    }
    if (!stopping_ && hooks_.interrupted && hooks_.interrupted()) {
      stopping_ = true;
      error_ = "interrupted: the probe sent its closing stop and ended";
      index = probe_.exchanges.size() - 1;
    }
    index_ = index;
    const auto& exchange = probe_.exchanges[index];
    if (hooks_.progress) {
      hooks_.progress("exchange " + std::to_string(index + 1) + "/" +
                      std::to_string(probe_.exchanges.size()) + " " + exchange.name);
    }
    recorder_.begin_exchange(executor().now(), exchange.name, exchange.kind, exchange.what);
    if (exchange.kind != ExchangeKind::connect) {
      write_from(0);
      return;
    }
    const bool was_open = pipe_ != nullptr;
    close_here();
    const Time at = executor().now() + (was_open ? kReconnectGap : Duration{0});
    executor().call_at(at, guarded([this] { open(); }));
  }

  void open() {
    link::connect(driver_.context(), target_,
                  [this, alive = alive_](std::error_code ec, link::BytePipePtr pipe) {
                    if (!*alive) return;
                    if (ec || !pipe) {
                      fail("cannot open " + link::to_uri(target_) + ": " + ec.message());
                      return;
                    }
                    opened(std::move(pipe));
                  });
  }

  void opened(link::BytePipePtr pipe) {
    pipe_ = std::move(pipe);
    recorder_.opened(executor().now(), "probe", pipe_->describe());
    const auto* current = pipe_.get();
    pipe_->start({[this, alive = alive_](link::ByteView bytes) {
                    if (*alive) recorder_.received(executor().now(), bytes);
                  },
                  [this, alive = alive_, current](std::error_code ec) {
                    if (*alive && pipe_.get() == current) closed_by_car(ec);
                  }});
    executor().call_at(executor().now() + probe_.settle, guarded([this] { write_from(0); }));
  }

  void write_from(std::size_t write) {
    const auto& exchange = probe_.exchanges[index_];
    if (write >= exchange.writes.size()) {
      executor().call_at(executor().now() + exchange.listen,
                         guarded([this] { finish_exchange(); }));
      return;
    }
    executor().call_at(executor().now() + exchange.writes[write].after, guarded([this, write] {
                         const auto& bytes = probe_.exchanges[index_].writes[write].bytes;
                         if (pipe_ && pipe_->is_open()) {
                           recorder_.sent(executor().now(), bytes);
                           pipe_->write(bytes);
                         }
                         write_from(write + 1);
                       }));
  }

  void finish_exchange() {
    recorder_.end_exchange(executor().now());
    start_exchange(stopping_ ? probe_.exchanges.size() : index_ + 1);
  }

  void closed_by_car(std::error_code ec) {
    link::LinkClose close;
    close.by = link::LinkClose::By::car;
    close.mode =
        ec == std::errc::connection_reset ? link::CloseMode::reset : link::CloseMode::graceful;
    close.reason = ec == link::end_of_stream() ? "car closed" : "car closed: " + ec.message();
    recorder_.closed(executor().now(), close);
    pipe_.reset();
  }

  void close_here() {
    if (!pipe_) return;
    auto pipe = std::exchange(pipe_, nullptr);
    pipe->close();
    recorder_.closed(executor().now(), {link::LinkClose::By::client, link::CloseMode::graceful,
                                        "closed by the probe"});
  }

  void fail(std::string error) {
    error_ = std::move(error);
    recorder_.end_exchange(executor().now());
    done_ = true;
  }

  harness::RunDriver& driver_;
  link::Endpoint target_;
  const Probe& probe_;
  CaptureRecorder& recorder_;
  const ProbeHooks& hooks_;
  link::BytePipePtr pipe_;
  std::size_t index_ = 0;
  bool done_ = false;
  bool stopping_ = false;
  std::optional<std::string> error_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace

link::CaptureHeader capture_header(const Probe& probe, std::string target,
                                   std::int64_t started_wall_us) {
  return {probe.version, std::string(mocks::to_string(probe.car)), probe.profile, std::move(target),
          started_wall_us};
}

ProbeRun run_probe(harness::RunDriver& driver, const link::Endpoint& target, const Probe& probe,
                   CaptureRecorder& recorder, const ProbeHooks& hooks) {
  ProbeRunner runner(driver, target, probe, recorder, hooks);
  auto error = runner.run();
  recorder.end_exchange(driver.executor().now());
  return {recorder.take(), std::move(error)};
}

}  // namespace hil::conform
