#include "client/leka/core.hpp"

#include <algorithm>
#include <charconv>
#include <utility>

namespace hil::client::leka {

namespace {
std::uint8_t u8(int v) {
  return static_cast<std::uint8_t>(v);
}
}  // namespace

bool GroupBuilder::check(std::string_view field, int value, int lo, int hi) {
  if (value >= lo && value <= hi) return true;
  if (first_error_.ok()) first_error_ = {BuildError::out_of_range, std::string(field)};
  return false;
}

GroupBuilder& GroupBuilder::add(proto::Command c) {
  group_.commands.push_back(std::move(c));
  return *this;
}

GroupBuilder& GroupBuilder::info() {
  return add(proto::Info{});
}
GroupBuilder& GroupBuilder::stop_led() {
  return add(proto::StopLed{});
}
GroupBuilder& GroupBuilder::stop_motor() {
  return add(proto::StopMotor{});
}
GroupBuilder& GroupBuilder::stop_robot() {
  return add(proto::StopRobot{});
}
GroupBuilder& GroupBuilder::ear_all(proto::Rgb color) {
  return add(proto::EarAll{color});
}
GroupBuilder& GroupBuilder::belt_all(proto::Rgb color) {
  return add(proto::BeltAll{color});
}

GroupBuilder& GroupBuilder::ear_range(int first, int last, proto::Rgb color) {
  if (!check("led.ear.range first", first, 0, 1)) return *this;
  if (!check("led.ear.range last", last, first, 1)) return *this;
  return add(proto::EarRange{u8(first), u8(last), color});
}

GroupBuilder& GroupBuilder::ear_single(int led, proto::Rgb color) {
  if (!check("led.ear.single led", led, 0, 1)) return *this;
  return add(proto::EarSingle{u8(led), color});
}

GroupBuilder& GroupBuilder::belt_range(int first, int last, proto::Rgb color) {
  const int max = limits_.max_belt_led_id;
  if (!check("led.belt.range first", first, 0, max)) return *this;
  if (!check("led.belt.range last", last, first, max)) return *this;
  return add(proto::BeltRange{u8(first), u8(last), color});
}

GroupBuilder& GroupBuilder::belt_single(int led, proto::Rgb color) {
  if (!check("led.belt.single led", led, 0, limits_.max_belt_led_id)) return *this;
  return add(proto::BeltSingle{u8(led), color});
}

GroupBuilder& GroupBuilder::motor_all(int direction, int speed) {
  if (!check("motor.all direction", direction, 0, 1)) return *this;
  if (!check("motor.all speed", speed, 0, 255)) return *this;
  return add(proto::MotorAll{u8(direction), u8(speed)});
}

GroupBuilder& GroupBuilder::motor_duo(int left_spin, int left_speed, int right_spin,
                                      int right_speed) {
  if (!check("motor.duo left_spin", left_spin, 0, 1)) return *this;
  if (!check("motor.duo left_speed", left_speed, 0, 255)) return *this;
  if (!check("motor.duo right_spin", right_spin, 0, 1)) return *this;
  if (!check("motor.duo right_speed", right_speed, 0, 255)) return *this;
  return add(proto::MotorDuo{u8(left_spin), u8(left_speed), u8(right_spin), u8(right_speed)});
}

GroupBuilder& GroupBuilder::motor_left(int spin, int speed) {
  if (!check("motor.left spin", spin, 0, 1)) return *this;
  if (!check("motor.left speed", speed, 0, 255)) return *this;
  return add(proto::MotorLeft{u8(spin), u8(speed)});
}

GroupBuilder& GroupBuilder::motor_right(int spin, int speed) {
  if (!check("motor.right spin", spin, 0, 1)) return *this;
  if (!check("motor.right speed", speed, 0, 255)) return *this;
  return add(proto::MotorRight{u8(spin), u8(speed)});
}

GroupBuilder& GroupBuilder::motivator(int id) {
  if (!check("motivator id", id, 0x51, 0x55)) return *this;
  return add(proto::Motivator{u8(id)});
}

GroupBuilder& GroupBuilder::guidance(int id) {
  if (!check("guidance id", id, 0x41, 0x4F)) return *this;
  return add(proto::Guidance{u8(id)});
}

BuildResult GroupBuilder::result() const {
  if (!first_error_.ok()) return first_error_;
  if (group_.commands.empty()) return {BuildError::group_empty, ""};
  return {};
}

std::vector<Bytes> split_frames(const proto::CommandGroup& group, std::size_t max_group_bytes,
                                proto::Dialect dialect) {
  std::vector<Bytes> frames;
  proto::CommandGroup part;
  std::size_t part_bytes = 0;
  for (const auto& c : group.commands) {
    const std::size_t size = 1 + proto::spec_of(c).data_bytes;
    if (!part.commands.empty() && part_bytes + size > max_group_bytes) {
      frames.push_back(proto::encode(part, {}, dialect));
      part.commands.clear();
      part_bytes = 0;
    }
    part.commands.push_back(c);
    part_bytes += size;
  }
  if (!part.commands.empty()) frames.push_back(proto::encode(part, {}, dialect));
  return frames;
}

std::optional<InfoReply> parse_info_line(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n'))
    line.remove_suffix(1);
  // Noise on the serial line before the reply (a glitch, a boot message
  // cut short) ends up at the start of the same line: the reply begins at
  // the last "LEKA ", as the frame receivers resynchronise on their header.
  const auto start = line.rfind("LEKA ");
  if (start == std::string_view::npos) return std::nullopt;
  line.remove_prefix(start + 4);
  InfoReply reply;
  while (!line.empty()) {
    if (line.front() == ' ') {
      line.remove_prefix(1);
      continue;
    }
    const auto end = std::min(line.find(' '), line.size());
    const std::string_view token = line.substr(0, end);
    line.remove_prefix(end);
    const auto eq = token.find('=');
    if (eq == std::string_view::npos || eq == 0) return std::nullopt;
    reply.fields[std::string(token.substr(0, eq))] = std::string(token.substr(eq + 1));
  }
  if (reply.fields.empty()) return std::nullopt;
  auto get = [&](const char* k) {
    auto it = reply.fields.find(k);
    return it == reply.fields.end() ? std::string() : it->second;
  };
  reply.name = get("name");
  reply.firmware = get("firmware");
  reply.state = get("state");
  const std::string buffer = get("buffer");
  int value = 0;
  auto [p, ec] = std::from_chars(buffer.data(), buffer.data() + buffer.size(), value);
  if (!buffer.empty() && ec == std::errc{} && p == buffer.data() + buffer.size())
    reply.buffer_bytes = value;
  return reply;
}

LekaClientCore::LekaClientCore(ClientConfig config) : config_(config) {
  config_.max_frame_bytes =
      std::clamp<std::size_t>(std::min(config_.max_frame_bytes, config_.bytes_per_period),
                              proto::kOverheadBytes + 5, proto::kMaxFrameBytes);
}

void LekaClientCore::on_connected(Time now) {
  connected_ = true;
  pump(now);
}

void LekaClientCore::on_closed(Time) {
  connected_ = false;
  queue_.clear();
  sent_.clear();
  line_.clear();
  for (const auto& p : pending_)
    events_.push_back(InfoDone{p.id, {InfoStatus::closed, {}}});
  pending_.clear();
}

BuildResult LekaClientCore::send(Time now, const GroupBuilder& builder) {
  auto result = builder.result();
  if (!result.ok()) return result;
  return send(now, builder.group());
}

BuildResult LekaClientCore::send(Time now, const proto::CommandGroup& group) {
  if (group.commands.empty()) return {BuildError::group_empty, ""};
  for (const auto& c : group.commands) {
    if (auto problem = proto::range_problem(c))
      return {BuildError::out_of_range, std::string(proto::spec_of(c).name)};
    if (!proto::spec_of(c).in(config_.dialect))
      return {BuildError::not_in_profile, std::string(proto::spec_of(c).name)};
  }
  for (auto& f :
       split_frames(group, config_.max_frame_bytes - proto::kOverheadBytes, config_.dialect))
    queue_.push_back({std::move(f), std::nullopt});
  pump(now);
  return {};
}

RequestId LekaClientCore::info(Time now) {
  const RequestId id = next_id_++;
  pending_.push_back({id, std::nullopt});
  queue_.push_back({proto::encode(proto::CommandGroup{{proto::Info{}}}, {}, config_.dialect), id});
  pump(now);
  return id;
}

std::size_t LekaClientCore::window_bytes(Time now) const {
  std::size_t total = 0;
  for (const auto& [at, bytes] : sent_)
    if (at > now - config_.loop_period) total += bytes;
  return total;
}

void LekaClientCore::pump(Time now) {
  while (!sent_.empty() && sent_.front().first <= now - config_.loop_period)
    sent_.pop_front();
  if (!connected_) return;
  while (!queue_.empty()) {
    const std::size_t size = queue_.front().bytes.size();
    if (config_.paced && window_bytes(now) + size > config_.bytes_per_period) break;
    Queued q = std::move(queue_.front());
    queue_.pop_front();
    sent_.push_back({now, size});
    if (q.info) {
      for (auto& p : pending_)
        if (p.id == *q.info) p.deadline = now + config_.info_timeout;
    }
    actions_.push_back({std::move(q.bytes)});
  }
}

void LekaClientCore::expire(Time now) {
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (it->deadline && *it->deadline <= now) {
      events_.push_back(InfoDone{it->id, {InfoStatus::timeout, {}}});
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
}

void LekaClientCore::on_timer(Time now) {
  expire(now);
  pump(now);
}

void LekaClientCore::on_bytes(Time now, ByteView bytes) {
  expire(now);
  for (std::uint8_t b : bytes) {
    if (b != '\n') {
      // The robot's line is short; a runaway line is noise, not a reply.
      if (line_.size() < 256) line_.push_back(static_cast<char>(b));
      continue;
    }
    std::string line = std::exchange(line_, {});
    if (!line.empty() && line.back() == '\r') line.pop_back();
    events_.push_back(LineReceived{line});
    auto reply = parse_info_line(line);
    // The robot answers infos in the order they were sent; the oldest one
    // already on the wire takes the line.
    auto it = std::find_if(pending_.begin(), pending_.end(),
                           [](const Pending& p) { return p.deadline.has_value(); });
    if (reply && it != pending_.end()) {
      events_.push_back(InfoDone{it->id, {InfoStatus::ok, std::move(reply)}});
      pending_.erase(it);
    }
  }
}

std::optional<Time> LekaClientCore::next_wakeup() const {
  link::Earliest due;
  for (const auto& p : pending_)
    due.consider(p.deadline);
  if (connected_ && !queue_.empty() && !sent_.empty()) {
    // The next frame fits once enough of the window's oldest frames leave it.
    const std::size_t need = queue_.front().bytes.size();
    std::size_t total = 0;
    for (const auto& s : sent_)
      total += s.second;
    std::optional<Time> fits;
    for (const auto& [at, bytes] : sent_) {
      if (total + need <= config_.bytes_per_period) break;
      total -= bytes;
      fits = at + config_.loop_period;
    }
    due.consider(fits);
  }
  return due.time();
}

std::vector<SendFrame> LekaClientCore::take_actions() {
  return std::exchange(actions_, {});
}
std::vector<Event> LekaClientCore::take_events() {
  return std::exchange(events_, {});
}

}  // namespace hil::client::leka
