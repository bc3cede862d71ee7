#include "mocks/firmware.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "protocol/common/overloaded.hpp"

namespace hil::mocks {

void require_config(std::string_view config, bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(std::string(config) + ": " + what);
}

namespace {

// `chassis`, the vehicle's chassis of `kind`, or the error that it has none.
template <class Chassis>
Chassis& required_chassis(Chassis* chassis, const sim::Vehicle& vehicle, std::string_view kind,
                          std::string_view firmware, std::string_view hint) {
  if (chassis == nullptr) {
    std::string message = std::string(firmware) + ": vehicle '" + vehicle.name() + "' has no " +
                          std::string(kind) + " chassis";
    if (!hint.empty()) message += " (" + std::string(hint) + ")";
    throw std::invalid_argument(message);
  }
  return *chassis;
}

}  // namespace

sim::DifferentialChassis& differential_chassis_of(sim::Vehicle& vehicle, std::string_view firmware,
                                                  std::string_view hint) {
  return required_chassis(vehicle.differential(), vehicle, "differential", firmware, hint);
}

sim::AckermannChassis& ackermann_chassis_of(sim::Vehicle& vehicle, std::string_view firmware,
                                            std::string_view hint) {
  return required_chassis(vehicle.ackermann(), vehicle, "Ackermann", firmware, hint);
}

sim::MecanumChassis& mecanum_chassis_of(sim::Vehicle& vehicle, std::string_view firmware,
                                        std::string_view hint) {
  return required_chassis(vehicle.mecanum(), vehicle, "mecanum", firmware, hint);
}

Time next_grid_point(Time now, Duration period) {
  return (now / period + 1) * period;
}

Firmware::Firmware(sim::World& world, sim::Vehicle& vehicle, std::string_view protocol,
                   std::string_view profile)
    : world_(world), vehicle_(vehicle), protocol_(protocol), profile_(profile) {}

Firmware::~Firmware() = default;

std::shared_ptr<const link::ProtocolAdapter> Firmware::adapter() const {
  return link::protocol_adapter(protocol(), profile());
}

void Firmware::advance(Time now) {
  now_ = std::max(now_, now);
  world_.advance_to(now);
  release_delayed(now);
  run_actions(now, script_.take_due(now));
}

void Firmware::release_delayed(Time now) {
  while (!delayed_.empty() && delayed_.front().due <= now) {
    const Bytes& bytes = delayed_.front().bytes;
    output_.insert(output_.end(), bytes.begin(), bytes.end());
    delayed_.pop_front();
  }
}

void Firmware::connect(Time now) {
  advance(now);
  connected_ = true;
  ++stats_.connections;
  output_.clear();
  delayed_.clear();
  close_.reset();
  on_connect(now);
  on_tick(now);
}

void Firmware::disconnect(Time now) {
  advance(now);
  if (!connected_) return;
  connected_ = false;
  output_.clear();
  delayed_.clear();  // answers still being worked out have no one to go to
  close_.reset();
  on_disconnect(now);
  on_tick(now);
}

void Firmware::receive(Time now, ByteView bytes) {
  advance(now);
  stats_.bytes_in += bytes.size();
  on_bytes(now, bytes);
  on_tick(now);
}

void Firmware::wake(Time now) {
  advance(now);
  on_tick(now);
}

std::optional<Time> Firmware::next_wakeup() const {
  link::Earliest next;
  next.consider(next_tick());
  next.consider(script_.next_due());
  next.consider(muted_until_);
  if (!delayed_.empty()) next.consider(delayed_.front().due);
  return next.time();
}

void Firmware::arm(Behaviour behaviour) {
  script_.arm(std::move(behaviour));
  if (wakeup_changed_) wakeup_changed_();
}

void Firmware::clear_behaviours() {
  script_.clear();
  if (wakeup_changed_) wakeup_changed_();
}

Bytes Firmware::take_output() {
  Bytes out;
  out.swap(output_);
  return out;
}

std::optional<link::CloseMode> Firmware::take_close() {
  if (!delayed_.empty() && close_ != link::CloseMode::reset) return std::nullopt;
  auto mode = close_;
  close_.reset();
  return mode;
}

void Firmware::queue_output(ByteView bytes) {
  if (reply_latency_ > Duration{0}) {
    Time due = now_ + reply_latency_;
    if (!delayed_.empty()) due = std::max(due, delayed_.back().due);
    delayed_.push_back({due, Bytes(bytes.begin(), bytes.end())});
  } else if (!delayed_.empty()) {
    delayed_.push_back({delayed_.back().due, Bytes(bytes.begin(), bytes.end())});
  } else {
    output_.insert(output_.end(), bytes.begin(), bytes.end());
  }
  stats_.bytes_out += bytes.size();
}

void Firmware::send(ByteView frame) {
  if (!connected_) return;
  queue_output(frame);
  ++stats_.frames_out;
}

void Firmware::send_bytes(ByteView bytes) {
  if (!connected_) return;
  queue_output(bytes);
}

void Firmware::send(std::string_view frame) {
  send(ByteView(reinterpret_cast<const std::uint8_t*>(frame.data()), frame.size()));
}

Disposition Firmware::dispose(Time now, std::string_view kind) {
  const Disposition d = script_.dispose(now, kind);
  if (d == Disposition::reject) ++stats_.rejected;
  if (d == Disposition::ignore) ++stats_.ignored;
  return d;
}

void Firmware::frame_handled(Time now, std::string_view kind) {
  run_actions(now, script_.frame_handled(now, kind));
}

void Firmware::enter_fault(Time now, bool entered) {
  if (fault_ == entered) return;
  fault_ = entered;
  on_fault(now, entered);
}

void Firmware::run_actions(Time now, const std::vector<Behaviour>& fired) {
  for (const Behaviour& b : fired) {
    std::visit(protocol::Overloaded{
                   [](const Reject&) {},  // active in the script
                   [](const Ignore&) {},
                   [&](const MuteTelemetry& m) {
                     const Time until = now + m.duration;
                     if (!muted_until_ || until > *muted_until_) muted_until_ = until;
                   },
                   [&](const SendBytes& s) { send(ByteView(s.bytes)); },
                   [&](const EnterFault&) { enter_fault(now, true); },
                   [&](const ClearFault&) { enter_fault(now, false); },
                   [&](const CloseConnection& c) {
                     if (connected_) close_ = c.mode;
                   },
               },
               b.action);
  }
  if (muted_until_ && now >= *muted_until_) muted_until_.reset();
}

}  // namespace hil::mocks
