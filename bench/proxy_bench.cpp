// Proxy cost on loopback, measured side by side with the plain path in the
// same run: round-trip latency of small frames (echo car, direct and through
// `hil::link::Proxy`) and one-way throughput of a bulk stream (sink car,
// direct and through the proxy). The proxy and the car each run on their own
// io_context thread; the client is this thread with blocking sockets.
//
// Usage: proxy_bench [--frames N] [--mib M] [--protocol raw|logi] [--markdown FILE]

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <asio/io_context.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "link/asio_executor.hpp"
#include "link/proxy.hpp"
#include "link/transport.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace hil::link;

// What a server started on a ServingThread listens on, and what keeps it
// serving.
struct Served {
  std::string address;
  std::shared_ptr<void> server;
};

// An io_context run on a thread of its own until the object is gone:
// `serve` starts a server there, and it serves until then.
class ServingThread {
 public:
  explicit ServingThread(const std::function<Served(TransportContext&)>& serve) {
    std::promise<std::string> address;
    thread_ = std::thread([this, &serve, &address] {
      AsioExecutor executor(io_);
      TransportContext ctx{executor, &io_};
      const Served served = serve(ctx);
      address.set_value(served.address);
      auto guard = asio::make_work_guard(io_);
      io_.run();
    });
    address_ = address.get_future().get();
  }
  ~ServingThread() {
    io_.stop();
    thread_.join();
  }
  const std::string& address() const { return address_; }

 private:
  asio::io_context io_;
  std::thread thread_;
  std::string address_;
};

// A car on its own thread: echoes every byte, or counts and discards them.
class Car {
 public:
  explicit Car(bool echo)
      : echo_(echo), thread_([this](TransportContext& ctx) { return serve(ctx); }) {}
  const std::string& address() const { return thread_.address(); }
  std::uint64_t received() const { return received_; }

 private:
  // The accepted connections, then the listener: both live on the car's thread.
  struct Server {
    std::vector<BytePipePtr> pipes;
    std::unique_ptr<Listener> listener;
  };

  Served serve(TransportContext& ctx) {
    auto server = std::make_shared<Server>();
    server->listener = listen(ctx, parse_endpoint("tcp://127.0.0.1:0"));
    server->listener->start([this, pipes = &server->pipes](BytePipePtr p) {
      pipes->push_back(p);
      std::weak_ptr<BytePipe> weak = p;
      p->start({[this, weak](ByteView b) {
                  received_ += b.size();
                  if (echo_)
                    if (auto self = weak.lock()) self->write(b);
                },
                [](std::error_code) {}});
    });
    return Served{server->listener->address(), server};
  }

  bool echo_;
  std::atomic<std::uint64_t> received_{0};
  ServingThread thread_;  // last: it serves with the members above
};

// The proxy on its own thread.
class ProxyThread {
 public:
  ProxyThread(const std::string& upstream, const std::string& protocol)
      : thread_([&](TransportContext& ctx) {
          ProxyOptions o;
          o.listen = parse_endpoint("tcp://127.0.0.1:0");
          o.upstream = parse_endpoint(upstream);
          o.protocol = protocol_adapter(protocol);
          auto proxy = std::make_shared<Proxy>(ctx, o);
          proxy->start();
          return Served{proxy->address(), proxy};
        }) {}
  const std::string& address() const { return thread_.address(); }

 private:
  ServingThread thread_;
};

int connect_to(const std::string& uri) {
  const auto e = std::get<TcpEndpoint>(parse_endpoint(uri));
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(e.port);
  ::inet_pton(AF_INET, e.host.c_str(), &a.sin_addr);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    std::perror("connect");
    std::exit(2);
  }
  int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

struct Latency {
  double p50_us, p99_us;
};

Latency round_trips(const std::string& uri, int frames) {
  const int fd = connect_to(uri);
  const std::string frame = "LOGI:SP:050:D7#";
  std::vector<double> us;
  us.reserve(static_cast<std::size_t>(frames));
  char buf[64];
  for (int i = 0; i < frames + 200; ++i) {
    const auto t0 = Clock::now();
    if (::write(fd, frame.data(), frame.size()) != static_cast<ssize_t>(frame.size())) std::exit(3);
    std::size_t got = 0;
    while (got < frame.size()) {
      const ssize_t n = ::read(fd, buf + got, sizeof buf - got);
      if (n <= 0) std::exit(4);
      got += static_cast<std::size_t>(n);
    }
    if (i >= 200)
      us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  }
  ::close(fd);
  std::sort(us.begin(), us.end());
  return {us[us.size() / 2], us[us.size() * 99 / 100]};
}

double throughput_mb_s(const std::string& uri, const Car& sink, std::size_t mib) {
  const int fd = connect_to(uri);
  // Whole STAT frames (a frame-aware proxy holds an unfinished frame back).
  const std::string frame =
      "LOGI:STAT:SP:050,STA:002,RUN:1,MODE:AUTO,MAN:STOP,DIS:123,TRK:0110,DEV:-3,OBS:0,RPM:120:121:"
      "-119:0:3B#";
  std::vector<char> chunk;
  while (chunk.size() + frame.size() <= 64 * 1024)
    chunk.insert(chunk.end(), frame.begin(), frame.end());
  const std::uint64_t start_count = sink.received();
  const std::uint64_t total = (mib * 1024 * 1024 / chunk.size() + 1) * chunk.size();
  const auto t0 = Clock::now();
  for (std::uint64_t sent = 0; sent < total;) {
    std::size_t off = 0;
    while (off < chunk.size()) {
      const ssize_t n = ::write(fd, chunk.data() + off, chunk.size() - off);
      if (n <= 0) std::exit(5);
      off += static_cast<std::size_t>(n);
    }
    sent += chunk.size();
  }
  const auto deadline = Clock::now() + std::chrono::seconds(120);
  while (sink.received() - start_count < total) {
    if (Clock::now() > deadline) {
      std::fprintf(stderr, "proxy_bench: only %llu of %llu bytes arrived\n",
                   static_cast<unsigned long long>(sink.received() - start_count),
                   static_cast<unsigned long long>(total));
      std::exit(6);
    }
    std::this_thread::yield();
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  ::close(fd);
  return static_cast<double>(total) / seconds / 1e6;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 20000;
  std::size_t mib = 256;
  std::string protocol = "raw";
  std::string markdown;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--frames")
      frames = std::stoi(value());
    else if (a == "--mib")
      mib = std::stoul(value());
    else if (a == "--protocol")
      protocol = value();
    else if (a == "--markdown")
      markdown = value();
    else {
      std::fprintf(
          stderr,
          "usage: proxy_bench [--frames N] [--mib M] [--protocol raw|logi] [--markdown FILE]\n");
      return 2;
    }
  }
  Car echo(true);
  Car sink(false);
  ProxyThread to_echo(echo.address(), protocol);
  ProxyThread to_sink(sink.address(), protocol);

  const Latency direct = round_trips(echo.address(), frames);
  const Latency proxied = round_trips(to_echo.address(), frames);
  const double direct_mb = throughput_mb_s(sink.address(), sink, mib);
  const double proxied_mb = throughput_mb_s(to_sink.address(), sink, mib);
  // A round trip crosses the proxy twice.
  const double added_per_frame_us = (proxied.p50_us - direct.p50_us) / 2;

  char table[1024];
  std::snprintf(table, sizeof table,
                "| path (protocol %s) | round trip p50 | round trip p99 | one-way throughput |\n"
                "|---|---:|---:|---:|\n"
                "| plain TCP | %.1f µs | %.1f µs | %.0f MB/s |\n"
                "| through the proxy | %.1f µs | %.1f µs | %.0f MB/s |\n\n"
                "Added median latency per frame per crossing: %.1f µs (target < 50 µs). "
                "Throughput through one proxied connection: %.0f MB/s (target >= 100 MB/s).\n",
                protocol.c_str(), direct.p50_us, direct.p99_us, direct_mb, proxied.p50_us,
                proxied.p99_us, proxied_mb, added_per_frame_us, proxied_mb);
  std::fputs(table, stdout);
  if (!markdown.empty()) std::ofstream(markdown, std::ios::app) << table << '\n';
  return 0;
}
