#include "apps/logi-client/tui.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <asio/posix/stream_descriptor.hpp>
#include <asio/post.hpp>
#include <asio/signal_set.hpp>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "apps/common/log_file.hpp"
#include "apps/common/program.hpp"
#include "apps/logi-client/tui_model.hpp"
#include "apps/logi-client/tui_view.hpp"
#include "client/logi/session.hpp"
#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

namespace hil::apps::logi_client {

namespace {

/// The screen's SessionControl over a real LogiSession; the session is made
/// again when the operator connects to another address, the log is kept.
class LiveSession final : public SessionControl {
 public:
  LiveSession(link::TransportContext& context, logi::ClientConfig config, std::string log_dir,
              logi::LogiSession::EventSink sink)
      : context_(context),
        config_(std::move(config)),
        log_dir_(std::move(log_dir)),
        sink_(std::move(sink)) {}

  void connect(const std::string& host, std::uint16_t port) override {
    const std::string address = "tcp://" + host + ":" + std::to_string(port);
    if (!session_ || address != address_) {
      link::Endpoint endpoint;
      try {
        endpoint = link::parse_endpoint(address);
      } catch (const std::exception& e) {
        log_->add({context_.executor.now(), logi::LogKind::note, "",
                   "cannot connect to " + address + ": " + e.what()});
        return;
      }
      session_.reset();
      session_ = std::make_unique<logi::LogiSession>(context_, endpoint, config_, sink_, log_);
      address_ = address;
    }
    session_->connect();
  }
  void disconnect() override {
    if (session_) session_->disconnect();
  }
  logi::SubmitResult submit(const proto::Message& command) override {
    if (!session_) return {0, logi::Refusal::not_connected};
    return session_->submit(command);
  }
  logi::SubmitResult press(proto::Direction direction) override {
    if (!session_) return {0, logi::Refusal::not_connected};
    return session_->press(direction);
  }
  logi::SubmitResult release() override {
    if (!session_) return {0, logi::Refusal::not_held};
    return session_->release();
  }
  logi::SubmitResult emergency_stop() override {
    if (!session_) return {0, logi::Refusal::not_connected};
    return session_->emergency_stop();
  }
  logi::SubmitResult confirm_resend(logi::RequestId request) override {
    if (!session_) return {0, logi::Refusal::unknown_request};
    return session_->confirm_resend(request);
  }
  bool busy() const override {
    return session_ && (session_->core().queued() > 0 || session_->core().in_flight() > 0);
  }
  std::string save_log(LogFormat format) override {
    char stamp[32];
    const std::time_t t = std::time(nullptr);
    std::tm local{};
    localtime_r(&t, &local);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
    const char* ext = format == LogFormat::txt   ? "txt"
                      : format == LogFormat::csv ? "csv"
                                                 : "ndjson";
    const std::string path = log_dir_ + "/logi-client-log-" + stamp + "." + ext;
    if (!log_->save(path, format)) return "could not write " + path + ": " + std::strerror(errno);
    return "log saved to " + path + " (" + std::to_string(log_->total()) + " entries)";
  }

  const std::shared_ptr<logi::CommLog>& log() const { return log_; }

 private:
  link::TransportContext& context_;
  logi::ClientConfig config_;
  std::string log_dir_;
  logi::LogiSession::EventSink sink_;
  std::shared_ptr<logi::CommLog> log_ = std::make_shared<logi::CommLog>();
  std::unique_ptr<logi::LogiSession> session_;
  std::string address_;
};

/// The program around the model: terminal input, signals, timers, redraws.
class TuiApp {
 public:
  explicit TuiApp(const TuiOptions& options)
      : session_(program_.context(), client_config(options), options.log_dir,
                 [this](Time now, const logi::Event& event) {
                   // Handled on a later turn: the model may be inside a call on the session.
                   asio::post(program_.io(), [this, now, event] {
                     model_.on_event(now, event);
                     changed();
                   });
                 }),
        model_(session_, model_config(options)),
        input_(program_.io(), ::dup(STDIN_FILENO)) {}

  int run() {
    TuiScreen screen;
    screen_ = &screen;
    program_.on_stop_signal([this](int) {
      model_.quit(now());
      changed();
    });
    resize_signal_.async_wait([this](const std::error_code& ec, int) { on_resize(ec); });
    model_.start(now());
    wait_for_input();
    tick();
    changed();
    program_.run();
    screen_ = nullptr;
    return 0;
  }

 private:
  static logi::ClientConfig client_config(const TuiOptions& options) {
    logi::ClientConfig c;
    c.keepalive = options.keepalive;
    return c;
  }
  static TuiModelConfig model_config(const TuiOptions& options) {
    TuiModelConfig c;
    c.host = options.host;
    c.port = options.port;
    c.connect_at_start = options.connect_at_start;
    return c;
  }

  void wait_for_input() {
    input_.async_wait(asio::posix::stream_descriptor::wait_read, [this](const std::error_code& ec) {
      if (ec) return;
      bool any = false;
      while (const auto k = screen_->read_key()) {
        any = true;
        model_.on_key(now(), *k);
      }
      // Readable with nothing to read, again and again: the terminal is gone.
      idle_wakeups_ = any ? 0 : idle_wakeups_ + 1;
      if (idle_wakeups_ > 100) model_.quit(now());
      changed();
      if (!model_.done()) wait_for_input();
    });
  }

  void on_resize(const std::error_code& ec) {
    if (ec) return;
    screen_->resize();
    changed();
    resize_signal_.async_wait([this](const std::error_code& e, int) { on_resize(e); });
  }

  // Redraws now and then even without news: the STAT age, the banner.
  void tick() {
    executor().call_after(link::milliseconds(250), [this] {
      if (model_.done()) return;
      changed();
      tick();
    });
  }

  // After anything happened: the log, the model's timer, the screen, the end.
  void changed() {
    const auto fresh = session_.log()->since(log_seen_);
    log_seen_ += fresh.size();
    if (!fresh.empty()) model_.on_log(fresh);
    model_.on_time(now());
    if (wakeup_timer_ != 0) executor().cancel(wakeup_timer_);
    wakeup_timer_ = 0;
    if (const auto at = model_.next_wakeup()) {
      wakeup_timer_ = executor().call_at(*at, [this] {
        wakeup_timer_ = 0;
        changed();
      });
    }
    if (screen_ != nullptr) screen_->draw(model_, now());
    if (model_.done()) {
      input_.cancel();
      resize_signal_.cancel();
      program_.stop(/*at_once=*/true);
    }
  }

  Time now() { return program_.executor().now(); }
  link::AsioExecutor& executor() { return program_.executor(); }

  ProgramLoop program_{SIGINT, SIGTERM, SIGHUP};
  LiveSession session_;
  TuiModel model_;
  asio::posix::stream_descriptor input_;
  asio::signal_set resize_signal_{program_.io(), SIGWINCH};
  TuiScreen* screen_ = nullptr;
  std::uint64_t log_seen_ = 0;
  link::Executor::TimerId wakeup_timer_ = 0;
  int idle_wakeups_ = 0;
};

}  // namespace

int run_tui(const TuiOptions& options) {
  if (::isatty(STDIN_FILENO) == 0 || ::isatty(STDOUT_FILENO) == 0) {
    std::fputs("logi-client: the terminal UI needs a terminal; use --script or actions\n", stderr);
    return 2;
  }
  // Asio may make the terminal non-blocking; the shell gets it back as it was.
  const int stdin_flags = ::fcntl(STDIN_FILENO, F_GETFL);
  struct RestoreFlags {
    int flags;
    ~RestoreFlags() {
      if (flags >= 0) ::fcntl(STDIN_FILENO, F_SETFL, flags);
    }
  } restore{stdin_flags};
  try {
    TuiApp app(options);
    return app.run();
  } catch (const std::exception& e) {
    // The screen is closed by now (its destructor ran during unwinding).
    std::fprintf(stderr, "logi-client: %s\n", e.what());
    return 1;
  }
}

}  // namespace hil::apps::logi_client
