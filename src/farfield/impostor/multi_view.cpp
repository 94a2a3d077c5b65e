// Tecchia, Loscos and Chrysanthou 2002 (Steed's lecture part 3, "Crowd using impostors"): precomputed views per
// animation frame, the nearest one per agent.
#include "farfield/impostor/multi_view.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::impostor {

namespace {

Vec3 directionOf(float az, float el) {
  return Vec3(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
}

}  // namespace

Vec2 octahedralPoint(const Vec3& direction) {
  const Vec3 d(direction.x, direction.y, std::max(direction.z, 0.0f));
  const float l1 = std::abs(d.x) + std::abs(d.y) + d.z;
  if (!(l1 > 0.0f)) return Vec2(0.0f);
  const Vec2 p = Vec2(d.x, d.y) / l1;
  return Vec2(p.x + p.y, p.x - p.y);
}

Vec3 octahedralDirection(const Vec2& point) {
  const Vec2 q = glm::clamp(point, Vec2(-1.0f), Vec2(1.0f));
  const Vec2 p(0.5f * (q.x + q.y), 0.5f * (q.x - q.y));
  return glm::normalize(Vec3(p.x, p.y, std::max(0.0f, 1.0f - std::abs(p.x) - std::abs(p.y))));
}

Vec3 ViewGrid::direction(int cell) const {
  if (octahedral) {
    const float step = 2.0f / float(std::max(azimuths - 1, 1));
    return octahedralDirection(Vec2(-1.0f + step * float(cell % azimuths), -1.0f + step * float(cell / azimuths)));
  }
  return directionOf(azimuth(cell % azimuths), elevation(cell / azimuths));
}

int nearestView(const ViewGrid& grid, const Vec3& to_camera) {
  const Vec3 d = glm::normalize(to_camera);
  if (grid.octahedral) {
    const int n = grid.azimuths;
    const Vec2 f = (octahedralPoint(d) * 0.5f + 0.5f) * float(n - 1);
    const int col = int(std::lround(f.x)), row = int(std::lround(f.y));
    int best = -1;
    float best_dot = -2.0f;
    for (int r = std::max(row - 1, 0); r <= std::min(row + 1, n - 1); ++r)
      for (int c = std::max(col - 1, 0); c <= std::min(col + 1, n - 1); ++c) {
        const float dot = glm::dot(grid.direction(r * n + c), d);
        if (dot > best_dot) best_dot = dot, best = r * n + c;
      }
    return best;
  }
  float az = std::atan2(d.y, d.x);
  if (az < 0.0f) az += float(2.0 * kPi);
  const int ai = int(std::lround(az / float(2.0 * kPi) * float(grid.azimuths))) % grid.azimuths;
  // On a ring of fixed elevation the nearest view is the nearest azimuth; between the rings below and above the
  // direction's elevation, compare the two candidates exactly (further rings are further still).
  const float el = std::asin(std::clamp(d.z, -1.0f, 1.0f));
  const float step = grid.max_elevation / float(grid.elevations);
  const int below = std::clamp(int(std::floor(el / step)), 0, grid.elevations - 1);
  const int above = std::min(below + 1, grid.elevations - 1);
  const int a = below * grid.azimuths + ai, b = above * grid.azimuths + ai;
  return glm::dot(grid.direction(a), d) >= glm::dot(grid.direction(b), d) ? a : b;
}

float worstViewAngle(const ViewGrid& grid) {
  float worst = 0.0f;
  const int n = 256;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= n / 4; ++j) {
      const Vec3 d = directionOf(float(2.0 * kPi) * float(i) / float(n), grid.max_elevation * float(j) / float(n / 4));
      const float c = std::clamp(glm::dot(grid.direction(nearestView(grid, d)), d), -1.0f, 1.0f);
      worst = std::max(worst, std::acos(c));
    }
  return worst;
}

gpu::AtlasLayout atlasLayout(const Box3& bounds, const ViewGrid& grid, int frames, float texel_m) {
  if (!(texel_m > 0.0f) || frames < 1) throw Error("multi-view atlas", "texel size and frame count must be positive");
  if (grid.azimuths < 1 || grid.elevations < 1 || (grid.octahedral && (grid.azimuths < 2 || grid.azimuths != grid.elevations)))
    throw Error("multi-view atlas", "a grid needs at least one view; an octahedral one N x N views, N >= 2");
  gpu::AtlasLayout l;
  l.azimuths = grid.azimuths;
  l.max_elevation = grid.max_elevation;
  l.elevations = grid.elevations;
  l.octahedral = grid.octahedral;
  l.frames = frames;
  l.centre = bounds.center();
  const Vec3 half = bounds.hi - l.centre;
  // Seen from any azimuth the model stays within the vertical cylinder around the centre; from elevation e its
  // vertical extent is at most half.z cos e + r sin e.
  const float r = std::sqrt(half.x * half.x + half.y * half.y);
  float hh = 0.0f;
  for (int v = 0; v < grid.viewCount(); ++v) {
    const float e = std::asin(std::clamp(grid.direction(v).z, 0.0f, 1.0f));
    hh = std::max(hh, half.z * std::cos(e) + r * std::sin(e));
  }
  l.half_size = Vec2(r, hh) * 1.02f;
  l.radius = glm::length(half) * 1.02f;
  l.cell_width = std::max(4, int(std::ceil(2.0f * l.half_size.x / texel_m)));
  l.cell_height = std::max(4, int(std::ceil(2.0f * l.half_size.y / texel_m)));
  return l;
}

gpu::CaptureView captureView(const gpu::AtlasLayout& layout, const ViewGrid& grid, int cell) {
  gpu::CaptureView v;
  v.cell = cell;
  v.to_camera = grid.direction(cell);
  const Vec3 d = v.to_camera;
  // Same axes as the runtime quad (multiview.vert.glsl): right = z x d, up = d x right.
  Vec3 right = glm::cross(Vec3(0, 0, 1), d);
  right = glm::dot(right, right) < 1e-8f ? Vec3(1, 0, 0) : glm::normalize(right);
  const Vec3 up = glm::cross(d, right);
  const Vec3 eye = layout.centre + d * (2.0f * layout.radius);
  const Mat4 view = glm::lookAt(eye, layout.centre, up);
  const Mat4 ortho = glm::orthoRH_ZO(-layout.half_size.x, layout.half_size.x, -layout.half_size.y, layout.half_size.y,
                                     layout.radius * 0.999f, 3.0f * layout.radius * 1.001f);
  Mat4 reverse(1.0f);  // z' = w - z: reversed Z, as every Farfield pass
  reverse[2][2] = -1.0f;
  reverse[3][2] = 1.0f;
  v.view_proj = reverse * ortho * view;
  return v;
}

SwitchDistances switchDistances(const gpu::AtlasLayout& layout, float worst_view_angle, double focal_px,
                                double error_px, double frame_error_m) {
  SwitchDistances s;
  const double texel = 2.0 * double(layout.half_size.y) / double(layout.cell_height);
  s.texel_m = texel * focal_px;
  s.view_m = double(layout.half_size.x) * double(worst_view_angle) * focal_px / std::max(error_px, 1e-6);
  s.frame_m = frame_error_m * focal_px / std::max(error_px, 1e-6);
  return s;
}

double frameError(std::span<const std::vector<Vec3>> pose_positions, int frames) {
  const size_t poses = pose_positions.size();
  if (frames < 1 || poses == 0 || poses % size_t(frames) != 0)
    throw Error("multi-view frames", std::to_string(frames) + " frames do not divide " + std::to_string(poses) +
                                         " poses");
  double worst = 0.0;
  for (size_t p = 0; p < poses; ++p) {
    const size_t frame = size_t(std::lround(double(p) * double(frames) / double(poses))) % size_t(frames);
    const std::vector<Vec3>& a = pose_positions[p];
    const std::vector<Vec3>& b = pose_positions[frame * poses / size_t(frames)];
    if (a.size() != b.size()) throw Error("multi-view frames", "poses with different vertex counts");
    for (size_t v = 0; v < a.size(); ++v) worst = std::max(worst, double(glm::length(a[v] - b[v])));
  }
  return worst;
}

int framesForBound(std::span<const std::vector<Vec3>> pose_positions, double max_m) {
  const int poses = int(pose_positions.size());
  for (int f = 1; f < poses; ++f)
    if (poses % f == 0 && frameError(pose_positions, f) <= max_m) return f;
  return std::max(poses, 1);
}

BoundChoice chooseForBound(double error_px, double focal_px, double switch_m, double half_width_m,
                           float max_elevation, bool octahedral) {
  if (!(error_px > 0.0) || !(focal_px > 0.0) || !(switch_m > 0.0) || !(half_width_m > 0.0) || !(max_elevation > 0.0f))
    throw Error("multi-view bound", "error, focal length, switch distance and half width must be positive");
  BoundChoice c;
  c.texel_m = float(switch_m / focal_px);
  const double allowed = error_px * switch_m / (focal_px * half_width_m);
  if (octahedral) {
    // Neighbouring map points are at most about pi / (N - 1) apart (the map's edge, a quarter circle per N / 2 - 1/2
    // steps); start below and refine until the measured worst angle fits.
    for (int n = std::max(2, int(std::floor(kPi / 2.0 / allowed))); n < 4096; ++n) {
      c.grid = ViewGrid::octahedralGrid(n);
      if (double(worstViewAngle(c.grid)) <= allowed) break;
    }
    return c;
  }
  // Equal spacing s: the worst angle is s at the top ring's gap and s / sqrt(2) between four views; start from the
  // spacing equal to the allowed angle and refine until the measured worst angle fits.
  for (int n = std::max(1, int(std::ceil(double(max_elevation) / std::min(allowed, double(max_elevation))))); n < 4096;
       ++n) {
    c.grid.elevations = n;
    c.grid.max_elevation = max_elevation;
    c.grid.azimuths = std::max(3, int(std::ceil(2.0 * kPi / (double(max_elevation) / n))));
    if (double(worstViewAngle(c.grid)) <= allowed) break;
  }
  return c;
}

MultiViewImpostor bakeMultiView(gpu::CrowdRenderer& renderer, const gpu::SkinnedGpuModel& model,
                                const gpu::AtlasLayout& layout, const ViewGrid& grid) {
  if (layout.frames < 1 || model.poseCount() % uint32_t(layout.frames) != 0)
    throw Error("multi-view bake", std::to_string(model.poseCount()) + " palette poses are not a multiple of " +
                                       std::to_string(layout.frames) + " frames");
  Stopwatch clock;
  MultiViewImpostor out;
  out.grid = grid;
  out.worst_view_angle = worstViewAngle(grid);
  out.layout = layout;
  out.atlas = std::make_unique<gpu::ImpostorAtlasGpu>(layout);
  std::vector<gpu::CaptureView> views;
  for (int c = 0; c < grid.viewCount(); ++c) views.push_back(captureView(layout, grid, c));
  const uint32_t step = model.poseCount() / uint32_t(layout.frames);
  for (int f = 0; f < layout.frames; ++f) renderer.capture(model, uint32_t(f) * step, *out.atlas, f, views);
  renderer.finish();  // the bake time is the GPU's too
  out.bake_seconds = clock.seconds();
  return out;
}

}  // namespace farfield::impostor
