#include "view/live_model.hpp"

#include "view/drawing.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <variant>

#include "link/capture/wire_log.hpp"
#include "link/faults/profile_yaml.hpp"
#include "mocks/behaviour_yaml.hpp"
#include "sim/geometry.hpp"

namespace hil::view {
namespace {

using nlohmann::json;

double ms_of(link::Time t) {
  return std::chrono::duration<double, std::milli>(t).count();
}

std::string hex_of(protocol::ByteView bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  const std::size_t shown = std::min<std::size_t>(bytes.size(), 64);
  out.reserve(shown * 3);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i != 0) out += ' ';
    out += kDigits[bytes[i] >> 4];
    out += kDigits[bytes[i] & 0xF];
  }
  if (bytes.size() > shown) out += " ...";
  return out;
}

Reply bad(const std::string& message) {
  return Reply{400, json{{"error", message}}};
}

// Runs `parse`, which reads YAML the page sent; the 400 reply for what it
// threw, if anything: a ConfigError as it reads, another YAML error after
// `what`.
template <class Parse>
std::optional<Reply> bad_yaml(const std::string& what, Parse parse) {
  try {
    parse();
  } catch (const config::ConfigError& e) {
    return bad(e.what());
  } catch (const YAML::Exception& e) {
    return bad(what + ": " + e.what());
  }
  return std::nullopt;
}

// A number field; nullopt when absent; throws a message for a wrong type.
std::optional<double> number_field(const json& request, const char* name) {
  const auto it = request.find(name);
  if (it == request.end() || it->is_null()) return std::nullopt;
  if (!it->is_number() || !std::isfinite(it->get<double>()))
    throw std::invalid_argument(std::string("'") + name + "' must be a number");
  return it->get<double>();
}

std::string string_field(const json& request, const char* name, std::string fallback = {}) {
  const auto it = request.find(name);
  if (it == request.end() || it->is_null()) return fallback;
  if (!it->is_string()) throw std::invalid_argument(std::string("'") + name + "' must be a string");
  return it->get<std::string>();
}

json arena_json(const sim::World& world) {
  std::vector<bool> present(world.arena().obstacles.size());
  for (std::size_t i = 0; i < present.size(); ++i)
    present[i] = world.obstacle_present(i);
  return view::arena_json(world.arena(), &present);
}

// The sonar's beam as the physics sees it (no noise, no sensor faults):
// the page draws the rays and marks where the nearest one hits.
json sonar_json(sim::World& world, const sim::Vehicle& vehicle) {
  const auto& def = vehicle.def().sonar;
  const auto pose = vehicle.pose();
  const sim::Vec2 from = pose.to_arena(def.mount_m);
  const double axis = pose.heading_rad + def.mount_angle_rad;
  json rays = json::array();
  std::optional<double> nearest;
  const int count = std::max(1, def.rays);
  for (int i = 0; i < count; ++i) {
    const double spread =
        count == 1 ? 0.0 : -def.beam_half_angle_rad + 2 * def.beam_half_angle_rad * i / (count - 1);
    const double angle = axis + spread;
    const sim::Vec2 to = from + def.max_range_m * sim::Vec2{std::cos(angle), std::sin(angle)};
    const auto hit = world.ray_cast(from, to, nullptr);
    const double d = hit.value_or(def.max_range_m);
    if (hit && (!nearest || *hit < *nearest)) nearest = hit;
    const sim::Vec2 end = from + d * sim::Vec2{std::cos(angle), std::sin(angle)};
    rays.push_back({{"x", end.x_m}, {"y", end.y_m}, {"hit", hit.has_value()}});
  }
  return {{"x", from.x_m},
          {"y", from.y_m},
          {"axis_deg", sim::rad_to_deg(axis)},
          {"rays", rays},
          {"echo", nearest.has_value()},
          {"distance_m", nearest.value_or(def.max_range_m)}};
}

json line_json(const sim::World& world, const sim::Vehicle& vehicle) {
  const auto& def = vehicle.def().line_tracker;
  const auto pose = vehicle.pose();
  const auto reading = vehicle.line_tracker();
  json sensors = json::array();
  for (std::size_t i = 0; i < def.lateral_m.size(); ++i) {
    const sim::Vec2 p = pose.to_arena({def.ahead_m, def.lateral_m[i]});
    sensors.push_back({{"name", "H" + std::to_string(4 - i)},
                       {"x", p.x_m},
                       {"y", p.y_m},
                       {"on_tape", world.arena().on_tape(p)}});
  }
  std::string bits;
  for (int b = 3; b >= 0; --b)
    bits += ((reading.mask >> b) & 1) != 0 ? '1' : '0';
  return {{"sensors", sensors}, {"mask", bits}, {"deviation", reading.deviation}};
}

json frames_json(const std::deque<WireWatch::Frame>& frames) {
  json out = json::array();
  for (const auto& f : frames)
    out.push_back({{"t_ms", sim::round_to(ms_of(f.at), 0.1)},
                   {"valid", f.valid},
                   {"kind", f.kind},
                   {"text", f.text},
                   {"hex", f.hex}});
  return out;
}

json profile_json(const link::FaultProfile& profile) {
  json rules = json::array();
  for (std::size_t i = 0; i < profile.rules.size(); ++i) {
    const auto& r = profile.rules[i];
    rules.push_back({{"name", r.name.empty() ? "#" + std::to_string(i + 1) : r.name},
                     {"kind", std::string(link::to_string(r.kind()))},
                     {"direction", std::string(link::to_string(r.direction))}});
  }
  return rules;
}

}  // namespace

// ---- WireWatch ----

WireWatch::WireWatch(std::shared_ptr<const link::ProtocolAdapter> adapter)
    : adapter_(std::move(adapter)) {}

void WireWatch::on_open(link::Time /*at*/, const std::string& /*client*/,
                        const std::string& /*car*/) {
  // A new connection starts both streams afresh: half a frame left by the
  // last client must not swallow the first frame of the next.
  for (int d = 0; d < 2; ++d)
    splitters_[d] = adapter_ ? adapter_->splitter_for(static_cast<link::Direction>(d)) : nullptr;
  last_close_.clear();
}

void WireWatch::on_delivered(link::Time at, link::Direction d, protocol::ByteView bytes) {
  auto& splitter = splitters_[static_cast<int>(d)];
  auto& kept = frames_[static_cast<int>(d)];
  if (!splitter) {
    kept.push_back(Frame{at, false, "bytes", std::string(bytes.size(), '.'), hex_of(bytes)});
  } else {
    scratch_.clear();
    splitter->feed(bytes, scratch_);
    for (auto& f : scratch_) {
      ++seen_[static_cast<int>(d)];
      // The page is open to anyone on the machine: a login string is never
      // kept, only the hex a debugger needs.
      std::string text = link::masked_frame_text(f.kind, std::move(f.text));
      kept.push_back(Frame{at, f.valid, std::move(f.kind), std::move(text), hex_of(f.raw)});
    }
  }
  while (kept.size() > kFramesKept)
    kept.pop_front();
}

void WireWatch::on_fault(const link::FaultEvent& event) {
  faults_.push_back(Fault{event.at, event.direction, std::string(link::to_string(event.kind)),
                          event.rule, event.detail});
  while (faults_.size() > kFaultsKept)
    faults_.pop_front();
}

void WireWatch::on_close(link::Time /*at*/, const link::LinkClose& close) {
  last_close_ = std::string(link::to_string(close.by)) + ": " + close.reason;
}

// ---- LiveModel ----

LiveModel::LiveModel(std::vector<ViewedCar> cars) {
  for (auto& viewed : cars) {
    Car car;
    car.original_obstacles = viewed.car->world().arena().obstacles.size();
    car.viewed = std::move(viewed);
    cars_.push_back(std::move(car));
  }
}

void LiveModel::sample() {
  for (auto& car : cars_) {
    const auto pose = car.viewed.car->vehicle().pose();
    // A point only when the car moved: a parked car keeps its whole trail.
    if (!car.trail.empty()) {
      const auto& last = car.trail.back();
      if (std::hypot(pose.x_m - last.x_m, pose.y_m - last.y_m) < 0.005) continue;
    }
    car.trail.push_back(pose);
    while (car.trail.size() > kTrailPoints)
      car.trail.pop_front();
  }
}

json LiveModel::car_json(const Car& car, std::size_t index, link::Time now) const {
  auto& mock = *car.viewed.car;
  auto& vehicle = mock.vehicle();
  auto& firmware = mock.firmware();
  const auto pose = vehicle.pose();
  const auto twist = vehicle.velocity();
  const auto footprint = vehicle.chassis().footprint();
  json j;
  j["index"] = index;
  j["name"] = mock.name();
  j["kind"] = std::string(mocks::to_string(mock.kind()));
  j["arena"] = arena_json(mock.world());
  j["pose"] = {
      {"x", pose.x_m}, {"y", pose.y_m}, {"heading_deg", sim::rad_to_deg(pose.heading_rad)}};
  j["footprint"] = {{"length", footprint.length_m},
                    {"width", footprint.width_m},
                    {"center_ahead", footprint.center_ahead_m}};
  json trail = json::array();
  for (const auto& p : car.trail)
    trail.push_back({sim::round_to(p.x_m, 1e-3), sim::round_to(p.y_m, 1e-3)});
  j["trail"] = trail;
  j["sonar"] = sonar_json(mock.world(), vehicle);
  j["line"] = line_json(mock.world(), vehicle);
  const auto battery = vehicle.battery();
  const auto tag = vehicle.rfid();
  j["telemetry"] = {
      {"speed_mps", std::hypot(twist.vx_mps, twist.vy_mps)},
      {"vx_mps", twist.vx_mps},
      {"vy_mps", twist.vy_mps},
      {"turn_degps", sim::rad_to_deg(twist.wz_radps)},
      {"sonar_cm", static_cast<int>(j["sonar"]["distance_m"].get<double>() * 100 + 0.5)},
      {"line", j["line"]["mask"]},
      {"rfid", tag ? json(*tag) : json(nullptr)},
      {"rfid_reads", vehicle.rfid_reads()},
      {"battery_v", battery.voltage_v},
      {"odometer_m", vehicle.odometry().distance_m},
      {"contacts", vehicle.contacts()},
  };
  j["mode"] = firmware.summary();
  j["in_fault"] = firmware.in_fault();
  // The dialect the car plays (protocol/common/car_profile.hpp) and its
  // processing time before each answer.
  j["profile"] = std::string(firmware.adapter()->profile());
  j["reply_latency_ms"] = sim::round_to(ms_of(firmware.reply_latency()), 0.001);
  j["sim_time_ms"] = sim::round_to(ms_of(now), 1);
  const auto& stats = firmware.stats();
  j["stats"] = {{"frames_in", stats.frames_in},   {"frames_out", stats.frames_out},
                {"bad_frames", stats.bad_frames}, {"rejected", stats.rejected},
                {"ignored", stats.ignored},       {"connections", stats.connections}};
  j["behaviours"] = {{"waiting", firmware.script().waiting()},
                     {"active", firmware.script().active()}};
  if (car.viewed.server != nullptr) {
    j["client_connected"] = car.viewed.server->client_connected();
    j["address"] = car.viewed.server->address();
    j["faults_injected"] = car.viewed.server->faults_injected();
  } else {
    j["client_connected"] = firmware.connected();
    j["faults_injected"] = 0;
  }
  j["fault_rules"] = profile_json(car.viewed.faults);
  j["fault_profile"] = car.viewed.faults_text;
  json frames = {{"to_car", json::array()}, {"to_client", json::array()}};
  json faults = json::array();
  if (car.viewed.watch) {
    const auto& w = *car.viewed.watch;
    frames["to_car"] = frames_json(w.frames(link::Direction::to_car));
    frames["to_client"] = frames_json(w.frames(link::Direction::to_client));
    for (const auto& f : w.faults())
      faults.push_back({{"t_ms", sim::round_to(ms_of(f.at), 0.1)},
                        {"direction", std::string(link::to_string(f.direction))},
                        {"kind", f.kind},
                        {"rule", f.rule},
                        {"detail", f.detail}});
    j["last_close"] = w.last_close();
  }
  j["frames"] = frames;
  j["faults"] = faults;
  return j;
}

json LiveModel::snapshot(link::Time now) const {
  json cars = json::array();
  for (std::size_t i = 0; i < cars_.size(); ++i)
    cars.push_back(car_json(cars_[i], i, now));
  return {{"cars", cars}};
}

std::vector<base::MetricFamily> LiveModel::metrics() const {
  using Family = base::MetricFamily;
  Family bytes{"hil_mock_bytes_total",
               "Bytes at the mock car: to_car the car received (after faults), to_client the "
               "car wrote (before faults).",
               Family::Type::counter,
               {}};
  Family frames{"hil_mock_frames_total",
                "Frames at the mock car: to_car client frames the car decoded, to_client frames "
                "the car sent.",
                Family::Type::counter,
                {}};
  Family bad_frames{"hil_mock_bad_frames_total",
                    "Client input the car could not decode: checksum errors, garbage, malformed "
                    "or oversized frames.",
                    Family::Type::counter,
                    {}};
  Family faults{"hil_mock_faults_total",
                "Faults injected on the car's links by rule kind, refused connections included.",
                Family::Type::counter,
                {}};
  Family connections{
      "hil_mock_connections_total", "Clients the car served.", Family::Type::counter, {}};
  Family open{
      "hil_mock_open_connections", "Clients connected to the car now.", Family::Type::gauge, {}};
  for (const auto& car : cars_) {
    const std::string& name = car.viewed.car->name();
    const auto& firmware = car.viewed.car->firmware();
    const auto& stats = firmware.stats();
    const auto* server = car.viewed.server;
    const auto count = [](std::uint64_t n) { return static_cast<double>(n); };
    bytes.add({{"car", name}, {"direction", "to_car"}}, count(stats.bytes_in))
        .add({{"car", name}, {"direction", "to_client"}}, count(stats.bytes_out));
    frames.add({{"car", name}, {"direction", "to_car"}}, count(stats.frames_in))
        .add({{"car", name}, {"direction", "to_client"}}, count(stats.frames_out));
    bad_frames.add({{"car", name}}, count(stats.bad_frames));
    for (const auto& kind : link::kFaultKindNames) {
      const std::uint64_t n = server != nullptr ? server->faults_injected(kind.value) : 0;
      faults.add({{"car", name}, {"kind", std::string(kind.name)}}, count(n));
    }
    connections.add({{"car", name}}, count(stats.connections));
    const bool connected = server != nullptr ? server->client_connected() : firmware.connected();
    open.add({{"car", name}}, connected ? 1 : 0);
  }
  return {std::move(bytes),  std::move(frames),      std::move(bad_frames),
          std::move(faults), std::move(connections), std::move(open)};
}

Reply LiveModel::handle(std::string_view action, std::string_view body) {
  try {
    json request = body.empty() ? json::object() : json::parse(body);
    if (!request.is_object()) return bad("the request body must be a JSON object");
    std::size_t index = 0;
    if (const auto n = number_field(request, "car")) {
      if (*n < 0 || *n != std::floor(*n) || *n >= static_cast<double>(cars_.size()))
        return bad("'car' must be a car number from 0 to " + std::to_string(cars_.size() - 1));
      index = static_cast<std::size_t>(*n);
    }
    Car& car = cars_.at(index);
    if (action == "faults") return set_faults(car, request);
    if (action == "behaviour") return trigger(car, request);
    if (action == "car") return move_car(car, request);
    if (action == "obstacle") return obstacle(car, request);
    if (action == "reset") return reset(car);
    return Reply{404, json{{"error", "no such action '" + std::string(action) +
                                         "' (faults, behaviour, car, obstacle, reset)"}}};
  } catch (const json::exception& e) {
    return bad(std::string("the request body is not valid JSON: ") + e.what());
  } catch (const std::exception& e) {
    return bad(e.what());
  }
}

Reply LiveModel::set_faults(Car& car, const json& request) {
  if (car.viewed.server == nullptr) return Reply{409, json{{"error", "this car has no link"}}};
  const auto it = request.find("profile");
  if (it == request.end()) return bad("'profile' is missing: give fault rules (docs/faults.md)");
  std::string text;
  if (it->is_string()) {
    text = it->get<std::string>();
  } else if (it->is_object() || it->is_array()) {
    text = it->dump(2);  // JSON is YAML: one loader for both
  } else if (!it->is_null()) {
    return bad("'profile' must be YAML text, a JSON object or list of rules, or null");
  }
  link::FaultProfile profile;
  const bool blank = text.find_first_not_of(" \t\r\n") == std::string::npos;
  if (!blank) {
    if (auto reply =
            bad_yaml("profile", [&] { profile = link::parse_fault_profile_text(text, "profile"); }))
      return *reply;
  }
  car.viewed.server->set_faults(profile);
  car.viewed.faults = profile;
  car.viewed.faults_text = blank ? std::string() : text;
  return Reply{200, json{{"ok", true}, {"rules", profile_json(profile)}}};
}

Reply LiveModel::trigger(Car& car, const json& request) {
  auto& firmware = car.viewed.car->firmware();
  if (request.contains("yaml")) {
    const std::string yaml = string_field(request, "yaml");
    std::vector<mocks::Behaviour> behaviours;
    if (auto reply = bad_yaml(
            "behaviour", [&] { behaviours = mocks::parse_behaviours_text(yaml, "behaviour"); }))
      return *reply;
    for (auto& b : behaviours)
      firmware.arm(std::move(b));
    return Reply{200, json{{"ok", true}, {"armed", behaviours.size()}}};
  }
  const std::string action = string_field(request, "action");
  mocks::Behaviour b;
  b.name = "view " + action;
  if (action == "drop-link" || action == "reset-link") {
    b.action = mocks::CloseConnection{action == "reset-link" ? link::CloseMode::reset
                                                             : link::CloseMode::graceful};
  } else if (action == "stall-telemetry") {
    const double ms = number_field(request, "duration_ms").value_or(3000);
    if (ms <= 0 || ms > 3'600'000) return bad("'duration_ms' must be from 1 to 3600000");
    b.action = mocks::MuteTelemetry{
        std::chrono::duration_cast<link::Duration>(std::chrono::duration<double, std::milli>(ms))};
  } else if (action == "reject-next") {
    const double count = number_field(request, "count").value_or(1);
    if (count < 1 || count != std::floor(count) || count > 1e6)
      return bad("'count' must be a whole number from 1");
    b.action = mocks::Reject{string_field(request, "match"), static_cast<std::uint64_t>(count)};
  } else if (action == "fault") {
    b.action = mocks::EnterFault{};
  } else if (action == "clear-fault") {
    b.action = mocks::ClearFault{};
  } else if (action == "clear") {
    firmware.clear_behaviours();
    return Reply{200, json{{"ok", true}}};
  } else {
    return bad(
        "'action' must be one of drop-link, reset-link, stall-telemetry, reject-next, "
        "fault, clear-fault, clear (or give 'yaml' behaviours as docs/mocks.md)");
  }
  firmware.arm(std::move(b));
  return Reply{200, json{{"ok", true}}};
}

Reply LiveModel::move_car(Car& car, const json& request) {
  auto& vehicle = car.viewed.car->vehicle();
  const auto& arena = car.viewed.car->world().arena();
  const auto pose = vehicle.pose();
  const double x = number_field(request, "x").value_or(pose.x_m);
  const double y = number_field(request, "y").value_or(pose.y_m);
  const double heading_deg =
      number_field(request, "heading_deg").value_or(sim::rad_to_deg(pose.heading_rad));
  if (x < 0 || x > arena.width_m || y < 0 || y > arena.height_m)
    return bad("the car must stay inside the arena (0..width, 0..height metres)");
  vehicle.place(sim::Pose{x, y, sim::deg_to_rad(heading_deg)});
  car.trail.clear();
  return Reply{200, json{{"ok", true}}};
}

Reply LiveModel::obstacle(Car& car, const json& request) {
  auto& world = car.viewed.car->world();
  const std::string op = string_field(request, "op", "add");
  if (op == "remove" || op == "move") {
    const auto n = number_field(request, "index");
    if (!n || *n < 0 || *n != std::floor(*n) ||
        !world.obstacle_present(static_cast<std::size_t>(*n)))
      return bad("'index' must be the index of an obstacle in the arena");
    const auto index = static_cast<std::size_t>(*n);
    sim::Obstacle moved = world.arena().obstacles.at(index);
    world.remove_obstacle(index);
    if (op == "remove") return Reply{200, json{{"ok", true}}};
    // The world has no move: the obstacle goes back in at its new place
    // under a new index.
    std::visit(
        [&](auto& o) {
          o.center_m.x_m = number_field(request, "x").value_or(o.center_m.x_m);
          o.center_m.y_m = number_field(request, "y").value_or(o.center_m.y_m);
        },
        moved);
    const auto added = world.add_obstacle(std::move(moved));
    return Reply{200, json{{"ok", true}, {"index", added}}};
  }
  if (op != "add") return bad("'op' must be add, move or remove");
  const auto x = number_field(request, "x");
  const auto y = number_field(request, "y");
  if (!x || !y) return bad("an obstacle needs 'x' and 'y' in metres");
  const std::string shape = string_field(request, "shape", "box");
  const std::string name = string_field(request, "name", "parcel");
  sim::Obstacle o;
  if (shape == "box") {
    const double w = number_field(request, "width").value_or(0.3);
    const double h = number_field(request, "height").value_or(0.2);
    if (w <= 0 || h <= 0) return bad("'width' and 'height' must be above 0");
    o = sim::BoxObstacle{
        name, {*x, *y}, w, h, sim::deg_to_rad(number_field(request, "angle_deg").value_or(0))};
  } else if (shape == "circle") {
    const double r = number_field(request, "radius").value_or(0.1);
    if (r <= 0) return bad("'radius' must be above 0");
    o = sim::CircleObstacle{name, {*x, *y}, r};
  } else {
    return bad("'shape' must be box or circle");
  }
  const auto index = world.add_obstacle(std::move(o));
  return Reply{200, json{{"ok", true}, {"index", index}}};
}

Reply LiveModel::reset(Car& car) {
  auto& world = car.viewed.car->world();
  const auto& arena = world.arena();
  const std::size_t count = arena.obstacles.size();
  for (std::size_t i = car.original_obstacles; i < count; ++i)
    world.remove_obstacle(i);
  for (std::size_t i = 0; i < car.original_obstacles; ++i)
    if (!world.obstacle_present(i)) world.add_obstacle(world.arena().obstacles.at(i));
  car.viewed.car->vehicle().place(world.arena().start);
  car.trail.clear();
  return Reply{200, json{{"ok", true}}};
}

}  // namespace hil::view
