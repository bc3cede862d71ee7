#pragma once
// Pictures of an arena and the paths driven in it, as standalone SVG.

#include <span>
#include <string>

#include "sim/arena.hpp"
#include "sim/trajectory.hpp"

namespace hil::sim {

struct SvgOptions {
  std::string title;          ///< drawn above the arena; empty for none
  double pixels_per_m = 200;  ///< drawing scale
  bool legend = true;         ///< explain colours and marks below the arena
  bool grid = true;           ///< a light 0.5 m grid with metre labels
};

/// The arena (walls, obstacles, tape, RFID stations with their ids, start
/// pose) and each trajectory (path, footprint and heading at its last pose,
/// marks for collisions, stops and stations) as one SVG document.
std::string render_svg(const Arena& arena, std::span<const Trajectory> trajectories,
                       const SvgOptions& options = {});

}  // namespace hil::sim
