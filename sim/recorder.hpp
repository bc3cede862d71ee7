#pragma once
// Records what each vehicle of a world did, as trajectories for pictures
// and reports: poses at a fixed period, and marks for collisions, stations
// read and the moments a moving car came to rest.

#include <vector>

#include "sim/trajectory.hpp"
#include "sim/world.hpp"

namespace hil::sim {

class TrajectoryRecorder {
 public:
  /// Samples every `period` of simulated time (default 50 ms).
  explicit TrajectoryRecorder(Duration period = std::chrono::milliseconds(50));

  /// Call after advancing the world; picks up samples, contacts and
  /// station reads since the last call. Consumes the world's contact
  /// events (they are returned too, for the caller's own use).
  std::vector<ContactEvent> observe(World& world);
  /// Adds a labelled note at the vehicle's current position.
  void note(World& world, std::size_t vehicle, std::string label);

  const std::vector<Trajectory>& trajectories() const { return trajectories_; }

 private:
  struct Track {
    Duration next_sample{};
    std::uint64_t rfid_reads = 0;
    bool moving = false;
  };
  void ensure(World& world);

  Duration period_;
  std::vector<Trajectory> trajectories_;
  std::vector<Track> tracks_;
};

}  // namespace hil::sim
