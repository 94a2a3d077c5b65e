// Section 5.5 of Decoret et al. 1999 in the cell walkthrough (Representation::MmiDynamic): dynamic impostors dropped
// under fast motion or when stale, and updated in decreasing error angle while they fit in the frame budget.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "farfield/core/error_bound.h"
#include "farfield/core/timer.h"
#include "farfield/runtime/walkthrough_cells.h"

namespace farfield::runtime {

// Section 5.5, first step: fast motion drops every dynamic impostor; a kept one must still cover the view and stay
// under its error angle.
void Walkthrough::dropStaleDynamic(const Camera& camera, Cell& cell) {
  dynamic_threshold_rad_ = ErrorBound::forCamera(options_.dynamic_error_px, camera).angle();
  const double threshold = dynamic_threshold_rad_;
  // Fast motion: the error a fresh impostor of the nearest layer would gather per frame at this speed.
  bool fast = false;
  if (has_previous_) {
    double growth = 0.0;
    for (const Layer& layer : cell.layers) growth = std::max(growth, errorAngle(previous_eye_, camera.eye, layer.bounds));
    fast = growth * options_.min_lifetime_frames > threshold;
  }
  previous_eye_ = camera.eye;
  has_previous_ = true;
  if (fast) {
    ++stats_.fast_frames;
    for (Layer& layer : cell.layers) layer.dynamic.reset();
  }
  for (Layer& layer : cell.layers)
    if (layer.dynamic && (!layer.dynamic->covers(camera) || layer.dynamic->errorAngle(camera.eye) > threshold))
      layer.dynamic.reset();
  fast_ = fast;
  plan_.report.fast_motion = fast;
}

// Section 5.5, second step: the prediction of this frame's cost, then updates in decreasing error angle while they
// fit in what is left of the budget. An update is drawn from the next frame on (this frame's plan is made).
void Walkthrough::updateDynamic(const Camera& camera, Cell& cell, const std::function<void()>& before_gpu_work) {
  if (fast_) return;
  FrameReport& report = plan_.report;
  const double threshold = dynamic_threshold_rad_;
  double triangles = double(report.geometry_triangles);
  double draws = double(plan_.items.size());
  for (const LayerDecision& decision : plan_.layers) {
    if (std::holds_alternative<LayerAsGeometry>(decision)) continue;
    const Layer& layer = cell.layers[layerOf(decision)];
    if (layer.dynamic) {
      triangles += double(layer.dynamic->triangleCount());
      draws += 1.0;
    } else {
      for (const auto& view : layer.views) triangles += double(view->triangleCount());
      draws += double(layer.views.size());
    }
  }
  const double pixels = double(camera.width) * double(camera.height);
  const double predicted = cost_.predict(triangles, draws, pixels);
  report.predicted_ms = predicted;
  report.over_budget = predicted > options_.frame_budget_ms;
  if (report.over_budget) ++stats_.over_budget_frames;
  stats_.predicted_ms += predicted;
  ++stats_.predicted_frames;
  double left = options_.frame_budget_ms - predicted;

  // Candidates: layers whose drawn representation is off by more than the threshold, worst first.
  std::vector<std::pair<double, size_t>> candidates;
  for (size_t l = 0; l < cell.layers.size(); ++l) {
    const Layer& layer = cell.layers[l];
    double error = 0.0;
    if (layer.dynamic) {
      error = layer.dynamic->errorAngle(camera.eye);
    } else {
      error = std::numeric_limits<double>::infinity();
      for (const Vec3& eye : layer.view_eyes) error = std::min(error, errorAngle(eye, camera.eye, layer.bounds));
      if (layer.view_eyes.empty()) error = 0.0;  // nothing of it in the baked views: nothing to refresh
    }
    if (error > threshold) candidates.emplace_back(error, l);
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first; });

  const Camera capture = DynamicImpostor::captureCamera(camera, options_.dynamic);
  const Frustum frustum = Frustum::fromMatrix(capture.viewProjection());
  const double capture_pixels = double(capture.width) * double(capture.height);
  bool started = false;
  for (const auto& [error, l] : candidates) {
    if (report.updates >= options_.max_updates) break;
    Layer& layer = cell.layers[l];
    ids_.clear();
    uint64_t layer_triangles = 0;
    for (uint32_t id : layer.objects)
      if (frustum.intersects(scene_.objects[id - 1].world_bounds)) {
        ids_.push_back(id);
        layer_triangles += object_triangles_[id];
      }
    if (ids_.empty()) continue;
    std::vector<gpu::DrawItem> items;
    gpu_scene_.appendDrawItems(ids_, items);
    const double cost =
        cost_.predict(double(layer_triangles), double(items.size()), capture_pixels) + update_overhead_ms_;
    if (cost > left) {
      ++stats_.skipped_for_budget;
      continue;
    }
    if (!started && before_gpu_work) before_gpu_work();
    started = true;
    layer.dynamic = std::make_unique<DynamicImpostor>(renderer_, items, camera, layer.bounds, options_.dynamic);
    const double actual = layer.dynamic->updateMs();
    // What the model does not see (readback, quantisation, meshing, upload), learnt as a running mean.
    const double render_part = cost - update_overhead_ms_;
    update_overhead_ms_ = stats_.updates == 0 ? std::max(0.0, actual - render_part)
                                              : 0.8 * update_overhead_ms_ + 0.2 * std::max(0.0, actual - render_part);
    stats_.predicted_update_error_ms += std::abs(actual - cost);
    left -= actual;
    ++report.updates;
    ++stats_.updates;
    stats_.update_ms_total += actual;
    stats_.update_ms_max = std::max(stats_.update_ms_max, actual);
    report.update_stats.triangles += layer_triangles;
    report.update_stats.draw_calls += uint32_t(items.size());
    report.update_stats.objects += uint32_t(ids_.size());
  }
}

}  // namespace farfield::runtime
