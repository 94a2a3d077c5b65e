// Sillion et al. 1997, section 5.1: "very little of this memory is needed at any given time, since very few impostors
// are active; a concurrent process can therefore be used to pre-fetch impostors in a neighborhood of the viewer".
// Which view regions (street cells) to read ahead: those adjacent to the viewer's cell in the direction of motion.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/urban/street_graph.h"

namespace farfield::runtime {

struct PrefetchChoice {
  uint32_t exit_junction = 0xffffffffu;  // the junction the viewer is heading for
  std::vector<uint32_t> cells;           // most likely next first
};

// The cells the viewer in `cell` may enter next, moving by `motion` (world xy; a zero motion is taken as moving along
// the cell): the cells of the streets at the junction it heads for (the cell's destination when it moves along the
// cell, its origin when it moves backwards), both directions of each, ordered by how well their direction agrees with
// the motion (ties by id), then the cell's twin if not among them (the viewer turning round where it stands); at
// most max_cells (0 = all).
PrefetchChoice prefetchCells(const urban::StreetGraph& graph, uint32_t cell, Vec2 motion, size_t max_cells);

}  // namespace farfield::runtime
