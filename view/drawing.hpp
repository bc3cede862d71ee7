#pragma once
// The arena drawing shared by the live view (`hil mock --view`) and the
// playback in `hil run --report-dir` pages: the arena as JSON and the one
// script that draws it, so a recorded run looks like the live car did.

#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/arena.hpp"

namespace hil::view {

/// Walls, obstacles, tape and stations in the drawing's JSON shape. With
/// `present`, obstacle i is left out when present[i] is false (removed from
/// a running world); obstacles keep their index in the arena either way.
nlohmann::json arena_json(const sim::Arena& arena, const std::vector<bool>* present = nullptr);

/// A browser script (no dependencies) defining:
///   hilFit(canvas, arena)        scale the arena into the canvas;
///   hilToArena(cx, cy)           canvas pixels back to arena metres;
///   hilDrawArena(ctx, arena, picked)   walls, grid, tape, stations, obstacles
///                                (obstacle `picked` highlighted);
///   hilDrawCar(ctx, car)         trail, sonar beam, body with heading, line
///                                sensors; car = {pose {x, y, heading_deg},
///                                footprint {length, width, center_ahead},
///                                trail [[x, y]...], in_fault, label, and
///                                optionally sonar and line as the live view
///                                sends them};
///   hilDraw(ctx, car, picked)    all of the above for one car.
std::string_view drawing_script();

}  // namespace hil::view
