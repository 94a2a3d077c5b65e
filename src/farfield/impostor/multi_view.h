// Precomputed multi-view impostors for animated crowds: Tecchia, Loscos and Chrysanthou 2002, as in Steed's lecture
// part 3, "Crowd using impostors" (32 azimuths x 8 elevations per animation frame, the best view chosen per agent).
//
// Views lie on a grid of azimuths (full circle, azimuth 0 = the agent's +x, its facing) and elevations (0 up to
// below max_elevation, evenly spaced), or, as an option, on an N x N grid of the upper hemisphere's octahedral map
// (the layout of octahedral impostors: views spread evenly over the hemisphere, no crowding at the zenith; the
// four around a direction are the corners of its map square). Each view is an orthographic image of the model, centred on its capture centre,
// of a fixed world extent (half_size) for every view so that one quad size fits all; an atlas layer holds every view
// of one animation frame. Pure functions here (views, selection, error and memory estimates); the bake renders with
// gpu::CrowdRenderer.
#pragma once

#include <algorithm>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/gpu/crowd_renderer.h"

namespace farfield::impostor {

struct ViewGrid {
  int azimuths = 32;
  int elevations = 8;
  float max_elevation = float(kPi / 2);  // radians: elevations j * max_elevation / elevations, j = 0..elevations-1
  // Octahedral: azimuths = elevations = N (>= 2) are the map's columns and rows; view (row, column) looks from the
  // hemisphere direction of map point (-1 + 2 column / (N - 1), -1 + 2 row / (N - 1)) (octahedralDirection), the
  // map's edge being the horizon. max_elevation is then pi / 2.
  bool octahedral = false;

  static ViewGrid octahedralGrid(int n) { return ViewGrid{n, n, float(kPi / 2), true}; }
  int viewCount() const { return azimuths * elevations; }
  float azimuth(int i) const { return float(2.0 * kPi) * float(i) / float(azimuths); }
  float elevation(int j) const { return max_elevation * float(j) / float(elevations); }
  // Unit direction from the agent towards the camera of view `cell` (elevation * azimuths + azimuth), agent space.
  Vec3 direction(int cell) const;
};

// The upper hemisphere's octahedral map: a direction (z < 0 taken as its horizontal part) to its point in [-1, 1]^2
// (p = (x, y) / (|x| + |y| + z), then (p.x + p.y, p.x - p.y): the horizon is the square's edge, the zenith its
// centre), and back (unit length). multiview.vert.glsl computes the same map.
Vec2 octahedralPoint(const Vec3& direction);
Vec3 octahedralDirection(const Vec2& point);

// The view whose direction is nearest (largest dot product) to the unit direction `to_camera` (agent space): the
// nearest azimuth on the two elevation rings around the direction's elevation, compared exactly; on an octahedral
// grid the nearest of the 3 x 3 views around the direction's map point.
int nearestView(const ViewGrid& grid, const Vec3& to_camera);

// Largest angle (radians) between a direction with elevation in [0, max_elevation] and its nearest view, sampled
// densely (a bound on the view quantisation the impostor shows). About 16,000 samples: a few milliseconds, so
// callers keep it (MultiViewImpostor::worst_view_angle) rather than call it per frame.
float worstViewAngle(const ViewGrid& grid);

// The atlas for a model whose animated bounds (agent space: feet on z = 0, facing +x) are `bounds`: cells tall
// enough that the texel is `texel_m` metres, each cell's world extent covering the model from every view of the grid.
gpu::AtlasLayout atlasLayout(const Box3& bounds, const ViewGrid& grid, int frames, float texel_m);

// Orthographic capture of view `cell` for the layout (reversed Z, depth range around the centre +- radius).
gpu::CaptureView captureView(const gpu::AtlasLayout& layout, const ViewGrid& grid, int cell);

// Distances (metres) beyond which an impostor keeps a promise, for a camera of `focal_px` (pixels per unit of
// tangent, height / (2 tan(fov_y / 2))): Dobbyn et al.'s rule, a texel covers at most one pixel (texel_m *
// focal_px); the view error stays under `error_px` (the model's half width moves by at most radius *
// worst_view_angle, the grid's worstViewAngle); and the animation frame's error (frame_error_m, frameError below: a
// vertex's distance to where the geometry shows it) stays under `error_px`.
struct SwitchDistances {
  double texel_m = 0.0;
  double view_m = 0.0;
  double frame_m = 0.0;
  double both() const { return std::max({texel_m, view_m, frame_m}); }
};
SwitchDistances switchDistances(const gpu::AtlasLayout& layout, float worst_view_angle, double focal_px,
                                double error_px, double frame_error_m = 0.0);

// Animation frames from the error bound. pose_positions[p]: the model's vertices (agent space, metres) in palette
// pose p of P (one walk cycle, evenly spaced; the same vertex count each). frameError: the largest distance between
// a vertex in pose p and in the pose the impostor shows for it (frame round(p * frames / P) mod frames, palette pose
// frame * P / frames), over every p and vertex; frames must divide P (throws farfield::Error otherwise).
// framesForBound: the fewest frames among the divisors of P whose frameError is at most max_m (P when none is).
double frameError(std::span<const std::vector<Vec3>> pose_positions, int frames);
int framesForBound(std::span<const std::vector<Vec3>> pose_positions, double max_m);

// Views and texel size chosen from the error bound instead of fixed numbers: for impostors drawn from `switch_m`
// metres on (a camera of `focal_px`), the texel that covers one pixel there (Dobbyn's rule: switch_m / focal_px) and
// the coarsest grid of equal azimuth and elevation spacing whose worst view angle keeps a model of half width
// `half_width_m` within `error_px` there (worstViewAngle(grid) <= error_px * switch_m / (focal_px * half_width_m)).
// Throws farfield::Error for non-positive arguments.
struct BoundChoice {
  ViewGrid grid;
  float texel_m = 0.0f;
};
// With `octahedral`, the coarsest N x N octahedral grid that keeps it.
BoundChoice chooseForBound(double error_px, double focal_px, double switch_m, double half_width_m,
                           float max_elevation = float(kPi / 2), bool octahedral = false);

// A baked model: layout, grid and the atlas on the GPU.
struct MultiViewImpostor {
  ViewGrid grid;
  float worst_view_angle = 0.0f;  // worstViewAngle(grid), radians
  gpu::AtlasLayout layout;
  std::unique_ptr<gpu::ImpostorAtlasGpu> atlas;
  double bake_seconds = 0.0;
  size_t byteSize() const { return atlas ? atlas->byteSize() : 0; }
};

// Renders every view of every frame: frame f shows palette pose f * model.poseCount() / layout.frames (the pose
// count must be a multiple of the frame count; throws farfield::Error otherwise). Needs a current context.
MultiViewImpostor bakeMultiView(gpu::CrowdRenderer& renderer, const gpu::SkinnedGpuModel& model,
                                const gpu::AtlasLayout& layout, const ViewGrid& grid);

}  // namespace farfield::impostor
