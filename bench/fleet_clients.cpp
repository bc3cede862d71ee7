// The fleet load driver's clients: a LOGI session per car, and the echo
// round trip beside it.

#include "bench/fleet_clients.hpp"

#include <asio/connect.hpp>
#include <asio/write.hpp>
#include <cmath>

namespace hil::bench::fleet {

using asio::ip::tcp;

EchoServer::EchoServer() {
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

EchoServer::~EchoServer() {
  std::error_code ec;
  acceptor_.close(ec);
  thread_.join();
}

void CarClient::start(unsigned port, Clock::time_point first_command, Clock::duration period) {
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

void CarClient::schedule() {
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

void CarClient::send(const logi::Message& message, bool counted) {
  pending_ = logi::command_of(message);
  pending_counted_ = counted;
  sent_at_ = Clock::now();
  out_.push_back(logi::encode_text(message));
  if (out_.size() == 1) write();
}

void CarClient::write() {
  auto self = shared_from_this();
  asio::async_write(socket_, asio::buffer(out_.front()), [self](std::error_code ec, std::size_t) {
    if (ec) return;
    self->out_.pop_front();
    if (!self->out_.empty()) self->write();
  });
}

void CarClient::read() {
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

void CarClient::on_bytes(std::size_t n) {
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

void EchoClient::start(unsigned short port) {
  socket_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  socket_.set_option(tcp::no_delay(true));
  ping();
}

void EchoClient::ping() {
  sent_at_ = Clock::now();
  auto self = shared_from_this();
  asio::async_write(socket_, asio::buffer(kPing, sizeof kPing - 1),
                    [self](std::error_code ec, std::size_t) {
                      if (!ec) self->read(0);
                    });
}

void EchoClient::read(std::size_t have) {
  auto self = shared_from_this();
  socket_.async_read_some(asio::buffer(buf_ + have, sizeof buf_ - have),
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

}  // namespace hil::bench::fleet
