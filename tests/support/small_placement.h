// A small placement problem shared by the placement's and the viewer's tests: a 12-block city with one object per
// building, a hand-made cost profile (so the times are the model's, not this machine's noise) and placement options
// for 128x128 frames at 45 degrees under 2 px, with a t_max of 9 ms that only impostors can keep from some views.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "farfield/bake/place.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/core/object_fill.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::test {

inline gen::City smallPlacementCity() {
  gen::CityOptions o;
  o.blocks = 12;
  o.detail = 0;
  o.seed = 3;
  o.objects = gen::ObjectGrouping::Buildings;
  return gen::generateCity(o);
}

inline gpu::CostProfile handProfile() {
  gpu::CostProfile p;
  p.model.base_ms = 1.0;
  p.model.ms_per_draw = 0.25;
  p.model.ms_per_mtriangle = 10.0;
  p.safety_factor = 1.0;
  p.width = p.height = 128;
  p.fov_y_deg = 45.0;
  return p;
}

inline bake::PlaceOptions smallPlaceOptions(const scene::Scene& scene) {
  bake::PlaceOptions p;
  p.width = p.height = 128;
  p.fov_deg = 45.0f;
  p.error_px = 2.0;
  p.layered.texel_pixels = 2.0;
  p.layered.max_texture_size = 128;
  p.max_pitch_deg = 20.0f;
  p.visibility_face = 32;
  const Box3 b = scene.bounds();
  p.min_region_size = 0.26f * std::max(b.extent().x, b.extent().y);
  p.candidates.direction_step = float(degToRad(45.0));
  p.candidates.apex_angles = {float(degToRad(45.0)), float(degToRad(90.0))};
  p.candidates.distance_steps = 5;
  p.hierarchy.max_levels = 6;
  p.progress = false;
  p.t_max_ms = 9.0;
  return p;
}

// A walkthrough over the placement database in `dir`, with the runtime's defaults otherwise.
inline runtime::WalkthroughOptions placedWalkthroughOptions(const std::string& dir) {
  runtime::WalkthroughOptions options;
  options.database = dir;
  options.representation = runtime::Representation::Placed;
  return options;
}

// Frame f of `frames` of a walk across the placement's view space at mid height, turning slowly (128 x 128, 45
// degrees, as the placement's frames).
inline Camera viewSpaceWalkCamera(const Box3& space, int f, int frames) {
  const float t = float(f) / float(frames - 1);
  Camera camera;
  camera.eye = Vec3(space.lo.x + (space.hi.x - space.lo.x) * (0.1f + 0.8f * t),
                    space.lo.y + 0.5f * (space.hi.y - space.lo.y), 0.5f * (space.lo.z + space.hi.z));
  const float yaw = 0.3f + 2.5f * t;
  camera.at = camera.eye + Vec3(std::cos(yaw), std::sin(yaw), 0.0f);
  camera.width = camera.height = 128;
  camera.fov_y = float(degToRad(45.0));
  return camera;
}

// The fill term's workload of drawn items (gpu/cost_model.h): each scene object among them counted once, from the
// eye (core/object_fill.h). Impostor quads (ids past the scene's objects) have their own fill term.
inline double itemsFill(std::span<const gpu::DrawItem> items, const scene::Scene& scene, const Camera& camera) {
  const FillLens lens = FillLens::of(camera.width, camera.height, double(camera.fov_y));
  std::vector<uint32_t> ids;
  for (const gpu::DrawItem& item : items)
    if (item.object_id >= 1 && item.object_id <= scene.objects.size()) ids.push_back(item.object_id);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  double fill = 0.0;
  for (uint32_t id : ids) fill += lens.objectPixels(scene.objects[id - 1].world_bounds, camera.eye);
  return fill;
}

}  // namespace farfield::test
