// Procedural terrain: seeded diamond-square fractal on a (2^n + 1) x (2^n + 1) grid.
#pragma once

#include <cstdint>

#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

struct FractalOptions {
  int size = 513;            // grid points per side: 2^n + 1, 3..16385
  uint64_t seed = 1;
  double cell_size = 30.0;   // metres
  double relief = 1500.0;    // metres between the lowest and the highest point after normalisation
  double base = 200.0;       // height of the lowest point, metres
  double roughness = 0.55;   // amplitude factor per halving of the feature size (H = -log2(roughness))
  double ridge_bias = 0.35;  // 0..1: share of a large-scale ridge (a mountain range across the map) mixed in
  int octave_start = 1;      // the first subdivision level that gets random offsets (0 = the corners too)
};

// Deterministic for a given seed on every platform (own random numbers, no std distributions). Throws
// farfield::Error for a size that is not 2^n + 1 or options out of range.
Heightfield fractalTerrain(const FractalOptions& options = {});

}  // namespace farfield::terrain
