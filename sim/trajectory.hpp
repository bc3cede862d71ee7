#pragma once
// What a run leaves behind for pictures and reports: where each vehicle went
// and what happened on the way.

#include <string>
#include <vector>

#include "sim/geometry.hpp"
#include "sim/time.hpp"

namespace hil::sim {

struct TrajectorySample {
  Duration time{};
  Pose pose;
};

enum class MarkKind {
  collision,  ///< the chassis touched a wall, an obstacle or another car
  stop,       ///< the chassis came to rest (or was told to stop)
  station,    ///< an RFID station was read
  note,       ///< anything else worth a label (a fault, a mode change)
};

/// One labelled event on the path.
struct TrajectoryMark {
  Duration time{};
  Vec2 position_m;
  MarkKind kind = MarkKind::note;
  std::string label;
};

struct Trajectory {
  std::string vehicle;     ///< the car's name, shown in the legend
  double length_m = 0.30;  ///< footprint drawn at the last pose
  double width_m = 0.25;
  std::vector<TrajectorySample> samples;
  std::vector<TrajectoryMark> marks;
};

}  // namespace hil::sim
