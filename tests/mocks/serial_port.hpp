#pragma once
// A serial program's end of a mock's pty: the port opened the way such a
// program opens it, every byte that arrives handed on as it comes.

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>

#include "protocol/common/bytes.hpp"
#include "tests/mocks/serial_support.hpp"

namespace hil::mocks::test {

class SerialPort {
 public:
  /// Opens `path` in raw mode at `speed` (B9600, ...); each read's bytes go
  /// to `on_bytes` while the port lives.
  SerialPort(asio::io_context& io, const std::string& path, speed_t speed,
             std::function<void(protocol::ByteView)> on_bytes)
      : port_(io), on_bytes_(std::move(on_bytes)) {
    port_.assign(open_serial_port(path, speed));
    read();
  }
  ~SerialPort() { *alive_ = false; }
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Writes all of `bytes` at once; a short write is a test failure.
  void write(protocol::ByteView bytes) {
    const auto n = ::write(port_.native_handle(), bytes.data(), bytes.size());
    ASSERT_EQ(n, static_cast<ssize_t>(bytes.size())) << "write to the port failed";
  }

 private:
  void read() {
    port_.async_read_some(asio::buffer(buffer_),
                          [this, alive = alive_](std::error_code ec, std::size_t n) {
                            if (!*alive) return;
                            on_bytes_(protocol::ByteView(buffer_.data(), n));
                            if (!ec) read();
                          });
  }

  asio::posix::stream_descriptor port_;
  std::function<void(protocol::ByteView)> on_bytes_;
  std::array<std::uint8_t, 512> buffer_{};
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::mocks::test
