#include "sim/recorder.hpp"

#include <cmath>

namespace hil::sim {

namespace {

// A car counts as moving above 1 cm/s or about 0.6 degrees/s, and as at
// rest below half of that, so sensor-level jitter does not flood the marks.
constexpr double kMovingMps = 0.01;
constexpr double kMovingRadps = 0.01;

double speed_of(const Twist& t) {
  return std::hypot(t.vx_mps, t.vy_mps);
}

}  // namespace

TrajectoryRecorder::TrajectoryRecorder(Duration period) : period_(period) {}

void TrajectoryRecorder::ensure(World& world) {
  while (trajectories_.size() < world.vehicle_count()) {
    Vehicle& v = world.vehicle(trajectories_.size());
    Trajectory t;
    t.vehicle = v.name();
    const Footprint f = v.chassis().footprint();
    t.length_m = f.length_m;
    t.width_m = f.width_m;
    trajectories_.push_back(std::move(t));
    Track track;
    track.next_sample = world.time();
    track.rfid_reads = v.rfid_reads();
    tracks_.push_back(track);
  }
}

std::vector<ContactEvent> TrajectoryRecorder::observe(World& world) {
  ensure(world);
  const Duration now = world.time();
  // Contacts happened during the steps just run, before anything seen now.
  auto contacts = world.take_contacts();
  for (const auto& c : contacts) {
    if (c.phase != ContactEvent::Phase::begin) continue;
    trajectories_.at(c.vehicle).marks.push_back(
        {c.time, c.point_m, MarkKind::collision, "hit " + c.other_name});
  }
  for (std::size_t i = 0; i < world.vehicle_count(); ++i) {
    Vehicle& v = world.vehicle(i);
    Trajectory& t = trajectories_[i];
    Track& track = tracks_[i];
    if (now >= track.next_sample) {
      t.samples.push_back({now, v.pose()});
      while (track.next_sample <= now)
        track.next_sample += period_;
    }
    if (v.rfid_reads() != track.rfid_reads) {
      track.rfid_reads = v.rfid_reads();
      if (auto id = v.rfid()) t.marks.push_back({now, v.pose().position(), MarkKind::station, *id});
    }
    const Twist vel = v.velocity();
    const double speed = speed_of(vel);
    if (!track.moving && (speed > kMovingMps || std::abs(vel.wz_radps) > kMovingRadps)) {
      track.moving = true;
    } else if (track.moving && speed < kMovingMps / 2 &&
               std::abs(vel.wz_radps) < kMovingRadps / 2) {
      track.moving = false;
      t.marks.push_back({now, v.pose().position(), MarkKind::stop, "stop"});
    }
  }
  return contacts;
}

void TrajectoryRecorder::note(World& world, std::size_t vehicle, std::string label) {
  ensure(world);
  trajectories_.at(vehicle).marks.push_back(
      {world.time(), world.vehicle(vehicle).pose().position(), MarkKind::note, std::move(label)});
}

}  // namespace hil::sim
