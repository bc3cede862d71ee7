#include "harness/exec_client.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <deque>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/write.hpp>

extern char** environ;

namespace hil::harness {
namespace {

using std::chrono::milliseconds;

// Output that does not end in a line break is still a line once this long.
constexpr std::size_t kMaxLineBytes = 64 * 1024;
// A program whose pipes stay open after it exited (a child it left behind
// holds them) has its exit recorded this long after waitpid saw it.
constexpr Duration kPipeGrace = milliseconds(300);

bool plain_word(std::string_view word) {
  return !word.empty() && std::all_of(word.begin(), word.end(),
                                      [](char c) { return (c >= 'a' && c <= 'z') || c == '_'; });
}

std::string_view trim_view(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0)
    s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0)
    s.remove_suffix(1);
  return s;
}

// The first whitespace-separated word of `s`, and `s` after it.
std::pair<std::string_view, std::string_view> first_word(std::string_view s) {
  s = trim_view(s);
  const auto end = s.find_first_of(" \t");
  if (end == std::string_view::npos) return {s, {}};
  return {s.substr(0, end), trim_view(s.substr(end))};
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool one_of(std::string_view word, std::initializer_list<std::string_view> words) {
  return std::find(words.begin(), words.end(), word) != words.end();
}

std::optional<ClientLine> event_line(std::string_view rest) {
  const auto [what, args] = first_word(rest);
  ClientLine line;
  line.kind = ClientLine::Kind::event;
  line.record_data = nlohmann::json::object();
  if (what == "connection") {
    const auto [state, more] = first_word(args);
    if (!one_of(state, {"connecting", "connected", "disconnected", "reconnecting", "authenticating",
                        "degraded", "down"}) ||
        !more.empty())
      return std::nullopt;
    line.record_kind = ClientKind::connection;
    line.record_data["state"] = std::string(state);
    return line;
  }
  if ((what == "stale" || what == "fresh") && args.empty()) {
    line.record_kind = *parse_record_kind(Source::client, what);
    return line;
  }
  if (what == "command") {
    const auto [command, after] = first_word(args);
    const auto [state, more] = first_word(after);
    if (command.empty() || state.empty() || !more.empty()) return std::nullopt;
    line.record_kind = ClientKind::command;
    line.record_data["command"] = std::string(command);
    line.record_data["state"] = std::string(state);
    return line;
  }
  if ((what == "notice" || what == "parse_error") && !args.empty()) {
    line.record_kind = *parse_record_kind(Source::client, what);
    line.record_data["text"] = std::string(args);
    return line;
  }
  // `movement enabled|disabled REASON`, `login ok|failed [REASON]`.
  const auto [word, reason] = first_word(args);
  if (what == "movement" && one_of(word, {"enabled", "disabled"})) {
    line.record_kind = ClientKind::movement;
    line.record_data["enabled"] = word == "enabled";
    line.record_data["reason"] = std::string(reason);
    return line;
  }
  if (what == "login" && one_of(word, {"ok", "failed"})) {
    line.record_kind = ClientKind::login;
    line.record_data["ok"] = word == "ok";
    if (!reason.empty()) line.record_data["reason"] = std::string(reason);
    return line;
  }
  return std::nullopt;
}

std::string exit_text(const nlohmann::json& exit) {
  if (exit.contains("code")) {
    // The shell's own codes for a command it could not run.
    const int code = exit["code"].get<int>();
    return "the client exited with code " + std::to_string(code) +
           (code == 127   ? " (the shell found no such command)"
            : code == 126 ? " (the command is not executable)"
                          : "");
  }
  return "the client was ended by signal " + exit.value("signal", nlohmann::json(0)).dump();
}

class ExecSession final : public ScenarioClient {
 public:
  ExecSession(link::TransportContext& context, ExecOptions options, RunTimeline& timeline)
      : executor_(context.executor),
        io_(*context.io),
        options_(std::move(options)),
        timeline_(timeline),
        stdin_(io_),
        stdout_(io_),
        stderr_(io_) {}

  ~ExecSession() override {
    *alive_ = false;
    if (pid_ > 0 && !reaped_) {
      ::kill(-pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    if (startup_timer_ != 0) executor_.cancel(startup_timer_);
  }

  void start() override {
    spawn();
    if (pid_ <= 0) return;
    read(stdout_, out_buffer_, out_line_, "stdout");
    read(stderr_, err_buffer_, err_line_, "stderr");
  }

  void execute(const std::string& text, Done done) override {
    if (pid_ <= 0) {
      done(false, spawn_error_.empty() ? "the client is not running" : spawn_error_);
      return;
    }
    if (exit_) {
      done(false, exit_text(*exit_) + " before this action");
      return;
    }
    pending_.push_back(std::move(done));
    queue_write(text + "\n");
    if (!first_action_handed_) {
      first_action_handed_ = true;
      arm_startup_timer();
    }
  }

  // Lines go out as the scenario reaches them; results come back in order.
  bool concurrent() const override { return true; }

  void cancel() override {
    // Results still owed for these actions must not be taken for later ones.
    ignore_results_ += pending_.size();
    pending_.clear();
  }

  void stop() override {
    closing_ = true;
    if (writes_.empty()) close_stdin();
  }

  void poll() override { reap(); }

  bool finished() const override { return pid_ <= 0 || exit_.has_value(); }

  void on_first_result(std::function<void()> f) override { on_first_result_ = std::move(f); }

  void terminate(bool hard) override {
    if (pid_ <= 0 || reaped_) return;
    killed_ = hard ? SIGKILL : SIGTERM;
    ::kill(-pid_, killed_);
  }

 private:
  using Descriptor = asio::posix::stream_descriptor;

  void spawn() {
    std::array<int, 2> in{-1, -1}, out{-1, -1}, err{-1, -1};
    if (::pipe2(in.data(), O_CLOEXEC) != 0 || ::pipe2(out.data(), O_CLOEXEC) != 0 ||
        ::pipe2(err.data(), O_CLOEXEC) != 0) {
      spawn_error_ = std::string("cannot make pipes for the client: ") + std::strerror(errno);
      for (int fd : {in[0], in[1], out[0], out[1], err[0], err[1]})
        if (fd >= 0) ::close(fd);
      record_spawn_error();
      return;
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in[0], 0);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_adddup2(&actions, err[1], 2);
    // Nothing else of hil's: the sockets of other runs going on at the
    // same time (hil run -j) must not stay open in this program, or a
    // close or reset there would not reach their clients.
    posix_spawn_file_actions_addclosefrom_np(&actions, 3);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    // Its own process group, so a wrapper's children end with it; signals
    // hil ignores (SIGPIPE) or handles are the program's own again.
    sigset_t defaults;
    sigemptyset(&defaults);
    for (int s : {SIGPIPE, SIGINT, SIGTERM, SIGHUP, SIGQUIT})
      sigaddset(&defaults, s);
    sigset_t none;
    sigemptyset(&none);
    posix_spawnattr_setflags(
        &attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setsigmask(&attr, &none);

    std::vector<std::string> env_strings;
    for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
      const std::string_view entry(*e);
      if (entry.rfind("HIL_", 0) == 0) continue;  // ours replace any inherited ones
      env_strings.emplace_back(entry);
    }
    for (const auto& [name, value] : options_.environment) {
      std::string key = "HIL_";
      for (char c : name)
        key += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      env_strings.push_back(key + "=" + value);
    }
    std::vector<char*> envp;
    for (auto& s : env_strings)
      envp.push_back(s.data());
    envp.push_back(nullptr);
    std::string sh = "/bin/sh", dash_c = "-c", command = options_.command;
    std::array<char*, 4> argv{sh.data(), dash_c.data(), command.data(), nullptr};

    const int rc = ::posix_spawn(&pid_, "/bin/sh", &actions, &attr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    ::close(in[0]);
    ::close(out[1]);
    ::close(err[1]);
    if (rc != 0) {
      pid_ = -1;
      spawn_error_ = std::string("cannot start the client: ") + std::strerror(rc);
      for (int fd : {in[1], out[0], err[0]})
        ::close(fd);
      record_spawn_error();
      return;
    }
    stdin_.assign(in[1]);
    stdout_.assign(out[0]);
    stderr_.assign(err[0]);
    stdin_.non_blocking(true);
    timeline_.add(ClientKind::start,
                  {{"command", options_.command}, {"pid", static_cast<long long>(pid_)}});
  }

  void record_spawn_error() { timeline_.add(ClientKind::notice, {{"text", spawn_error_}}); }

  void queue_write(std::string bytes) {
    writes_.push_back(std::move(bytes));
    if (writes_.size() == 1) write_next();
  }

  void write_next() {
    if (writes_.empty()) {
      if (closing_) close_stdin();
      return;
    }
    asio::async_write(stdin_, asio::buffer(writes_.front()),
                      [this, alive = std::weak_ptr<bool>(alive_)](std::error_code ec, std::size_t) {
                        if (const auto a = alive.lock(); !a || !*a) return;
                        if (ec) {
                          // The program closed its stdin or is gone; what it
                          // owes shows when it exits.
                          writes_.clear();
                          if (closing_) close_stdin();
                          return;
                        }
                        writes_.pop_front();
                        write_next();
                      });
  }

  void close_stdin() {
    if (stdin_.is_open()) {
      std::error_code ignored;
      stdin_.close(ignored);
    }
  }

  void read(Descriptor& from, std::array<char, 4096>& buffer, std::string& line,
            const char* stream) {
    from.async_read_some(asio::buffer(buffer),
                         [this, &from, &buffer, &line, stream, alive = std::weak_ptr<bool>(alive_)](
                             std::error_code ec, std::size_t n) {
                           if (const auto a = alive.lock(); !a || !*a) return;
                           for (std::size_t i = 0; i < n; ++i) {
                             if (buffer[i] == '\n' || line.size() >= kMaxLineBytes) {
                               on_line(line, stream);
                               line.clear();
                               if (buffer[i] == '\n') continue;
                             }
                             line += buffer[i];
                           }
                           if (ec) {
                             if (!line.empty()) on_line(line, stream);
                             line.clear();
                             ++closed_streams_;
                             reap();
                             return;
                           }
                           read(from, buffer, line, stream);
                         });
  }

  void on_line(std::string line, const char* stream) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (std::string_view(stream) == "stdout") {
      const ClientLine parsed = parse_client_line(line);
      if (parsed.kind == ClientLine::Kind::result) {
        on_result(parsed, line);
        return;
      }
      if (parsed.kind == ClientLine::Kind::event) {
        timeline_.add(parsed.record_kind, parsed.record_data);
        return;
      }
    }
    timeline_.add(ClientKind::output, {{"line", line}, {"stream", stream}});
  }

  void on_result(const ClientLine& result, const std::string& line) {
    if (!answered_ && on_first_result_) on_first_result_();
    answered_ = true;
    if (ignore_results_ > 0) {
      --ignore_results_;
      return;
    }
    if (pending_.empty()) {
      timeline_.add(ClientKind::output,
                    {{"line", line}, {"stream", "stdout"}, {"unexpected_result", true}});
      return;
    }
    Done done = std::move(pending_.front());
    pending_.pop_front();
    done(result.ok, result.reason);
  }

  // A program answers its first action within its startup timeout of
  // being handed it: time to start, counted from when there was something
  // to answer (a serial car's steps wait for the program to open the port).
  void arm_startup_timer() {
    startup_timer_ = executor_.call_after(options_.startup_timeout, [this] {
      startup_timer_ = 0;
      if (answered_ || pending_.empty()) return;
      fail_pending("no result from the client within " + link::format_ms(options_.startup_timeout) +
                   " of its first action");
    });
  }

  void fail_pending(const std::string& reason) {
    auto pending = std::move(pending_);
    pending_.clear();
    for (auto& done : pending)
      done(false, reason);
  }

  // Sees whether the program has exited; records it once its output is
  // read to the end (or the pipes stayed open past a grace period).
  void reap() {
    if (pid_ <= 0 || exit_) return;
    if (!reaped_) {
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r != pid_) return;
      reaped_ = true;
      reaped_at_ = executor_.now();
      nlohmann::json exit = nlohmann::json::object();
      if (WIFEXITED(status)) {
        exit["code"] = WEXITSTATUS(status);
      } else if (WIFSIGNALED(status)) {
        exit["signal"] = WTERMSIG(status);
      }
      if (killed_ != 0) exit["killed"] = true;
      status_ = std::move(exit);
    }
    if (closed_streams_ < 2 && executor_.now() - reaped_at_ < kPipeGrace) return;
    exit_ = status_;
    timeline_.add(ClientKind::exit, *exit_);
    fail_pending(exit_text(*exit_) + " before answering");
  }

  link::Executor& executor_;
  asio::io_context& io_;
  ExecOptions options_;
  RunTimeline& timeline_;
  Descriptor stdin_;
  Descriptor stdout_;
  Descriptor stderr_;
  std::array<char, 4096> out_buffer_{};
  std::array<char, 4096> err_buffer_{};
  std::string out_line_;
  std::string err_line_;
  std::deque<std::string> writes_;
  std::deque<Done> pending_;
  std::size_t ignore_results_ = 0;
  bool answered_ = false;
  bool closing_ = false;
  pid_t pid_ = -1;
  std::string spawn_error_;
  bool reaped_ = false;
  Time reaped_at_{0};
  int closed_streams_ = 0;
  int killed_ = 0;
  nlohmann::json status_;
  std::optional<nlohmann::json> exit_;
  link::Executor::TimerId startup_timer_ = 0;
  std::function<void()> on_first_result_;
  bool first_action_handed_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace

const std::vector<std::string>& placeholder_names() {
  static const std::vector<std::string> kNames = {"host",    "port",     "endpoint", "pty",
                                                  "actions", "scenario", "profile"};
  return kNames;
}

std::string shell_quote(std::string_view text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

std::string substitute_placeholders(std::string_view command, const Placeholders& values) {
  std::string out;
  std::size_t i = 0;
  while (i < command.size()) {
    const auto open = command.find('{', i);
    if (open == std::string_view::npos) break;
    const auto close = command.find('}', open);
    if (close == std::string_view::npos) break;
    const std::string_view word = command.substr(open + 1, close - open - 1);
    out.append(command.substr(i, open - i));
    if (!plain_word(word)) {  // "{}" or "{A}": not ours, kept as written
      out.append(command.substr(open, close - open + 1));
      i = close + 1;
      continue;
    }
    const std::string column = std::to_string(open + 1);
    const auto& names = placeholder_names();
    if (std::find(names.begin(), names.end(), word) == names.end()) {
      std::string known;
      for (const auto& n : names)
        known += (known.empty() ? "{" : ", {") + n + "}";
      throw std::invalid_argument("column " + column + ": unknown placeholder '{" +
                                  std::string(word) + "}' (known: " + known + ")");
    }
    const auto it = values.find(std::string(word));
    if (it == values.end())
      throw std::invalid_argument(
          "column " + column + ": '{" + std::string(word) + "}' has no value for this car" +
          (word == "pty"                      ? " (it talks TCP: use {host} and {port})"
           : word == "host" || word == "port" ? " (it talks over a serial port: use {pty})"
                                              : ""));
    out += shell_quote(it->second);
    i = close + 1;
  }
  out.append(command.substr(std::min(i, command.size())));
  return out;
}

ClientLine parse_client_line(std::string_view raw) {
  ClientLine line;
  std::string_view s = trim_view(raw);
  if (!s.empty() && s.front() == '[') {  // a time stamp such as "[   1.2340000]"
    const auto close = s.find(']');
    if (close != std::string_view::npos) s = trim_view(s.substr(close + 1));
  }
  const auto [word, rest] = first_word(s);
  const std::string w = lower(word);
  if (w == "ok") {
    line.kind = ClientLine::Kind::result;
    line.ok = true;
    return line;
  }
  if (w == "fail") {
    line.kind = ClientLine::Kind::result;
    line.ok = false;
    const auto colon = rest.find(": ");
    line.reason =
        std::string(colon == std::string_view::npos ? rest : trim_view(rest.substr(colon + 2)));
    if (line.reason.empty()) line.reason = "the client reported a failure";
    return line;
  }
  if (w == "event") {
    if (auto e = event_line(rest)) return *e;
  }
  return line;
}

std::unique_ptr<ScenarioClient> make_exec_client(link::TransportContext& context,
                                                 ExecOptions options, RunTimeline& timeline) {
  if (context.io == nullptr)
    throw std::logic_error("an external client needs the real-time driver");
  return std::make_unique<ExecSession>(context, std::move(options), timeline);
}

}  // namespace hil::harness
