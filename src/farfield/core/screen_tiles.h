// Screen regions as whole tiles: the pixels a screen pass must shade, given as rectangles that may overlap, become
// disjoint rectangles of whole tiles (runs of covered tiles per tile row), so that the pass shades each pixel once and
// only near the regions (the crowd's shadow receivers: gpu::ShadowReceiver).
#pragma once

#include <span>
#include <vector>

#include "farfield/core/math.h"

namespace farfield {

// Rectangles are (x0, y0, x1, y1) in pixels, exclusive ends. The result covers every pixel of every non-empty
// rectangle of `regions` inside the width x height frame, with disjoint rectangles made of tile_px x tile_px tiles
// (clipped at the frame's edges), each tile touching some region; rows of tiles from the bottom, runs left to right.
// Throws farfield::Error for a non-positive frame or tile size.
std::vector<glm::ivec4> tileCover(std::span<const glm::ivec4> regions, int width, int height, int tile_px);

}  // namespace farfield
