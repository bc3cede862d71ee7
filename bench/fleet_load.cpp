// A fleet in real time: `hil mock logi --count N` against N load clients,
// each holding a LOGI session (a command at a steady rate, every STAT and
// every FB read), measured side by side with a plain echo round trip on the
// same loopback in the same run. Prints a Markdown table.
//
// The mock runs as its own process (as users run it), so its CPU time and
// resident memory come from /proc. Memory per car is the mock's VmRSS minus
// that of a one-car mock started in the same run, over N - 1.
//
// Usage: fleet_load [--count N] [--seconds S] [--rate CMDS_PER_S] [--parked] [--hil PATH]
//                   [--sweep [N,N,...]] [--markdown FILE]
//                   [--max-ratio K --floor-ms F]   (a check: exit 1 on a regression)

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <asio/connect.hpp>
#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/steady_timer.hpp>
#include <asio/write.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "protocol/logi/codec.hpp"

extern char** environ;

namespace {

using Clock = std::chrono::steady_clock;
using asio::ip::tcp;
namespace logi = hil::protocol::logi;

constexpr double kStatPeriodMs = 500;
// The fleet targets for N = 1,000 on 2 cores (docs/performance.md).
constexpr double kTargetJitterP99Ms = 10;
constexpr double kTargetFeedbackP99Ms = 5;
constexpr double kTargetKibPerCar = 1024;
// One io_context thread serves every car: near a whole core it is saturated.
constexpr double kCpuSaturatedCores = 0.9;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(p / 100 * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

// ------------------------------------------------------------------ /proc

struct ProcSample {
  double cpu_s = 0;  // user + sys
  // Time the process's threads were runnable but waited for a core (the
  // machine's load as the mock felt it).
  double run_delay_s = 0;
  double rss_kib = 0;
  std::size_t fds = 0;
};

ProcSample sample(pid_t pid) {
  ProcSample s;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  // Fields after the command name (which may hold spaces), from field 3 on.
  const auto close = text.rfind(')');
  if (close != std::string::npos) {
    std::istringstream in(text.substr(close + 2));
    std::vector<std::string> f;
    std::string w;
    while (in >> w)
      f.push_back(w);
    if (f.size() > 12) {
      const double ticks = static_cast<double>(::sysconf(_SC_CLK_TCK));
      s.cpu_s = (std::stod(f[11]) + std::stod(f[12])) / ticks;  // utime, stime
    }
  }
  for (auto it = std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task");
       it != std::filesystem::directory_iterator(); ++it) {
    std::ifstream schedstat(it->path() / "schedstat");
    double on_cpu_ns = 0;
    double waiting_ns = 0;
    if (schedstat >> on_cpu_ns >> waiting_ns) s.run_delay_s += waiting_ns / 1e9;
  }
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) s.rss_kib = std::stod(line.substr(6));
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec))
    ++s.fds;
  return s;
}

std::string loadavg() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

std::string cpu_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

void raise_fd_limit() {
  rlimit l{};
  if (::getrlimit(RLIMIT_NOFILE, &l) == 0 && l.rlim_cur < l.rlim_max) {
    l.rlim_cur = l.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &l);
  }
}

rlim_t fd_limit() {
  rlimit l{};
  ::getrlimit(RLIMIT_NOFILE, &l);
  return l.rlim_cur;
}

// ------------------------------------------------------------------ the mock

// `hil mock logi --count N --port 0` as a child process; its output goes to
// a log file, read back when it fails.
class MockProcess {
 public:
  MockProcess(const std::string& hil, std::size_t count, const std::string& dir) {
    ports_file_ = dir + "/ports-" + std::to_string(count) + ".txt";
    log_file_ = dir + "/mock-" + std::to_string(count) + ".log";
    std::filesystem::remove(ports_file_);
    std::vector<std::string> args = {
        hil,  "mock",        "logi",   "--count", std::to_string(count), "--port",   "0",
        "-q", "--no-status", "--seed", "1",       "--ports-file",        ports_file_};
    std::vector<char*> argv;
    for (auto& a : args)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_file_.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    if (posix_spawn(&pid_, hil.c_str(), &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~MockProcess() { stop(); }
  MockProcess(const MockProcess&) = delete;
  MockProcess& operator=(const MockProcess&) = delete;

  pid_t pid() const { return pid_; }

  // The cars' ports once every car listens; empty when the mock exited.
  std::vector<unsigned> wait_for_ports(std::chrono::seconds limit) {
    const auto deadline = Clock::now() + limit;
    while (Clock::now() < deadline) {
      if (std::filesystem::exists(ports_file_)) {
        std::vector<unsigned> ports;
        std::ifstream in(ports_file_);
        std::string name, address;
        while (in >> name >> address)
          ports.push_back(
              static_cast<unsigned>(std::stoul(address.substr(address.rfind(':') + 1))));
        return ports;
      }
      int status = 0;
      if (pid_ <= 0 || ::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return {};
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return {};
  }

  std::string output() const {
    std::ifstream in(log_file_);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }

  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGINT);
    for (int i = 0; i < 500; ++i) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
  std::string ports_file_;
  std::string log_file_;
};

// ------------------------------------------------------------------ echo

// The physical baseline: a plain echo server on its own thread, blocking
// sockets, one connection.
class EchoServer {
 public:
  EchoServer() {
    acceptor_.open(tcp::v4());
    acceptor_.set_option(tcp::acceptor::reuse_address(true));
    acceptor_.bind(tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    acceptor_.listen();
    port_ = acceptor_.local_endpoint().port();
    thread_ = std::thread([this] {
      std::error_code ec;
      tcp::socket s(io_);
      acceptor_.accept(s, ec);
      if (ec) return;
      s.set_option(tcp::no_delay(true), ec);
      char buf[512];
      for (;;) {
        const std::size_t n = s.read_some(asio::buffer(buf), ec);
        if (ec) return;
        asio::write(s, asio::buffer(buf, n), ec);
        if (ec) return;
      }
    });
  }
  ~EchoServer() {
    std::error_code ec;
    acceptor_.close(ec);
    thread_.join();
  }
  unsigned short port() const { return port_; }

 private:
  asio::io_context io_;
  tcp::acceptor acceptor_{io_};
  unsigned short port_ = 0;
  std::thread thread_;
};

// ------------------------------------------------------------------ clients

struct Measurements {
  std::vector<double> stat_jitter_ms;  // |period - 500 ms|
  std::vector<double> feedback_ms;     // command written -> its FB read
  std::vector<double> echo_ms;         // echo round trip
  std::uint64_t stats = 0;
  std::uint64_t commands = 0;
  std::uint64_t feedback_missing = 0;  // a command whose FB had not come by the next one
  std::uint64_t rejected = 0;          // FB:...:0
  std::uint64_t bad_frames = 0;
  std::uint64_t connect_failures = 0;
  std::uint64_t disconnects = 0;
};

struct Window {
  Clock::time_point start;
  Clock::time_point end;
  bool contains(Clock::time_point t) const { return t >= start && t < end; }
};

// One car's client: MD:MAN at connect, then a command every 1/rate s at
// its own phase, alternately MV:CW and MV:CCW, so every car spins in place
// and its control loop runs all the time (the car's dearest state). Parked
// (--parked), the commands are SP:040 and SP:060 instead: the car stands,
// and what is left is the protocol, the link and the STAT.
class CarClient : public std::enable_shared_from_this<CarClient> {
 public:
  CarClient(asio::io_context& io, Measurements& m, const Window& w, bool parked)
      : socket_(io), timer_(io), m_(m), window_(w), parked_(parked) {}

  void start(unsigned port, Clock::time_point first_command, Clock::duration period) {
    next_command_ = first_command;
    period_ = period;
    auto self = shared_from_this();
    socket_.async_connect(
        tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)),
        [self](std::error_code ec) {
          if (ec) {
            ++self->m_.connect_failures;
            return;
          }
          std::error_code ignored;
          self->socket_.set_option(tcp::no_delay(true), ignored);
          self->send(logi::SetMode{logi::Mode::manual});
          self->read();
          self->schedule();
        });
  }
  void stop() {
    std::error_code ec;
    timer_.cancel();
    socket_.close(ec);
  }

 private:
  void schedule() {
    timer_.expires_at(next_command_);
    auto self = shared_from_this();
    timer_.async_wait([self](std::error_code ec) {
      if (ec || !self->socket_.is_open()) return;
      self->next_command_ += self->period_;
      const bool counted = self->window_.contains(Clock::now());
      if (self->pending_ && self->pending_counted_) ++self->m_.feedback_missing;
      if (counted) ++self->m_.commands;
      self->cw_ = !self->cw_;
      if (self->parked_)
        self->send(logi::SetSpeed{self->cw_ ? 40 : 60}, counted);
      else
        self->send(logi::Move{self->cw_ ? logi::Direction::cw : logi::Direction::ccw}, counted);
      self->schedule();
    });
  }

  void send(const logi::Message& message, bool counted = false) {
    pending_ = logi::command_of(message);
    pending_counted_ = counted;
    sent_at_ = Clock::now();
    out_.push_back(logi::encode_text(message));
    if (out_.size() == 1) write();
  }
  void write() {
    auto self = shared_from_this();
    asio::async_write(socket_, asio::buffer(out_.front()), [self](std::error_code ec, std::size_t) {
      if (ec) return;
      self->out_.pop_front();
      if (!self->out_.empty()) self->write();
    });
  }

  void read() {
    auto self = shared_from_this();
    socket_.async_read_some(asio::buffer(buf_), [self](std::error_code ec, std::size_t n) {
      if (ec) {
        if (ec != asio::error::operation_aborted) ++self->m_.disconnects;
        return;
      }
      self->on_bytes(n);
      self->read();
    });
  }

  void on_bytes(std::size_t n) {
    const auto now = Clock::now();
    items_.clear();
    decoder_.feed(hil::protocol::ByteView(reinterpret_cast<const std::uint8_t*>(buf_), n), items_);
    for (const auto& item : items_) {
      const auto* frame = std::get_if<hil::protocol::Frame<logi::Message>>(&item);
      if (frame == nullptr) {
        ++m_.bad_frames;
        continue;
      }
      if (std::holds_alternative<logi::Status>(frame->message)) {
        if (window_.contains(now)) {
          ++m_.stats;
          if (last_stat_ && window_.contains(*last_stat_))
            m_.stat_jitter_ms.push_back(std::abs(ms_between(*last_stat_, now) - kStatPeriodMs));
        }
        last_stat_ = now;
      } else if (const auto* fb = std::get_if<logi::Feedback>(&frame->message)) {
        if (pending_ && fb->command == *pending_) {
          if (pending_counted_) {
            m_.feedback_ms.push_back(ms_between(sent_at_, now));
            if (!fb->accepted) ++m_.rejected;
          }
          pending_.reset();
        }
      }
    }
  }

  tcp::socket socket_;
  asio::steady_timer timer_;
  Measurements& m_;
  const Window& window_;
  char buf_[1024];
  logi::Decoder decoder_;
  std::vector<logi::Item> items_;
  std::deque<std::string> out_;
  Clock::time_point next_command_;
  Clock::duration period_{};
  std::optional<logi::Command> pending_;
  bool pending_counted_ = false;
  Clock::time_point sent_at_;
  std::optional<Clock::time_point> last_stat_;
  bool parked_;
  bool cw_ = false;
};

// Pings the echo server every 5 ms from the same io_context as the cars'
// clients, one ping in flight, so both see the same machine.
class EchoClient : public std::enable_shared_from_this<EchoClient> {
 public:
  EchoClient(asio::io_context& io, Measurements& m, const Window& w)
      : socket_(io), timer_(io), m_(m), window_(w) {}
  void start(unsigned short port) {
    socket_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    socket_.set_option(tcp::no_delay(true));
    ping();
  }
  void stop() {
    std::error_code ec;
    timer_.cancel();
    socket_.close(ec);
  }

 private:
  void ping() {
    sent_at_ = Clock::now();
    auto self = shared_from_this();
    asio::async_write(socket_, asio::buffer(kPing, sizeof kPing - 1),
                      [self](std::error_code ec, std::size_t) {
                        if (!ec) self->read(0);
                      });
  }
  void read(std::size_t have) {
    auto self = shared_from_this();
    socket_.async_read_some(
        asio::buffer(buf_ + have, sizeof buf_ - have),
        [self, have](std::error_code ec, std::size_t n) {
          if (ec) return;
          if (have + n < sizeof kPing - 1) return self->read(have + n);
          const auto now = Clock::now();
          if (self->window_.contains(now))
            self->m_.echo_ms.push_back(ms_between(self->sent_at_, now));
          self->timer_.expires_at(self->sent_at_ + std::chrono::milliseconds(5));
          self->timer_.async_wait([self](std::error_code e) {
            if (!e) self->ping();
          });
        });
  }

  // As long as a STAT frame, so both paths carry the same bytes per write.
  static constexpr char kPing[] =
      "LOGI:STAT:SP=050,STA=000,RUN=0,MODE=MAN,MAN=CW,DIS=123,TRK=0000,DEV=0:00#";
  tcp::socket socket_;
  asio::steady_timer timer_;
  Measurements& m_;
  const Window& window_;
  char buf_[256];
  Clock::time_point sent_at_;
};

// ------------------------------------------------------------------ one run

struct Options {
  std::size_t count = 1000;
  double seconds = 30;
  double rate_hz = 1;
  bool parked = false;
  std::string hil = HIL_BINARY;
  std::vector<std::size_t> sweep;
  std::string markdown;
  std::optional<double> max_ratio;
  double floor_ms = 0;
};

struct Result {
  std::size_t count = 0;
  double seconds = 0;
  std::string failure;  // the mock did not start or the clients could not connect
  Measurements m;
  double stat_expected = 0;
  double cpu_cores = 0;        // mock CPU over the window, in cores
  double waited_fraction = 0;  // of the window, the mock runnable but not running
  double rss_kib = 0;
  double baseline_rss_kib = 0;
  std::size_t fds = 0;
  double driver_cpu_cores = 0;
  std::string load_before;
  std::string load_after;

  double jitter_p50() const { return percentile(m.stat_jitter_ms, 50); }
  double jitter_p99() const { return percentile(m.stat_jitter_ms, 99); }
  double jitter_max() const {
    return m.stat_jitter_ms.empty()
               ? 0
               : *std::max_element(m.stat_jitter_ms.begin(), m.stat_jitter_ms.end());
  }
  double fb_p50() const { return percentile(m.feedback_ms, 50); }
  double fb_p99() const { return percentile(m.feedback_ms, 99); }
  double echo_p50() const { return percentile(m.echo_ms, 50); }
  double echo_p99() const { return percentile(m.echo_ms, 99); }
  double kib_per_car() const {
    return count > 1 ? (rss_kib - baseline_rss_kib) / static_cast<double>(count - 1) : 0;
  }
  double stat_lost_fraction() const {
    return stat_expected > 0 ? std::max(0.0, 1 - static_cast<double>(m.stats) / stat_expected) : 0;
  }

  // What misses its target, in the order a user notices it; empty: none.
  std::vector<std::string> broken() const {
    std::vector<std::string> b;
    if (!failure.empty()) return {failure};
    if (cpu_cores >= kCpuSaturatedCores) b.push_back("CPU (the mock's thread is saturated)");
    if (jitter_p99() >= kTargetJitterP99Ms) b.push_back("STAT jitter");
    if (stat_lost_fraction() > 0.01) b.push_back("STATs missing");
    if (fb_p99() >= kTargetFeedbackP99Ms) b.push_back("feedback latency");
    if (m.feedback_missing > m.commands / 100) b.push_back("feedback missing");
    if (kib_per_car() >= kTargetKibPerCar) b.push_back("memory per car");
    if (m.disconnects > 0) b.push_back("connections dropped");
    return b;
  }
};

double driver_cpu_s() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
}

Result run_fleet(const Options& o, std::size_t count) {
  Result r;
  r.count = count;
  r.seconds = o.seconds;
  r.load_before = loadavg();
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("hil-fleet-" + std::to_string(::getpid())))
          .string();
  std::filesystem::create_directories(dir);

  // The empty baseline: a one-car mock, idle, in the same run.
  {
    MockProcess one(o.hil, 1, dir);
    if (one.wait_for_ports(std::chrono::seconds(30)).empty()) {
      r.failure = "the one-car mock did not start: " + one.output();
      return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    r.baseline_rss_kib = sample(one.pid()).rss_kib;
  }

  if (fd_limit() < count + 64) {
    r.failure = "fds (this driver may open " + std::to_string(fd_limit()) + " files, needs " +
                std::to_string(count + 64) + ")";
    return r;
  }
  MockProcess mock(o.hil, count, dir);
  const auto ports = mock.wait_for_ports(std::chrono::seconds(60 + count / 20));
  if (ports.size() != count) {
    std::string out = mock.output();
    while (!out.empty() && out.back() == '\n')
      out.pop_back();
    r.failure = "the mock did not start (" + out + ")";
    return r;
  }

  EchoServer echo;
  asio::io_context io;
  Measurements& m = r.m;
  Window window;
  const auto connect_at = Clock::now();
  // Connections, then 2 s for every car's first STAT and the mode change,
  // then the measured window.
  window.start =
      connect_at + std::chrono::seconds(2) + std::chrono::milliseconds(static_cast<long>(count));
  window.end = window.start + std::chrono::milliseconds(static_cast<long>(o.seconds * 1000));
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate_hz));
  std::vector<std::shared_ptr<CarClient>> clients;
  for (std::size_t i = 0; i < count; ++i) {
    auto c = std::make_shared<CarClient>(io, m, window, o.parked);
    // Spread evenly: car i's commands come at i/N of the period.
    const auto phase = period * static_cast<long>(i) / static_cast<long>(count);
    c->start(ports[i], window.start - period + phase, period);
    clients.push_back(c);
  }
  auto echo_client = std::make_shared<EchoClient>(io, m, window);
  echo_client->start(echo.port());

  ProcSample before;
  double driver_before = 0;
  asio::steady_timer at_start(io);
  at_start.expires_at(window.start);
  at_start.async_wait([&](std::error_code) {
    before = sample(mock.pid());
    driver_before = driver_cpu_s();
  });
  asio::steady_timer at_end(io);
  at_end.expires_at(window.end);
  at_end.async_wait([&](std::error_code) {
    const ProcSample after = sample(mock.pid());
    const double s = ms_between(window.start, window.end) / 1000;
    r.cpu_cores = (after.cpu_s - before.cpu_s) / s;
    r.waited_fraction = (after.run_delay_s - before.run_delay_s) / s;
    r.driver_cpu_cores = (driver_cpu_s() - driver_before) / s;
    r.rss_kib = after.rss_kib;
    r.fds = after.fds;
    for (auto& c : clients)
      c->stop();
    echo_client->stop();
  });
  io.run();
  r.stat_expected = static_cast<double>(count) * o.seconds * 1000 / kStatPeriodMs;
  r.load_after = loadavg();
  mock.stop();
  std::filesystem::remove_all(dir);
  return r;
}

// ------------------------------------------------------------------ output

std::string fixed(double v, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

std::string table(const std::vector<Result>& results, double rate_hz) {
  std::ostringstream out;
  out << "| cars | STAT jitter p50 / p99 / max | STATs read | feedback p50 / p99 | echo p50 / p99 "
         "| mock CPU (cores) | mock waited for a core | CPU per car | RSS per car | mock fds | "
         "loadavg (before -> after) "
         "| breaks |\n"
      << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n";
  for (const auto& r : results) {
    if (!r.failure.empty()) {
      out << "| " << r.count << " | | | | | | | | | | " << r.load_before << " | " << r.failure
          << " |\n";
      continue;
    }
    const auto b = r.broken();
    std::string breaks;
    for (const auto& x : b)
      breaks += (breaks.empty() ? "" : ", ") + x;
    out << "| " << r.count << " | " << fixed(r.jitter_p50(), 2) << " / " << fixed(r.jitter_p99(), 2)
        << " / " << fixed(r.jitter_max(), 1) << " ms | " << r.m.stats << " of "
        << fixed(r.stat_expected, 0) << " | " << fixed(r.fb_p50(), 2) << " / "
        << fixed(r.fb_p99(), 2) << " ms | " << fixed(r.echo_p50(), 3) << " / "
        << fixed(r.echo_p99(), 3) << " ms | " << fixed(r.cpu_cores, 2) << " | "
        << fixed(r.waited_fraction * 100, 0) << " % | "
        << fixed(r.cpu_cores / static_cast<double>(r.count) * 1e6, 0) << " µs/s | "
        << fixed(r.kib_per_car(), 0) << " KiB | " << r.fds << " | " << r.load_before << " -> "
        << r.load_after << " | " << (breaks.empty() ? "none" : breaks) << " |\n";
  }
  (void)rate_hz;
  return out.str();
}

std::string details(const Result& r, const Options& o) {
  std::ostringstream out;
  out << r.count << " cars, " << o.seconds << " s measured, " << o.rate_hz
      << " command(s) per car per second (" << (o.parked ? "SP, parked" : "MV, spinning")
      << "): " << r.m.commands << " commands, " << r.m.feedback_ms.size() << " answered ("
      << r.m.rejected << " refused), " << r.m.feedback_missing << " without FB, " << r.m.bad_frames
      << " bad frames, " << r.m.connect_failures << " failed connects, " << r.m.disconnects
      << " dropped; " << r.m.echo_ms.size() << " echo round trips; load driver "
      << fixed(r.driver_cpu_cores, 2) << " cores; mock RSS " << fixed(r.rss_kib / 1024, 1)
      << " MiB (one-car mock " << fixed(r.baseline_rss_kib / 1024, 1) << " MiB)\n";
  return out.str();
}

std::vector<std::size_t> parse_list(const std::string& text) {
  std::vector<std::size_t> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) v.push_back(std::stoul(item));
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "fleet_load: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--count") {
      o.count = std::stoul(value());
    } else if (a == "--seconds") {
      o.seconds = std::stod(value());
    } else if (a == "--rate") {
      o.rate_hz = std::stod(value());
    } else if (a == "--parked") {
      o.parked = true;
    } else if (a == "--hil") {
      o.hil = value();
    } else if (a == "--sweep") {
      o.sweep = {250, 500, 1000, 1500, 2000, 3000, 4000, 6000};
      if (i + 1 < argc && argv[i + 1][0] != '-') o.sweep = parse_list(argv[++i]);
    } else if (a == "--markdown") {
      o.markdown = value();
    } else if (a == "--max-ratio") {
      o.max_ratio = std::stod(value());
    } else if (a == "--floor-ms") {
      o.floor_ms = std::stod(value());
    } else {
      std::cerr << "usage: fleet_load [--count N] [--seconds S] [--rate CMDS_PER_S] [--parked] "
                   "[--hil PATH] "
                   "[--sweep [N,N,...]] [--markdown FILE] [--max-ratio K --floor-ms F]\n";
      return 2;
    }
  }
  if (o.count < 2 || o.seconds <= 0 || o.rate_hz <= 0 || o.rate_hz > 50) {
    std::cerr << "fleet_load: --count >= 2, --seconds > 0, --rate in (0, 50]\n";
    return 2;
  }
  raise_fd_limit();
  std::signal(SIGPIPE, SIG_IGN);

  std::ostringstream report;
  report << "Measured on " << std::thread::hardware_concurrency() << " core(s), " << cpu_name()
         << ", with `fleet_load";
  for (int i = 1; i < argc; ++i)
    report << ' ' << argv[i];
  report << "`:\n\n";

  std::vector<Result> results;
  int exit_code = 0;
  if (o.sweep.empty()) {
    results.push_back(run_fleet(o, o.count));
    std::cerr << details(results.back(), o);
    report << table(results, o.rate_hz);
    const Result& r = results.back();
    if (!r.failure.empty()) {
      report << "\nThe run failed: " << r.failure << "\n";
      exit_code = 1;
    } else if (o.max_ratio) {
      // The check: STAT jitter and feedback latency against the echo round
      // trip measured on the same loopback, in the same run.
      const double limit = *o.max_ratio * r.echo_p99() + o.floor_ms;
      report << "\nLimit: " << fixed(*o.max_ratio, 0) << " x echo p99 (" << fixed(r.echo_p99(), 3)
             << " ms) + " << fixed(o.floor_ms, 0) << " ms = " << fixed(limit, 2)
             << " ms for STAT jitter p99 and feedback p99.\n";
      if (r.jitter_p99() > limit || r.fb_p99() > limit || r.stat_lost_fraction() > 0.01 ||
          r.m.feedback_ms.empty() || r.m.disconnects > 0) {
        report << "REGRESSION: STAT jitter p99 " << fixed(r.jitter_p99(), 2) << " ms, feedback p99 "
               << fixed(r.fb_p99(), 2) << " ms, " << fixed(r.stat_lost_fraction() * 100, 1)
               << " % STATs missing, " << r.m.disconnects << " dropped\n";
        exit_code = 1;
      }
    }
  } else {
    // A shared machine can break one size by a blip of load: the sweep goes
    // on past a broken target until the mock's thread saturates (larger
    // fleets only fall further behind) or a mock cannot start, and names
    // the first size at which each target broke.
    std::vector<std::pair<std::string, std::size_t>> first_breaks;
    for (const auto n : o.sweep) {
      std::cerr << "fleet_load: " << n << " cars ..." << std::endl;
      results.push_back(run_fleet(o, n));
      std::cerr << details(results.back(), o);
      const auto b = results.back().broken();
      for (const auto& what : b)
        if (std::none_of(first_breaks.begin(), first_breaks.end(),
                         [&](const auto& f) { return f.first == what; }))
          first_breaks.emplace_back(what, n);
      if (!results.back().failure.empty() || results.back().cpu_cores >= kCpuSaturatedCores) break;
    }
    report << table(results, o.rate_hz) << '\n';
    if (first_breaks.empty()) {
      report << "No target broke up to " << o.sweep.back() << " cars.\n";
    } else {
      report << "First to break: " << first_breaks.front().first << " at "
             << first_breaks.front().second << " cars";
      for (std::size_t k = 1; k < first_breaks.size(); ++k)
        report << (k == 1 ? "; then " : ", ") << first_breaks[k].first << " at "
               << first_breaks[k].second;
      report << ".\n";
    }
  }
  std::cout << report.str();
  if (!o.markdown.empty()) std::ofstream(o.markdown, std::ios::app) << report.str() << '\n';
  return exit_code;
}
