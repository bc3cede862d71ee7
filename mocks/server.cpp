#include "mocks/server.hpp"

#include <array>
#include <optional>
#include <string>
#include <system_error>
#include <variant>

#include "link/capture/wire_log.hpp"
#include "link/mem_pipe.hpp"

namespace hil::mocks {
namespace {

// Tells a person about the faults injected on a client's link.
class FaultLogger final : public link::LinkObserver {
 public:
  FaultLogger(std::string id, std::function<void(const std::string&)> log)
      : id_(std::move(id)), log_(std::move(log)) {}
  void on_fault(const link::FaultEvent& e) override {
    log_(id_ + " " + link::format_ms(e.at) + " fault " + std::string(link::to_string(e.kind)) +
         " (" + e.rule + ", " + std::string(link::to_string(e.direction)) + "): " + e.detail);
  }

 private:
  std::string id_;
  std::function<void(const std::string&)> log_;
};

// Remembers why a client's link closed, and the firmware's counters then,
// for the session's "client gone" line (a next client may already be
// talking to the firmware when that line is written).
class CloseReason final : public link::LinkObserver {
 public:
  explicit CloseReason(const Firmware& firmware) : firmware_(firmware) {}
  void on_close(Time /*at*/, const link::LinkClose& close) override {
    reason_ = close.reason;
    stats_ = firmware_.stats();
  }
  const std::string& reason() const { return reason_; }
  FirmwareStats stats() const { return stats_ ? *stats_ : firmware_.stats(); }

 private:
  const Firmware& firmware_;
  std::string reason_;
  std::optional<FirmwareStats> stats_;
};

// What one session did to the firmware's counters, for its last log line.
std::string session_counts(const FirmwareStats& now, const FirmwareStats& at_start) {
  return std::to_string(now.bytes_in - at_start.bytes_in) + " bytes in, " +
         std::to_string(now.frames_in - at_start.frames_in) + " frames in, " +
         std::to_string(now.bad_frames - at_start.bad_frames) + " bad frames, " +
         std::to_string(now.frames_out - at_start.frames_out) + " frames out";
}

}  // namespace

// Counts the faults of every link the server opened, and its refusals, by
// kind: the links come and go, the counts stay.
class MockServer::FaultTally final : public link::LinkObserver {
 public:
  void on_fault(const link::FaultEvent& e) override {
    ++counts_.at(static_cast<std::size_t>(e.kind));
  }
  std::uint64_t count(link::FaultKind kind) const {
    return counts_.at(static_cast<std::size_t>(kind));
  }
  std::uint64_t total() const {
    std::uint64_t sum = 0;
    for (const auto n : counts_)
      sum += n;
    return sum;
  }

 private:
  std::array<std::uint64_t, std::variant_size_v<link::FaultAction>> counts_{};
};

MockServer::MockServer(link::TransportContext& context, Firmware& firmware, ServerOptions options)
    : context_(context),
      firmware_(firmware),
      options_(std::move(options)),
      timer_(context.executor,
             [this] {
               firmware_.wake(context_.executor.now());
               flush();
             }),
      tally_(std::make_shared<FaultTally>()) {
  if (!options_.protocol) options_.protocol = firmware_.adapter();
  gate_ = std::make_unique<link::FaultInjector>(
      link::Direction::to_car, options_.protocol,
      link::for_direction(options_.faults, link::Direction::to_car), options_.seed,
      // A refused connection never gets a link: its fault goes to the
      // observers from here.
      [this](const link::FaultEvent& e) {
        tally_->on_fault(e);
        for (const auto& o : options_.observers)
          o->on_fault(e);
      });
}

MockServer::~MockServer() {
  close();
  firmware_.set_wakeup_changed({});
  *alive_ = false;
}

void MockServer::say(const std::string& line) const {
  if (options_.log) options_.log(line);
}

void MockServer::start() {
  listener_ = link::listen(context_, options_.listen);
  running_ = true;
  std::weak_ptr<bool> alive_for_arm = alive_;
  firmware_.set_wakeup_changed([this, alive_for_arm] {
    if (const auto a = alive_for_arm.lock(); a && *a) reschedule();
  });
  std::weak_ptr<bool> alive = alive_;
  listener_->start([this, alive](link::BytePipePtr client) {
    if (const auto a = alive.lock(); a && *a) on_accept(std::move(client));
  });
  // The car lives before anyone connects: its control loop runs from now.
  firmware_.wake(context_.executor.now());
  flush();
}

std::string MockServer::address() const {
  return listener_ ? listener_->address() : link::to_uri(options_.listen);
}

void MockServer::set_faults(link::FaultProfile faults) {
  options_.faults = std::move(faults);
  gate_->set_profile(link::for_direction(options_.faults, link::Direction::to_car));
  if (link_ && link_->is_open()) link_->set_faults(options_.faults);
}

bool MockServer::client_connected() const {
  return link_ && link_->is_open();
}

std::uint64_t MockServer::faults_injected() const {
  return tally_->total();
}

std::uint64_t MockServer::faults_injected(link::FaultKind kind) const {
  return tally_->count(kind);
}

void MockServer::on_accept(link::BytePipePtr client) {
  if (!running_) {
    client->close(link::CloseMode::reset);
    return;
  }
  const auto now = context_.executor.now();
  ++accepted_;
  if (gate_->refuse_connection(now)) {
    ++turned_away_;
    say(options_.name + " refused a connection (fault rule): " + client->describe());
    client->close(link::CloseMode::reset);
    return;
  }
  if (client_connected()) {
    // The firmware serves one client: a second connection is accepted and
    // closed at once, and the first keeps its session.
    ++turned_away_;
    say(options_.name + " turned away a second client (one at a time): " + client->describe());
    client->close(link::CloseMode::graceful);
    return;
  }
  const std::uint64_t number = ++served_;
  const std::string id = options_.name + "/link" + std::to_string(number);

  link::LinkOptions link_options;
  link_options.protocol = options_.protocol;
  link_options.set_faults(options_.faults);
  link_options.seed = options_.seed + number - 1;
  link_options.observers = options_.observers;
  link_options.observers.push_back(tally_);
  if (options_.log)
    link_options.observers.push_back(std::make_shared<FaultLogger>(id, options_.log));
  if (!options_.wire_log_path.empty()) {
    std::error_code ec;
    auto log = link::WireLog::open(options_.wire_log_path,
                                   link::WireLogOptions{id, options_.protocol, {}}, ec);
    if (log)
      link_options.observers.push_back(log);
    else
      say(id + " cannot write the wire log " + options_.wire_log_path + ": " + ec.message());
  }

  // A client that never reads must not grow the process without end.
  client->set_send_limit(link::kMaxSendBacklogBytes);
  auto close_reason = std::make_shared<CloseReason>(firmware_);
  link_options.observers.push_back(close_reason);
  const std::string peer = client->describe();
  const FirmwareStats at_start = firmware_.stats();

  say(id + " client connected: " + peer);
  auto [car_end, firmware_end] = link::make_mem_pipe(context_.executor, id);
  firmware_end_ = firmware_end;
  std::weak_ptr<bool> alive = alive_;
  std::weak_ptr<link::BytePipe> weak_end = firmware_end;
  firmware_end->start(link::BytePipe::Handlers{
      [this, alive](link::ByteView bytes) {
        if (const auto a = alive.lock(); !a || !*a) return;
        firmware_.receive(context_.executor.now(), bytes);
        flush();
      },
      [this, alive, weak_end, id, close_reason, peer, at_start](std::error_code ec) {
        if (const auto a = alive.lock(); !a || !*a) return;
        // A next client may have connected before this session's end got
        // here: the firmware is theirs now, but this session is still told.
        const bool current = weak_end.lock() == firmware_end_;
        if (current) {
          firmware_end_.reset();
          firmware_.disconnect(context_.executor.now());
        }
        const std::string& why = close_reason->reason();
        if (why.find(std::make_error_code(std::errc::no_buffer_space).message()) !=
            std::string::npos) {
          say(id + " client dropped: it stopped reading and " +
              std::to_string(link::kMaxSendBacklogBytes) + " bytes waited for it (" + peer + ")");
        }
        std::string detail;
        if (!why.empty() && why != "client closed")
          detail = ": " + why;
        else if (ec != link::end_of_stream() && ec != link::closed_here())
          detail = ": " + ec.message();
        say(id + " client gone" + detail + " (" + session_counts(close_reason->stats(), at_start) +
            ")");
        if (current) flush();
      }});
  link_ = link::Link::create(context_.executor, std::move(client), std::move(car_end),
                             std::move(link_options));
  // One instant for the car's connection and the timeline's `open` (an
  // external client's origin): the car's clock grid and the fault times
  // moved to the origin then line up exactly.
  link_->start(now);
  firmware_.connect(now);
  flush();
}

void MockServer::flush() {
  Bytes out = firmware_.take_output();
  if (!out.empty() && firmware_end_) firmware_end_->write(out);
  if (const auto mode = firmware_.take_close(); mode && firmware_end_) {
    say(options_.name + " firmware closes the connection" +
        (*mode == link::CloseMode::reset ? " (reset)" : ""));
    auto end = firmware_end_;
    end->close(*mode);
  }
  reschedule();
}

void MockServer::reschedule() {
  timer_.schedule(running_ ? firmware_.next_wakeup() : std::nullopt);
}

void MockServer::close() {
  if (!running_) return;
  running_ = false;
  if (listener_) listener_->close();
  if (link_) link_->close();
  timer_.schedule(std::nullopt);
}

}  // namespace hil::mocks
