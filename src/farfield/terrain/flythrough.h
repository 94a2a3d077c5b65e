// Flythrough camera paths over a heightfield, like Chen et al. 1999's Figure 8: the camera starts away from the
// terrain, zooms in, flies over a plain, then over a mountain range and on to the plain beyond.
//
// The plain, the mountains and the plain beyond are found on the heightfield: it is cut into coarse tiles; the
// plain is the lowest, flattest tile; the mountains the highest tile within reach of it; the plain beyond the lowest,
// flattest tile as far again past the mountains (see flythrough.cpp). The eye
// follows a smooth curve through them at a clearance above the highest ground near the path, looking ahead and down.
#pragma once

#include <vector>

#include "farfield/core/math.h"
#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

struct Viewpoint {
  Vec3 eye{0.0f};
  Vec3 at{0.0f, 1.0f, 0.0f};
  float fov_y = float(degToRad(60.0));
};

// Nine hours at 30 frames a second; more would only be an allocation failure (the path is built in memory).
inline constexpr int kMaxFlythroughFrames = 1000000;

struct FlythroughOptions {
  int frames = 600;
  float fov_deg = 60.0f;
  float clearance = 0.0f;   // metres above the highest ground near the path; 0 = 2% of the map diagonal (>= 120 m)
  float reach = 0.15f;           // the mountains lie within this many map diagonals of the plain (more if none stand out)
  float start_distance = 0.35f;  // the start lies this many map diagonals before the plain, ...
  float start_height = 0.25f;    // ... this many diagonals above the highest point
  float look_ahead = 0.12f;     // the look-at point is this many diagonals ahead along the path, on the ground
};

struct FlythroughLandmarks {
  Vec2 plain{0.0f}, mountains{0.0f}, beyond{0.0f};  // world xy
};

// Throws farfield::Error for frames outside 2..kMaxFlythroughFrames or a heightfield smaller than 8x8 points.
std::vector<Viewpoint> flythroughPath(const Heightfield& hf, const FlythroughOptions& options = {},
                                      FlythroughLandmarks* landmarks = nullptr);

// The frames [first, first + length) played forwards, then backwards, `repeats` times (the viewer moving back and
// forth within one region, which a keyframe cache serves). Throws farfield::Error for an empty or out-of-range span.
std::vector<Viewpoint> backAndForth(const std::vector<Viewpoint>& path, size_t first, size_t length, int repeats);

}  // namespace farfield::terrain
