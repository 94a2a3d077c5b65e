// Per-frame choice between the high-resolution LOD and the LOD-sprite path (Chen et al. 1999 section 3, Figure 3),
// from a cost model calibrated on the running machine (terrain_cost.h), so that LOD-sprite never costs more than
// drawing the high-resolution LOD.
//
// The sprite path pays a keyframe (the high-resolution mesh into a larger target, its z-buffer read back, then the
// frame itself) once per sprite, and a cheap frame (the low-resolution mesh, textured with the sprite) for the rest of
// the sprite's life. Drawing the high LOD costs the same every frame. So:
// - while a sprite is valid (its error below the threshold), the sprite frame is drawn when it is predicted cheaper
//   than the high frame;
// - when a new sprite is due, it is taken only when its predicted cost over its expected life is lower:
//   keyframe_ms + (L - 1) * sprite_ms < L * high_ms, L the expected lifetime in frames (recent lifetimes,
//   spriteLifetimeEstimate). Otherwise the frame draws the high LOD, and the error metric keeps running from a
//   "virtual" keyframe at this viewpoint, so lifetimes keep being measured while no sprite exists; the virtual
//   keyframe's age is itself a lower bound of the lifetime, so a keyframe is taken as soon as that age makes it pay.
// Pure data in and out: no GL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>

namespace farfield::terrain {

enum class TerrainPath : uint8_t { High, Sprite };
const char* terrainPathName(TerrainPath path);

// Predicted costs of this frame's alternatives, milliseconds (>= 0).
struct PathCosts {
  double high_ms = 0.0;      // the high-resolution LOD at the frame's camera
  double sprite_ms = 0.0;    // the low-resolution LOD textured with a valid sprite
  double keyframe_ms = 0.0;  // a new keyframe and this frame drawn from it (includes sprite_ms)
};

// sprite_valid: a sprite exists and its error is below the threshold at this viewpoint. expected_lifetime: frames a
// new sprite is expected to serve (>= 1; only used when !sprite_valid).
TerrainPath choosePath(const PathCosts& costs, bool sprite_valid, double expected_lifetime);

// Expected lifetime of a new sprite from the most recent lifetimes (frames, each >= 1): their median; `fallback`
// when there are none.
double spriteLifetimeEstimate(const std::deque<uint64_t>& recent, double fallback);

}  // namespace farfield::terrain
