// The layered impostor's draw and capture costs, fitted and validated on this machine: see layered_calibration.h.
//
// Why the draw term is per layer and per filled pixel: an alpha-tested layer runs its fragment shader over its whole
// quad, transparent texels included, so its cost is fill (the quads' screen area, overdrawn as many times as there
// are layers), not triangles; llvmpipe is fill bound. Why the capture term is per layer and per texel: a regeneration
// renders the cluster once per layer into a target of the layer's size, reads it back, crops and uploads it.
#include "farfield/eval/layered_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>

#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/progress.h"
#include "farfield/core/shaft.h"
#include "farfield/core/timer.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/gpu/render_target.h"
#include "farfield/impostor/layered_fill.h"

namespace farfield::eval {

namespace {

double objectRadius(const Box3& b) { return 0.5 * double(glm::length(b.extent())); }

}  // namespace

LayeredCalibrateResult calibrateLayered(gpu::Renderer& renderer, const gpu::GpuScene& gpu_scene,
                                        const scene::Scene& scene, const LayeredCalibrateOptions& o) {
  const char* where = "layered impostor calibration";
  if (o.fit_samples < 8) throw Error(where, "needs at least 8 fitting samples");
  if (o.validation_samples < 4) throw Error(where, "needs at least 4 validation samples");
  if (o.repeats < 1) throw Error(where, "repeats must be at least 1");
  if (o.max_cluster_objects < 1) throw Error(where, "max_cluster_objects must be at least 1");
  if (o.view_space.empty() || !isFinite(o.view_space.lo) || !isFinite(o.view_space.hi))
    throw Error(where, "the view space is empty or not finite");
  const ErrorBound bound{o.error_px, o.width, o.height, degToRad(double(o.fov_deg))};
  bound.validate(where);
  Stopwatch wall;

  std::vector<uint32_t> usable;  // objects that may seed or join a cluster
  for (const scene::Object& obj : scene.objects)
    if (!obj.world_bounds.empty() && objectRadius(obj.world_bounds) <= 0.5 * o.max_object_size &&
        !obj.parts.empty())
      usable.push_back(obj.id);
  if (usable.empty()) throw Error(where, "the scene has no object small enough to be an impostor's cluster");
  const std::vector<gpu::ObjectDrawCost> costs = gpu_scene.objectDrawCosts();

  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  gpu::RenderTarget target(o.width, o.height);
  LayeredCalibrateResult result;
  const size_t wanted = o.fit_samples + o.validation_samples;
  Progress progress("calibrate: layered impostors", wanted);
  bool warmed = false;
  const float angles[] = {11.25f, 22.5f, 45.0f, 90.0f};
  size_t attempts = 0;
  while (result.fit.size() + result.checks.size() < wanted) {
    if (++attempts > 20 * wanted + 100) throw Error(where, "too few clusters of the scene have a layered plan");
    // A cluster: a random object and its nearest neighbours within a random radius.
    const uint32_t seed_id = usable[size_t(u(rng) * float(usable.size())) % usable.size()];
    const Vec3 c0 = scene.objects[seed_id - 1].world_bounds.center();
    const float reach = u(rng) * o.max_cluster_radius;
    std::vector<std::pair<float, uint32_t>> near;
    for (uint32_t id : usable) {
      const float d = glm::length(scene.objects[id - 1].world_bounds.center() - c0);
      if (d <= reach) near.push_back({d, id});
    }
    std::sort(near.begin(), near.end());
    if (near.size() > size_t(o.max_cluster_objects)) near.resize(size_t(o.max_cluster_objects));
    std::vector<uint32_t> ids;
    Box3 box;
    uint64_t triangles = 0;
    for (const auto& [d, id] : near) {
      ids.push_back(id);
      box.expand(scene.objects[id - 1].world_bounds);
      triangles += costs[id].triangles;
    }
    std::sort(ids.begin(), ids.end());
    // A shaft from the cluster towards a random eye of the view space, its minimum distance the eye's (at least
    // 1.5 radii, so that it clears the cluster).
    const Vec3 eye = o.view_space.lo + (o.view_space.hi - o.view_space.lo) * Vec3(u(rng), u(rng), u(rng));
    const Vec3 centre = box.center();
    Vec3 axis = eye - centre;
    if (glm::length(axis) < 1e-3f) continue;
    axis = glm::normalize(axis);
    const float radius = float(objectRadius(box));
    const float distance = std::max(glm::length(eye - centre), 1.5f * radius + 1.0f);
    const float apex = float(degToRad(double(angles[size_t(u(rng) * 4.0f) % 4])));
    impostor::LayeredPlan plan;
    try {
      const Shaft shaft = Shaft::make(centre, axis, apex, distance, where);
      plan = impostor::planLayered(box, shaft, bound, o.layered);
    } catch (const Error&) {
      ++result.skipped;
      continue;
    }
    if (!plan.keepsBound()) {
      ++result.skipped;
      continue;
    }
    if (!warmed) {  // the first capture and draw pay one-off driver costs: untimed
      const impostor::GpuLayeredImpostor first(
          impostor::cropLayered(impostor::captureLayered(renderer, gpu_scene, ids, plan)));
      warmed = true;
    }
    LayeredSample s;
    s.triangles = triangles * plan.layers.size();
    s.layers = plan.quads();
    s.texels = plan.texels;
    Stopwatch capture;
    impostor::LayeredImpostor cut = impostor::cropLayered(impostor::captureLayered(renderer, gpu_scene, ids, plan));
    if (!o.layer_tiles) impostor::coverWholeQuads(cut.plan);
    const impostor::GpuLayeredImpostor gpu(cut, o.layer_tiles ? impostor::LayerDraw::Tiles
                                                               : impostor::LayerDraw::WholeQuads);
    s.capture_ms = capture.milliseconds();
    // The view: the capture eye (fitting) or a random viewpoint of the shaft up to twice its minimum distance
    // (validation), looking at the cluster.
    const bool fitting = result.fit.size() < o.fit_samples;
    Camera view;
    view.eye = fitting ? plan.capture_eye : plan.shaft.sample(u(rng), u(rng), u(rng), 2.0f * distance);
    view.at = centre;
    view.up = plan.camera_up;
    view.width = o.width;
    view.height = o.height;
    view.fov_y = float(degToRad(double(o.fov_deg)));
    view.near_plane = 0.5f;
    view.far_plane = 20000.0f;
    std::vector<gpu::DrawItem> items, other_items;
    gpu.appendDrawItems(items);
    const impostor::GpuLayeredImpostor other(cut, o.layer_tiles ? impostor::LayerDraw::WholeQuads
                                                                 : impostor::LayerDraw::Tiles);
    other.appendDrawItems(other_items);
    double with = std::numeric_limits<double>::infinity(), without = with, with_other = with;
    for (int r = 0; r < o.repeats; ++r) {
      without = std::min(without, renderer.render(view, {}, target).wall_ms);
      with = std::min(with, renderer.render(view, items, target).wall_ms);
      with_other = std::min(with_other, renderer.render(view, other_items, target).wall_ms);
    }
    s.draw_other_ms = std::max(0.0, with_other - without);
    s.view = view;
    // The fill of what is drawn: the cropped quads' tiles.
    s.fill_pixels = impostor::layeredFillPixels(cut.plan, double(glm::length(view.eye - plan.shaft.apex)), bound);
    s.draw_ms = std::max(0.0, with - without);
    (fitting ? result.fit : result.checks).push_back(s);
    if (o.progress) progress.advance();
  }
  progress.finish();

  std::vector<gpu::CostSample> draw, capture;
  for (const LayeredSample& s : result.fit) {
    draw.push_back({0.0, double(s.layers), s.fill_pixels, s.draw_ms});
    capture.push_back({double(s.triangles), double(s.layers), double(s.texels), s.capture_ms});
  }
  gpu::LayeredCost& cost = result.cost;
  cost.calibrated = true;
  cost.draw = gpu::CostModel::fit(draw);
  cost.capture = gpu::CostModel::fit(capture);
  std::vector<double> draw_ratios, capture_ratios;
  for (LayeredSample& s : result.checks) {
    s.draw_predicted_ms = cost.draw.predict(0.0, double(s.layers), s.fill_pixels);
    s.capture_predicted_ms = cost.capture.predict(double(s.triangles), double(s.layers), double(s.texels));
    draw_ratios.push_back(s.draw_ms / std::max(s.draw_predicted_ms, o.noise_floor_ms));
    capture_ratios.push_back(s.capture_ms / std::max(s.capture_predicted_ms, o.noise_floor_ms));
  }
  result.draw_ratio_p50 = percentile(draw_ratios, 50.0);
  result.draw_ratio_p95 = percentile(draw_ratios, 95.0);
  result.draw_ratio_max = percentile(draw_ratios, 100.0);
  result.capture_ratio_p50 = percentile(capture_ratios, 50.0);
  result.capture_ratio_p95 = percentile(capture_ratios, 95.0);
  result.capture_ratio_max = percentile(capture_ratios, 100.0);
  std::vector<double> tiles_over_whole;
  double tiles_sum = 0.0, whole_sum = 0.0;
  for (const std::vector<LayeredSample>* set : {&result.fit, &result.checks})
    for (const LayeredSample& s : *set) {
      const double tiles = o.layer_tiles ? s.draw_ms : s.draw_other_ms;
      const double whole = o.layer_tiles ? s.draw_other_ms : s.draw_ms;
      tiles_over_whole.push_back(std::max(tiles, o.noise_floor_ms) / std::max(whole, o.noise_floor_ms));
      tiles_sum += tiles;
      whole_sum += whole;
    }
  result.tiles_over_whole_p50 = percentile(tiles_over_whole, 50.0);
  result.tiles_over_whole_sum = whole_sum > 0.0 ? tiles_sum / whole_sum : 1.0;
  cost.draw_safety_factor = std::max(1.0, result.draw_ratio_max);
  cost.capture_safety_factor = std::max(1.0, result.capture_ratio_max);
  // A prediction below the noise floor is bounded by the floor times the factor (see the ratios above).
  cost.validation = {{"fit_samples", result.fit.size()},
                     {"validation_samples", result.checks.size()},
                     {"repeats", o.repeats},
                     {"seed", o.seed},
                     {"error_px", o.error_px},
                     {"noise_floor_ms", o.noise_floor_ms},
                     {"draw_ratio_p50", result.draw_ratio_p50},
                     {"draw_ratio_p95", result.draw_ratio_p95},
                     {"draw_ratio_max", result.draw_ratio_max},
                     {"capture_ratio_p50", result.capture_ratio_p50},
                     {"capture_ratio_p95", result.capture_ratio_p95},
                     {"capture_ratio_max", result.capture_ratio_max},
                     {"fill_over", o.layer_tiles ? "tiles" : "whole quads"},
                     {"tiles_over_whole_draw_p50", result.tiles_over_whole_p50},
                     {"tiles_over_whole_draw_sum", result.tiles_over_whole_sum}};
  result.wall_s = wall.seconds();
  return result;
}

}  // namespace farfield::eval
