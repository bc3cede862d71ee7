#pragma once
// A client connected to a mock firmware under the virtual-time driver: the
// firmware behind a MockServer on mem://, the client end of the connection
// collecting what the car sends. Tests drive the virtual clock.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <variant>
#include <vector>

#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "protocol/common/decode.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"

namespace hil::mocks::test {

/// The instant `ms` milliseconds after the start of virtual time.
inline link::Time at_ms(std::int64_t ms) {
  return link::Time(link::milliseconds(ms));
}

/// Whole milliseconds since the start of virtual time.
inline std::int64_t ms_of(link::Time t) {
  return std::chrono::duration_cast<link::milliseconds>(t).count();
}

/// The client's end of one connection.
struct ClientEnd {
  link::BytePipePtr pipe;
  protocol::Bytes received;
  std::optional<std::error_code> closed;

  void write(std::string_view text) {
    pipe->write(
        protocol::ByteView(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  }
  void write(protocol::ByteView bytes) { pipe->write(bytes); }
  std::string text() const { return std::string(received.begin(), received.end()); }
  /// Returns what arrived so far and forgets it.
  protocol::Bytes take() { return std::exchange(received, {}); }
  std::string take_text() {
    auto b = take();
    return std::string(b.begin(), b.end());
  }
};

/// Feeds `bytes` to `decoder` and hands each frame that comes out to
/// `on_frame`; an error is a test failure, `complaint` followed by its detail.
template <class Message, class Decoder, class OnFrame>
void decode_frames(Decoder& decoder, protocol::ByteView bytes, std::string_view complaint,
                   OnFrame&& on_frame) {
  if (bytes.empty()) return;
  std::vector<protocol::DecodeItem<Message>> items;
  decoder.feed(bytes, items);
  for (auto& item : items) {
    if (const auto* e = std::get_if<protocol::DecodeError>(&item)) {
      ADD_FAILURE() << complaint << e->detail;
      continue;
    }
    on_frame(std::get<protocol::Frame<Message>>(item));
  }
}

/// Connects a client to `server` at its address; once connected the pipe is
/// stored in `pipe` and started with `handlers`, and a refusal goes to
/// `refused` (when given).
inline void connect_client(link::TransportContext& context, const MockServer& server,
                           link::BytePipePtr& pipe, link::BytePipe::Handlers handlers,
                           std::function<void(std::error_code)> refused = {}) {
  link::connect(context, link::parse_endpoint(server.address()),
                [&pipe, handlers = std::move(handlers), refused = std::move(refused)](
                    std::error_code ec, link::BytePipePtr connected) mutable {
                  if (ec) {
                    if (refused) refused(ec);
                    return;
                  }
                  pipe = connected;
                  pipe->start(std::move(handlers));
                });
}

/// A world with one vehicle, a firmware made by `make(world, vehicle)`, and
/// a MockServer listening on mem://car under a VirtualExecutor.
template <class FirmwareT>
class VirtualCar {
 public:
  template <class Make>
  VirtualCar(sim::VehicleDef vehicle, Make make, ServerOptions options = {},
             sim::WorldDef world = {})
      : world_(std::move(world)), vehicle_(world_.add_vehicle(std::move(vehicle))) {
    firmware_ = make(world_, vehicle_);
    options.listen = link::MemEndpoint{"car"};
    server_ = std::make_unique<MockServer>(context_, *firmware_, std::move(options));
    server_->start();
  }

  /// Connects a client; the connection is up when this returns.
  std::shared_ptr<ClientEnd> connect() {
    auto end = std::make_shared<ClientEnd>();
    link::connect(context_, link::MemEndpoint{"car"},
                  [end](std::error_code ec, link::BytePipePtr pipe) {
                    if (ec) {
                      end->closed = ec;
                      return;
                    }
                    end->pipe = pipe;
                    std::weak_ptr<ClientEnd> weak = end;
                    pipe->start({[weak](protocol::ByteView b) {
                                   if (auto e = weak.lock())
                                     e->received.insert(e->received.end(), b.begin(), b.end());
                                 },
                                 [weak](std::error_code why) {
                                   if (auto e = weak.lock()) e->closed = why;
                                 }});
                  });
    run_for(link::milliseconds(1));
    return end;
  }

  void run_for(link::Duration d) { executor_.run_for(d); }
  void run_until(link::Time t) { executor_.run_until(t); }
  /// Runs the events up to `t` one at a time, calling `look()` before each
  /// and at the end: a client sees what arrives at the time it arrives.
  template <class Look>
  void run_until_each(link::Time t, Look&& look) {
    for (;;) {
      look();
      const auto due = executor_.next_due();
      if (!due || *due > t) break;
      executor_.run_one();
    }
    executor_.run_until(t);
    look();
  }
  link::Time now() const { return executor_.now(); }

  link::VirtualExecutor& executor() { return executor_; }
  /// For a client session of its own to connect to mem://car.
  link::TransportContext& context() { return context_; }
  sim::World& world() { return world_; }
  sim::Vehicle& vehicle() { return vehicle_; }
  FirmwareT& firmware() { return *firmware_; }
  MockServer& server() { return *server_; }

 private:
  link::VirtualExecutor executor_;
  link::TransportContext context_{executor_};
  sim::World world_;
  sim::Vehicle& vehicle_;
  std::unique_ptr<FirmwareT> firmware_;
  std::unique_ptr<MockServer> server_;
};

}  // namespace hil::mocks::test
