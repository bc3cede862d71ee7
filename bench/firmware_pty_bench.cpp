// Real firmware on the emulated ATmega328P in real time, behind a pty at
// 9,600 baud as `hil mock arduino --elf` runs it: the time from writing a
// PING to reading the last byte of its answer, over many requests, and how
// much that time varies (the reply jitter). Load driver, not Google
// Benchmark:
//   firmware_pty_bench --elf FILE [--requests N] [--markdown FILE]
//                      [--max-jitter-ms X]
// The board runs in this process under the real-time driver (an
// io_context on its own thread); the client is this thread, with the pty
// opened raw at 9,600 baud, writing one request at a time. Jitter is the
// 99th percentile of the reply time less its 1st percentile; the worst
// and best are printed too. With --max-jitter-ms, exit 1 above it.

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>

#include "link/asio_executor.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"
#include "mocks/avr/avr_firmware.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/sketch.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/serial_support.hpp"

namespace {

namespace link = hil::link;
namespace mocks = hil::mocks;
using Clock = std::chrono::steady_clock;

struct Args {
  std::string elf;
  int requests = 300;
  std::string markdown;
  double max_jitter_ms = 0;
};

Args parse(int argc, char** argv) {
  Args args;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    const std::string value = argv[i + 1];
    if (flag == "--elf") {
      args.elf = value;
    } else if (flag == "--requests") {
      args.requests = std::max(10, std::atoi(value.c_str()));
    } else if (flag == "--markdown") {
      args.markdown = value;
    } else if (flag == "--max-jitter-ms") {
      args.max_jitter_ms = std::atof(value.c_str());
    } else {
      std::fprintf(stderr, "firmware_pty_bench: unknown option %s\n", flag.c_str());
      std::exit(2);
    }
  }
  if (args.elf.empty()) {
    std::fprintf(stderr,
                 "usage: firmware_pty_bench --elf FILE [--requests N] [--markdown FILE] "
                 "[--max-jitter-ms X]\n");
    std::exit(2);
  }
  return args;
}

// Reads until a frame's end marker; false after 2 s without one.
bool read_answer(int fd) {
  char buffer[128];
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 2000) <= 0) return false;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0) return false;
    if (std::string_view(buffer, static_cast<std::size_t>(n)).find('$') != std::string_view::npos)
      return true;
  }
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const auto at = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(at, v.size() - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse(argc, argv);
  const auto dir =
      std::filesystem::temp_directory_path() / ("hil-firmware-pty-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "board").string();

  asio::io_context io;
  link::AsioExecutor executor{io};
  link::TransportContext context{executor, &io};
  hil::sim::World world{hil::sim::WorldDef{}};
  hil::sim::Vehicle& vehicle = world.add_vehicle(hil::sim::arduino_robot());
  mocks::AvrConfig config;
  config.elf = args.elf;
  mocks::AvrFirmware firmware{world, vehicle, config};
  mocks::ServerOptions options;
  options.listen = link::PtyEndpoint{path, 9600, link::Duration{0}};
  mocks::MockServer server{context, firmware, std::move(options)};
  server.start();
  auto guard = asio::make_work_guard(io);
  std::thread driver([&io] { io.run(); });

  int fd = -1;
  try {
    fd = hil::mocks::test::open_serial_port(path, B9600);
  } catch (const std::system_error& e) {
    std::fprintf(stderr, "firmware_pty_bench: %s\n", e.what());
  }
  int status = 0;
  std::vector<double> ms;
  if (fd < 0) {
    status = 1;
  } else {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the reset and setup()
    for (int i = 0; i < args.requests; ++i) {
      char seq[3];
      std::snprintf(seq, sizeof seq, "%02X", (i + 1) & 0xFF);
      const std::string frame = hil::protocol::arduino::sketch_frame(seq, "PING", " ");
      const auto start = Clock::now();
      if (::write(fd, frame.data(), frame.size()) != static_cast<ssize_t>(frame.size()) ||
          !read_answer(fd)) {
        std::fprintf(stderr, "firmware_pty_bench: request %d got no answer\n", i + 1);
        status = 1;
        break;
      }
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      // A pause of a few ms, varied, so requests do not line up with the
      // board's slices the same way every time.
      std::this_thread::sleep_for(std::chrono::microseconds(3000 + 137 * (i % 11)));
    }
    ::close(fd);
  }
  asio::post(io, [&] { server.close(); });
  guard.reset();
  io.stop();
  driver.join();
  std::filesystem::remove_all(dir);
  if (ms.size() < 10) return 1;

  const double p1 = percentile(ms, 0.01);
  const double p50 = percentile(ms, 0.50);
  const double p99 = percentile(ms, 0.99);
  const double lo = *std::min_element(ms.begin(), ms.end());
  const double hi = *std::max_element(ms.begin(), ms.end());
  const double jitter = p99 - p1;
  if (std::getenv("HIL_BENCH_DUMP") != nullptr)
    for (std::size_t i = 0; i < ms.size(); ++i)
      std::printf("%zu %.2f\n", i, ms[i]);
  std::printf(
      "%zu PINGs on a pty at 9600 baud: reply time median %.2f ms, p1 %.2f, p99 %.2f, "
      "best %.2f, worst %.2f; jitter (p99 - p1) %.2f ms\n",
      ms.size(), p50, p1, p99, lo, hi, jitter);
  if (!args.markdown.empty()) {
    std::ofstream out(args.markdown);
    char line[256];
    std::snprintf(
        line, sizeof line,
        "| requests | median ms | p1 ms | p99 ms | best ms | worst ms | jitter (p99 - p1) ms |\n"
        "|---:|---:|---:|---:|---:|---:|---:|\n"
        "| %zu | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
        ms.size(), p50, p1, p99, lo, hi, jitter);
    out << line;
  }
  if (args.max_jitter_ms > 0 && jitter > args.max_jitter_ms) {
    std::printf("jitter %.2f ms is above %.2f ms: TOO MUCH\n", jitter, args.max_jitter_ms);
    status = 1;
  }
  return status;
}
