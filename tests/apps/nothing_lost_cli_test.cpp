// The wire log accounts for every byte: `hil proxy --log` between real TCP
// clients and a real TCP car, under load and when stopped mid-stream with
// SIGINT or SIGTERM. The bytes each link's log says were delivered equal
// the bytes the far side read from its socket, and the log is whole NDJSON
// to its last line.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/support/sanitizers.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

int listen_loopback(int& port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, 64) != 0)
    return -1;
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  port = ntohs(addr.sin_port);
  return fd;
}

bool send_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n <= 0) return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

/// The car: accepts connections and echoes every byte back, counting what
/// it read per connection, keyed by the first byte (each client sends one
/// letter of its own).
class EchoCar {
 public:
  EchoCar() {
    listen_fd_ = listen_loopback(port_);
    acceptor_ = std::thread([this] { accept_loop(); });
  }
  ~EchoCar() {
    stop_ = true;
    ::shutdown(listen_fd_, SHUT_RDWR);
    ::close(listen_fd_);
    acceptor_.join();
    for (auto& t : connections_)
      t.join();
  }
  int port() const { return port_; }
  std::map<char, std::uint64_t> received() {
    const std::lock_guard lock(mutex_);
    return received_;
  }

 private:
  void accept_loop() {
    while (!stop_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd < 0) continue;
      connections_.emplace_back([this, fd] { serve(fd); });
    }
  }
  void serve(int fd) {
    std::vector<char> buf(64 * 1024);
    std::uint64_t count = 0;
    char key = 0;
    for (;;) {
      const ssize_t n = ::read(fd, buf.data(), buf.size());
      if (n <= 0) break;
      if (key == 0) key = buf[0];
      count += static_cast<std::uint64_t>(n);
      {
        const std::lock_guard lock(mutex_);
        received_[key] = count;
      }
      if (!send_all(fd, buf.data(), static_cast<std::size_t>(n))) break;
    }
    ::close(fd);
  }

  int listen_fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread acceptor_;
  std::vector<std::thread> connections_;
  std::mutex mutex_;
  std::map<char, std::uint64_t> received_;
};

/// One client: writes `limit` bytes of its letter (or until the link
/// breaks when limit is 0) while another thread reads the echo; with a
/// limit it closes once the whole echo is back.
struct Client {
  char letter = 'A';
  std::uint64_t limit = 0;
  int fd = -1;
  std::atomic<std::uint64_t> written{0};
  std::atomic<std::uint64_t> read{0};
  std::thread writer;
  std::thread reader;

  void start(int port) {
    fd = connect_loopback(port);
    if (fd < 0) return;
    writer = std::thread([this] {
      const std::string chunk(16 * 1024, letter);
      while (limit == 0 || written < limit) {
        const std::size_t n =
            limit == 0
                ? chunk.size()
                : static_cast<std::size_t>(std::min<std::uint64_t>(chunk.size(), limit - written));
        if (!send_all(fd, chunk.data(), n)) return;
        written += n;
      }
    });
    reader = std::thread([this] {
      std::vector<char> buf(64 * 1024);
      // With a limit the client hangs up once its whole echo is back.
      while (limit == 0 || read < limit) {
        const ssize_t n = ::read(fd, buf.data(), buf.size());
        if (n <= 0) return;
        read += static_cast<std::uint64_t>(n);
      }
    });
  }
  void join() {
    if (writer.joinable()) writer.join();
    if (reader.joinable()) reader.join();
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

/// What one link's log says, by direction: bytes read from each side and
/// bytes delivered to the other.
struct LinkTotals {
  char letter = 0;
  std::uint64_t sent_to_car = 0;
  std::uint64_t delivered_to_car = 0;
  std::uint64_t sent_to_client = 0;
  std::uint64_t delivered_to_client = 0;
  bool closed = false;
};

/// Reads the log strictly: every line, the last one included, must be a
/// whole JSON object ending in a newline.
std::map<std::string, LinkTotals> read_log(const fs::path& path, std::uint64_t& lines) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n') << "the last line is cut";
  std::map<std::string, LinkTotals> links;
  std::size_t start = 0;
  lines = 0;
  while (start < text.size()) {
    const auto end = text.find('\n', start);
    if (end == std::string::npos) break;
    const auto r =
        nlohmann::json::parse(text.begin() + static_cast<std::ptrdiff_t>(start),
                              text.begin() + static_cast<std::ptrdiff_t>(end), nullptr, false);
    start = end + 1;
    ++lines;
    if (!r.is_object()) {
      ADD_FAILURE() << path << ":" << lines << ": not a JSON object";
      continue;
    }
    auto& link = links[r.at("link").get<std::string>()];
    const std::string event = r.at("event");
    if (event == "close") link.closed = true;
    if (event != "sent" && event != "delivered") continue;
    const auto bytes = r.at("bytes").get<std::uint64_t>();
    const std::string text_field = r.value("text", std::string());
    if (link.letter == 0 && !text_field.empty()) link.letter = text_field[0];
    const bool to_car = r.at("dir") == "to_car";
    (event == "sent" ? (to_car ? link.sent_to_car : link.sent_to_client)
                     : (to_car ? link.delivered_to_car : link.delivered_to_client)) += bytes;
  }
  return links;
}

/// Payload bytes of a pcap written by hil, by direction: [0] to the car
/// (from the client's address, 10.0.0.1), [1] to the client.
std::array<std::uint64_t, 2> pcap_payload(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::array<std::uint64_t, 2> totals{};
  EXPECT_GE(data.size(), 24u) << path;
  std::size_t at = 24;  // the file header
  const auto u8 = [&](std::size_t i) { return static_cast<std::uint8_t>(data[i]); };
  while (at + 16 <= data.size()) {
    std::uint32_t length = 0;
    std::memcpy(&length, data.data() + at + 8, 4);  // written in this machine's order
    at += 16;
    if (at + length > data.size()) {
      ADD_FAILURE() << path << ": the last packet is cut";
      break;
    }
    const std::size_t ip_header = (u8(at) & 0x0Fu) * 4u;
    const std::size_t tcp_header = (u8(at + ip_header + 12) >> 4u) * 4u;
    const bool from_client = u8(at + 12) == 10 && u8(at + 15) == 1;
    totals[from_client ? 0 : 1] += length - ip_header - tcp_header;
    at += length;
  }
  EXPECT_EQ(at, data.size()) << path << ": bytes after the last packet";
  return totals;
}

/// The pcap of link N: PATH for link 1, PATH-N for the others.
fs::path pcap_of(const fs::path& first, const std::string& link_id) {
  const std::string number = link_id.substr(4);
  if (number == "1") return first;
  return first.parent_path() / (first.stem().string() + "-" + number + first.extension().string());
}

/// `hil proxy` from the car's port to a free one, logging to `log`.
std::unique_ptr<HilProcess> start_proxy(int car_port, const fs::path& log) {
  const fs::path pcap = fs::path(log).replace_extension(".pcap");
  return std::make_unique<HilProcess>(
      std::vector<std::string>{"proxy", "--listen", "tcp://127.0.0.1:0", "--upstream",
                               "tcp://127.0.0.1:" + std::to_string(car_port), "--log", log.string(),
                               "--pcap", pcap.string(), "-q"});
}

fs::path scratch_log(const std::string& name) {
  const auto path = fs::temp_directory_path() /
                    ("hil-nothing-lost-" + std::to_string(::getpid()) + "-" + name + ".ndjson");
  fs::remove(path);
  return path;
}

/// Removes the wire log and every pcap beside it.
void remove_captures(const fs::path& log) {
  fs::remove(log);
  const fs::path pcap = fs::path(log).replace_extension(".pcap");
  fs::remove(pcap);
  for (int n = 2; n <= 16; ++n)
    fs::remove(pcap_of(pcap, "link" + std::to_string(n)));
}

/// Megabytes sent to the car (and echoed back) over all links together.
std::uint64_t megabytes_under_load() {
  // Override for a longer run: HIL_NOTHING_LOST_MB=500 ctest -R NothingLost
  if (const char* mb = std::getenv("HIL_NOTHING_LOST_MB")) return std::strtoull(mb, nullptr, 10);
  // Enough that all eight links carry traffic at once for a while, small
  // enough that the log and pcaps a CI run writes stay under ~100 MB.
  // A sanitizer build runs the same checks on a quarter of the bytes: the
  // proxy is several times slower there.
  return kSanitizerBuild ? 2 : 8;
}

/// The car, `hil proxy` in front of it logging to a scratch log, and the
/// clients writing through the proxy.
class NothingLost : public ::testing::Test {
 protected:
  /// Starts the proxy with its log named after `name`, then `count`
  /// clients, client i writing `limit(i)` bytes (0: until the link breaks).
  void start(const std::string& name, int count, const std::function<std::uint64_t(int)>& limit) {
    log_ = scratch_log(name);
    proxy_ = start_proxy(car_.port(), log_);
    ASSERT_GT(proxy_->pid(), 0) << proxy_->output();
    ASSERT_NO_FATAL_FAILURE(wait_for_port(*proxy_, port_, "clients connect to"));
    for (int i = 0; i < count; ++i) {
      auto c = std::make_unique<Client>();
      c->letter = static_cast<char>('A' + i);
      c->limit = limit(i);
      c->start(port_);
      ASSERT_GE(c->fd, 0);
      clients_.push_back(std::move(c));
    }
  }

  /// Reads the whole log (one link per client) into links_ and checks each
  /// link against the car, its client and its pcap: the bytes delivered to
  /// the car are those the car read, the bytes delivered to the client
  /// those the client read, the close is logged, and the pcap holds the
  /// same bytes. `more` checks what else holds for the way the run ended.
  void check_links(const std::function<void(const LinkTotals&, const Client&,
                                            std::uint64_t car_received)>& more) {
    links_ = read_log(log_, lines_);
    const auto car_received = car_.received();
    ASSERT_EQ(links_.size(), clients_.size());
    for (const auto& [id, l] : links_) {
      SCOPED_TRACE(id);
      const auto& c = *clients_.at(static_cast<std::size_t>(l.letter - 'A'));
      more(l, c, car_received.at(c.letter));
      EXPECT_EQ(l.delivered_to_car, car_received.at(c.letter));
      EXPECT_EQ(l.delivered_to_client, c.read);
      EXPECT_TRUE(l.closed) << "the close record is missing";
      const auto pcap = pcap_payload(pcap_of(fs::path(log_).replace_extension(".pcap"), id));
      EXPECT_EQ(pcap[0], l.delivered_to_car);
      EXPECT_EQ(pcap[1], l.delivered_to_client);
    }
  }

  /// Bytes delivered both ways over all links.
  std::uint64_t delivered() const {
    std::uint64_t total = 0;
    for (const auto& [id, l] : links_)
      total += l.delivered_to_car + l.delivered_to_client;
    return total;
  }

  EchoCar car_;
  fs::path log_;
  int port_ = -1;
  std::unique_ptr<HilProcess> proxy_;
  std::vector<std::unique_ptr<Client>> clients_;
  std::map<std::string, LinkTotals> links_;
  std::uint64_t lines_ = 0;
};

TEST_F(NothingLost, UnderLoadEveryByteOnEverySocketIsInTheLog) {
  constexpr int kClients = 8;
  const std::uint64_t total = megabytes_under_load() * 1000 * 1000;
  ASSERT_NO_FATAL_FAILURE(start("load", kClients, [&](int i) {
    return total / kClients + static_cast<std::uint64_t>(i) * 1009;  // sizes tell them apart
  }));
  for (auto& c : clients_)
    c->join();
  ASSERT_EQ(proxy_->interrupt(60s), 0) << proxy_->output();

  // Every byte each client wrote reached the car and came back.
  ASSERT_NO_FATAL_FAILURE(
      check_links([](const LinkTotals& l, const Client& c, std::uint64_t car_received) {
        EXPECT_EQ(c.written, c.limit);
        EXPECT_EQ(l.sent_to_car, c.written);
        EXPECT_EQ(l.sent_to_client, car_received);
        EXPECT_EQ(c.read, c.written);
      }));
  std::cout << "[ figures  ] " << delivered() << " bytes through " << kClients
            << " links, all in the log (" << lines_ << " records, " << fs::file_size(log_) / 1000000
            << " MB) and in the pcaps\n";
  remove_captures(log_);
}

class NothingLostOnSignal : public NothingLost, public ::testing::WithParamInterface<int> {};

TEST_P(NothingLostOnSignal, MidStreamLeavesAWholeLogThatMatchesTheSockets) {
  constexpr int kClients = 4;
  const int signal = GetParam();
  // No limit: each client writes until the proxy goes away.
  ASSERT_NO_FATAL_FAILURE(
      start(signal == SIGINT ? "sigint" : "sigterm", kClients, [](int) { return 0; }));
  // Stop it once every link carries traffic both ways.
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  for (;;) {
    bool all = true;
    for (auto& c : clients_)
      all = all && c->read > 1000000;
    if (all) break;
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "no traffic through the proxy";
    std::this_thread::sleep_for(10ms);
  }
  ::kill(proxy_->pid(), signal);
  ASSERT_EQ(proxy_->wait_exit(30s), 0) << proxy_->output();
  for (auto& c : clients_) {
    ::shutdown(c->fd, SHUT_RDWR);  // the writer may be blocked on a full socket
    c->join();
  }
  // The car's threads see the end too; give them their last reads.
  std::this_thread::sleep_for(200ms);

  ASSERT_NO_FATAL_FAILURE(check_links([](const LinkTotals& l, const Client& c, std::uint64_t) {
    EXPECT_LE(l.sent_to_car, c.written);  // the rest was still in the kernel
  }));
  std::cout << "[ figures  ] stopped by signal " << signal << " after " << delivered()
            << " bytes through " << kClients << " links; log whole (" << lines_ << " records)\n";
  remove_captures(log_);
}

INSTANTIATE_TEST_SUITE_P(SigintAndSigterm, NothingLostOnSignal, ::testing::Values(SIGINT, SIGTERM),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return info.param == SIGINT ? std::string("Sigint")
                                                       : std::string("Sigterm");
                         });

}  // namespace
}  // namespace hil::test
