// A half-close through hil's proxy over real sockets: a client sends its
// request and shuts down its sending side (shutdown(SHUT_WR)), a server
// reads to the end of the stream and only then answers and closes. The
// client gets the whole answer, as on a direct connection.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <asio/io_context.hpp>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <thread>

#include "link/asio_executor.hpp"
#include "link/capture/wire_log.hpp"
#include "link/proxy.hpp"
#include "link/transport.hpp"
#include "tests/harness/scratch_dir.hpp"
#include "tests/link/transports/real_time.hpp"

namespace hil::link {
namespace {

/// A blocking socket that gives up after 10 s, so no thread can hang.
int blocking_socket() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  timeval limit{};
  limit.tv_sec = 10;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
  return fd;
}

sockaddr_in loopback(std::uint16_t port) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return address;
}

bool send_all(int fd, const std::string& bytes) {
  for (std::size_t at = 0; at < bytes.size();) {
    const auto n = ::send(fd, bytes.data() + at, bytes.size() - at, MSG_NOSIGNAL);
    if (n <= 0) return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}

/// Reads until the peer's FIN; "error: ..." in `error` when the read
/// failed or timed out first.
std::string read_to_end(int fd, std::string& error) {
  std::string got;
  char buffer[65536];
  for (;;) {
    const auto n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n == 0) return got;
    if (n < 0) {
      if (errno == EINTR) continue;
      error = std::string("error: ") + std::strerror(errno);
      return got;
    }
    got.append(buffer, static_cast<std::size_t>(n));
  }
}

/// A server that reads the whole request, then writes `answer` and closes.
struct ReadThenAnswerServer {
  explicit ReadThenAnswerServer(std::string answer_bytes) : answer(std::move(answer_bytes)) {
    listen_fd = blocking_socket();
    const int on = 1;
    ::setsockopt(listen_fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    auto address = loopback(0);
    EXPECT_EQ(::bind(listen_fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    EXPECT_EQ(::listen(listen_fd, 4), 0);
    socklen_t length = sizeof address;
    ::getsockname(listen_fd, reinterpret_cast<sockaddr*>(&address), &length);
    port = ntohs(address.sin_port);
    thread = std::thread([this] {
      const int fd = ::accept(listen_fd, nullptr, nullptr);
      if (fd < 0) {
        error = "accept failed";
      } else {
        request = read_to_end(fd, error);
        if (error.empty() && !send_all(fd, answer)) error = "send failed";
        ::close(fd);
      }
      done = true;
    });
  }
  ~ReadThenAnswerServer() {
    ::shutdown(listen_fd, SHUT_RDWR);  // an accept still waiting returns
    if (thread.joinable()) thread.join();
    ::close(listen_fd);
  }

  std::string answer;
  int listen_fd = -1;
  std::uint16_t port = 0;
  std::thread thread;
  std::string request;
  std::string error;
  std::atomic<bool> done{false};
};

/// A client that sends `request`, shuts down its sending side and reads
/// the answer to the end.
struct HalfClosingClient {
  HalfClosingClient(std::uint16_t port, std::string request) {
    thread = std::thread([this, port, request = std::move(request)] {
      const int fd = blocking_socket();
      auto address = loopback(port);
      if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
        error = "connect failed";
      } else if (!send_all(fd, request)) {
        error = "send failed";
      } else {
        ::shutdown(fd, SHUT_WR);
        answer = read_to_end(fd, error);
      }
      ::close(fd);
      done = true;
    });
  }
  ~HalfClosingClient() {
    if (thread.joinable()) thread.join();
  }

  std::thread thread;
  std::string answer;
  std::string error;
  std::atomic<bool> done{false};
};

std::uint16_t port_of(const std::string& uri) {
  return static_cast<std::uint16_t>(std::stoi(uri.substr(uri.rfind(':') + 1)));
}

TEST(HalfCloseThroughTheProxy, TheClientGetsTheWholeAnswerAfterItsShutdown) {
  // Larger than the link's flow-control window and the socket buffers, so
  // the answer is still flowing long after the client's FIN went through.
  std::string answer(2u << 20, '\0');
  for (std::size_t i = 0; i < answer.size(); ++i)
    answer[i] = static_cast<char>('a' + i % 26);
  ReadThenAnswerServer car(answer);

  asio::io_context io;
  AsioExecutor executor(io);
  TransportContext context{executor, &io};
  ::hil::test::ScratchDir dir("hil-half-close");
  ProxyOptions options;
  options.listen = parse_endpoint("tcp://127.0.0.1:0");
  options.upstream = parse_endpoint("tcp://127.0.0.1:" + std::to_string(car.port));
  options.wire_log_path = (dir.path() / "wire.ndjson").string();
  Proxy proxy(context, options);
  proxy.start();

  const std::string request = "GET /status\n";
  HalfClosingClient client(port_of(proxy.address()), request);
  const bool finished = test::run_until(
      io, [&] { return client.done && car.done && proxy.open_links() == 0; }, seconds(20));
  ASSERT_TRUE(finished) << "client done " << client.done << ", car done " << car.done
                        << ", open links " << proxy.open_links();
  EXPECT_EQ(car.error, "");
  EXPECT_EQ(car.request, request) << "the car read the request to its end";
  EXPECT_EQ(client.error, "");
  EXPECT_EQ(client.answer.size(), answer.size());
  EXPECT_TRUE(client.answer == answer) << "the whole answer, in order";

  // The wire log shows the half-close, then the close once both ended.
  std::vector<std::string> ends;
  for (const auto& r : read_wire_log(options.wire_log_path)) {
    const std::string event = r["event"].get<std::string>();
    if (event == "half_close") ends.push_back("half_close " + r["dir"].get<std::string>());
    if (event == "close") ends.push_back("close " + r["reason"].get<std::string>());
  }
  const std::vector<std::string> expected = {"half_close to_car", "close client and car closed"};
  EXPECT_EQ(ends, expected);
  proxy.close();
}

}  // namespace
}  // namespace hil::link
