// How far a simplified surface lies from the surface it simplifies (the arena's simplified levels, gpu/arena_mesh.h):
// the largest distance from a vertex of the full surface to the simplified one, and from points of the simplified
// triangles (corners, edge midpoints, centroid and three inner points) to the full one. Nearest triangles are found
// through a uniform grid over each surface, so a mesh of n triangles costs about n lookups of a few triangles each
// rather than n^2 distance tests. Pure geometry: no GL, safe on worker threads.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/math.h"

namespace farfield::gpu {

// Both index lists are triangles over `positions`. 0 for identical lists; infinity when one is empty and the other not.
double surfaceDeviation(std::span<const Vec3> positions, std::span<const uint32_t> full,
                        std::span<const uint32_t> simplified);

}  // namespace farfield::gpu
