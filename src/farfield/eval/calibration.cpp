#include "farfield/eval/calibration.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <random>
#include <span>

#include "farfield/core/error.h"
#include "farfield/core/object_fill.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/eval/mode.h"
#include "farfield/eval/plan_geometry.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/bvh.h"

namespace farfield::eval {

namespace {

// The geometry pass over a list of objects, as the walkthrough draws a plan's geometry (eval/plan_geometry.h): on the
// GPU (gpu::GpuCuller), or on the CPU (clusters in the frustum, occlusion-culled or not) as the context's options say.
class RuntimeGeometry final : public Mode {
 public:
  explicit RuntimeGeometry(const ModeContext& context) : geometry_(context, "calibrate") { geometry_.prepare(context); }
  std::string name() const override { return "runtime-geometry"; }
  void frame(FrameContext& frame) override { geometry_.submitObjects(frame, ids); }
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override {
    return geometry_.lateFrameStats(path_frame);
  }
  std::vector<uint32_t> ids;  // the next frame's objects, ascending

 private:
  PlanGeometry geometry_;
};

}  // namespace

gpu::CostModel fitWithFillCap(std::span<const gpu::CostSample> samples, double frame_pixels,
                              std::span<const double> bounded_fill) {
  if (!bounded_fill.empty() && bounded_fill.size() != samples.size())
    throw Error("cost model", std::to_string(bounded_fill.size()) + " bounded fills for " +
                                  std::to_string(samples.size()) + " samples");
  // The model at a cap (0: none), fitted on every sample but those of fold `skip` (sample i is in fold i % kFolds;
  // -1: all of them).
  const auto fitAt = [&](double cap, int skip) {
    std::vector<gpu::CostSample> kept;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (int(i % kFillCapFolds) == skip) continue;
      kept.push_back(samples[i]);
      if (cap > 0.0) kept.back().fill = std::min(kept.back().fill, cap);
    }
    gpu::CostModel m = gpu::CostModel::fit(kept);
    m.fill_cap_pixels = cap;
    return m;
  };
  // A cap's score, out of sample: each fold bounded by the model fitted on the others, with the factor and margin
  // that model leaves on the fold, summed over the fold's bounded workloads.
  const auto heldOutBound = [&](double cap) {
    double sum = 0.0;
    for (int fold = 0; fold < int(kFillCapFolds); ++fold) {
      const gpu::CostModel m = fitAt(cap, fold);
      double factor = 1.0, margin = 0.0;
      for (size_t i = size_t(fold); i < samples.size(); i += kFillCapFolds) {
        const gpu::CostSample& s = samples[i];
        const double predicted = m.predict(s.triangles, s.draw_calls, s.pixels, s.fill);
        factor = std::max(factor, s.ms / std::max(predicted, 1e-6));
        margin = std::max(margin, s.ms - predicted);
      }
      for (size_t i = size_t(fold); i < samples.size(); i += kFillCapFolds) {
        const gpu::CostSample& s = samples[i];
        const double predicted =
            m.predict(s.triangles, s.draw_calls, s.pixels, bounded_fill.empty() ? s.fill : bounded_fill[i]);
        sum += std::min(predicted * factor, predicted + margin);
      }
    }
    return sum;
  };
  double best_cap = 0.0, best_score = heldOutBound(0.0);
  for (double frames : {2.0, 3.0, 4.0, 6.0, 8.0}) {
    const double score = heldOutBound(frames * frame_pixels);
    if (score < best_score * (1.0 - 1e-12)) best_cap = frames * frame_pixels, best_score = score;
  }
  return fitAt(best_cap, -1);
}

std::vector<Camera> randomViews(const Box3& view_space, size_t count, uint32_t seed, int width, int height,
                                float fov_deg, float near_plane, float far_plane) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Camera> out;
  out.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    Camera c;
    c.eye = view_space.lo + (view_space.hi - view_space.lo) * Vec3(u(rng), u(rng), u(rng));
    const float yaw = float(2.0 * kPi) * u(rng);
    const float pitch = float(degToRad(10.0)) * (2.0f * u(rng) - 1.0f);
    c.at = c.eye + Vec3(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), std::sin(pitch));
    c.width = width;
    c.height = height;
    c.fov_y = float(degToRad(double(fov_deg)));
    c.near_plane = near_plane;
    c.far_plane = far_plane;
    out.push_back(c);
  }
  return out;
}

Box3 defaultViewSpace(const scene::Scene& scene) {
  const Box3 b = scene.bounds();
  if (b.empty()) throw Error("view space", "the scene is empty");
  const float z = b.lo.z + 1.7f;
  return Box3::fromPoints(Vec3(b.lo.x, b.lo.y, z), Vec3(b.hi.x, b.hi.y, z + 0.01f));
}

CalibrateResult calibrate(gpu::Context& context, const scene::Scene& scene, const CalibrateOptions& options) {
  const char* where = "calibrate";
  if (options.views < 8) throw Error("--views", "need at least 8 validation views, got " + std::to_string(options.views));
  if (options.repeats < 1) throw Error("--repeats", "must be at least 1");
  if (options.fit_views < 8) throw Error("--fit-views", "need at least 8 fitting views");
  if (!(options.margin_quantile > 0.0 && options.margin_quantile <= 1.0))
    throw Error("--margin-quantile", "must be in (0, 1]");
  if (options.width < 8 || options.height < 8 || options.width > 8192 || options.height > 8192)
    throw Error("--size", "must be 8..8192 pixels per side");
  if (!(options.fov_deg > 1.0f && options.fov_deg < 170.0f)) throw Error("--fov", "must be in (1, 170) degrees");
  if (scene.objects.empty()) throw Error(where, "the scene has no objects");
  const Box3 space = options.view_space.empty() ? defaultViewSpace(scene) : options.view_space;
  if (!isFinite(space.lo) || !isFinite(space.hi)) throw Error("--view-space", "is not finite");

  Stopwatch wall;
  context.makeCurrent();
  CalibrateResult result;
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  gpu::RenderTarget target(options.width, options.height);

  // Fitting views, then validation views: both random views of the view space drawn the way a walkthrough draws them
  // (frustum-culled geometry), so the fit sees the overdraw and clipping of the frames it must predict (workloads
  // timed from overviews mispredicted street views by 3.5x on llvmpipe).
  gpu::CostProfile& profile = result.profile;
  profile.width = options.width;
  profile.height = options.height;
  profile.fov_y_deg = options.fov_deg;
  profile.renderer = context.description();
  const double pixels = double(options.width) * double(options.height);
  const FillLens fill_lens = FillLens::of(options.width, options.height, degToRad(double(options.fov_deg)));
  std::vector<uint32_t> ids;
  std::vector<gpu::DrawItem> items;
  const bool placed = bool(options.visible_set);
  // The runtime's frames are counted as placement counts a view: whole objects.
  const bool whole_objects = placed || options.gpu_frames;
  const std::vector<gpu::ObjectDrawCost> object_cost =
      whole_objects ? gpu_scene.objectDrawCosts() : std::vector<gpu::ObjectDrawCost>{};
  // The frames timed: the runtime's GPU-driven ones, or the CPU-culled ones of before (placed frames occlusion-culled,
  // the others frustum-culled clusters). The context holds the arena the GPU frames draw (alive as long as they are).
  ModeContext mode_context;
  mode_context.scene = &scene;
  mode_context.gpu_scene = &gpu_scene;
  mode_context.bvh = &bvh;
  mode_context.renderer = &renderer;
  mode_context.width = options.width;
  mode_context.height = options.height;
  // Occlusion culling on in every GPU-driven frame: the walkthrough modes' gpu_occlusion=auto keeps it off only where
  // their frames measure faster without it, so the model is fitted on the slower of the two where they differ.
  mode_context.options = {{"geometry", options.gpu_frames ? "gpu" : "cpu"},
                          {"occlusion", options.gpu_frames || placed ? "on" : "off"},
                          {"gpu_occlusion", "on"}};
  RuntimeGeometry geometry(mode_context);
  FrameRunner runner(renderer, target);
  // A view's workload, counted once: the objects it draws (returned in `view_ids`) and their triangles, draw calls and
  // estimated fill, as the model counts them.
  const auto workload = [&](const Camera& camera, std::vector<uint32_t>& view_ids) {
    view_ids.clear();
    bvh.queryFrustum(Frustum::fromMatrix(camera.viewProjection()), view_ids);
    std::sort(view_ids.begin(), view_ids.end());
    ViewCheck check;
    check.camera = camera;
    if (placed) {
      if (const std::vector<uint32_t>* visible = options.visible_set(camera.eye)) {
        std::vector<uint32_t> kept;
        std::set_intersection(view_ids.begin(), view_ids.end(), visible->begin(), visible->end(),
                              std::back_inserter(kept));
        view_ids.swap(kept);
      }
    }
    if (whole_objects) {
      for (uint32_t id : view_ids) {
        check.triangles += object_cost[id].triangles;
        check.draw_calls += object_cost[id].draws;
      }
    } else {
      items.clear();
      if (!view_ids.empty()) gpu_scene.appendDrawItems(view_ids, items, camera);
      for (const gpu::DrawItem& item : items) check.triangles += item.triangleCount();
      check.draw_calls = items.size();
    }
    const std::optional<Box3> region = options.region_of ? options.region_of(camera.eye) : std::nullopt;
    for (uint32_t id : view_ids) {
      const Box3& bounds = scene.objects[id - 1].world_bounds;
      check.fill += fill_lens.objectPixels(bounds, camera.eye);
      if (region) check.region_fill += fill_lens.objectPixels(bounds, *region);
    }
    if (!region) check.region_fill = check.fill;
    return check;
  };
  // One timed render of a view's objects. A GPU-driven one after an untimed one of the same view, so that the
  // culler's last-frame visibility is the view's own (a walkthrough's consecutive frames see nearly the same) and no
  // object list is sent in the timed one.
  const auto render = [&](const Camera& camera, const std::vector<uint32_t>& view_ids) {
    geometry.ids = view_ids;
    if (options.gpu_frames) runner.run(geometry, camera, 0);
    return runner.run(geometry, camera, 0);
  };
  // Every view rendered once, then again in further passes over all of them, the fastest render kept: a view's
  // renders are a pass apart (seconds), so a slow spell of the machine does not slow all of them. The fitting and the
  // validation views are rendered in the same passes, in an order shuffled per pass, so that both sample the
  // machine's state alike. Measured one set after the other, a calibration's validation views took 1.18x their
  // prediction at the median (0.93-0.99 in the calibrations before it on the same views), and the safety factor
  // (2.50 against 1.66-1.88) took the machine's change between the two sets in as the model's error.
  const std::vector<Camera> fit_views = randomViews(space, options.fit_views, options.seed ^ 0x9e3779b9u, options.width,
                                                    options.height, options.fov_deg, options.near_plane,
                                                    options.far_plane);
  const std::vector<Camera> views = randomViews(space, options.views, options.seed, options.width, options.height,
                                                options.fov_deg, options.near_plane, options.far_plane);
  std::vector<Camera> cameras = fit_views;
  cameras.insert(cameras.end(), views.begin(), views.end());
  std::vector<ViewCheck> checks;
  std::vector<std::vector<uint32_t>> view_ids(cameras.size());
  for (size_t i = 0; i < cameras.size(); ++i) checks.push_back(workload(cameras[i], view_ids[i]));
  std::vector<size_t> order(cameras.size());
  std::mt19937 shuffle_rng(options.seed + 0x51u);
  for (int r = 0; r < options.repeats; ++r) {
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), shuffle_rng);
    Progress progress("calibrate: fitting and validation views, pass " + std::to_string(r + 1) + " of " +
                          std::to_string(options.repeats),
                      cameras.size());
    for (size_t i : order) {
      const FrameRecord frame = render(cameras[i], view_ids[i]);
      ViewCheck& c = checks[i];
      c.measured_ms = r == 0 ? frame.wall_ms : std::min(c.measured_ms, frame.wall_ms);
      c.measured_cpu_ms = r == 0 ? frame.cpu_ms : std::min(c.measured_cpu_ms, frame.cpu_ms);
      c.measured_gpu_ms = r == 0 ? frame.gpu_ms : std::min(c.measured_gpu_ms, frame.gpu_ms);
      c.drawn_triangles = frame.triangles;  // the GPU culler's count of this frame (FrameRunner, after its wait)
      if (options.progress) progress.advance();
    }
    progress.finish();
  }
  {
    std::vector<gpu::CostSample> samples;
    std::vector<double> region_fills;
    for (size_t i = 0; i < fit_views.size(); ++i) {
      const ViewCheck& c = checks[i];
      const double fill = options.fill_term ? c.fill : 0.0;
      samples.push_back({double(c.triangles), double(c.draw_calls), pixels, c.measured_ms, fill});
      region_fills.push_back(c.region_fill);
    }
    profile.model = options.fill_term ? fitWithFillCap(samples, pixels, region_fills) : gpu::CostModel::fit(samples);
  }
  // The CPU and GPU terms, each fitted on its own measurements of the fitting views (the fill as the wall model has it,
  // uncapped); the GPU term's triangles are those drawn after culling.
  const auto fitTerm = [&](double ViewCheck::*measured, auto&& triangles) {
    std::vector<gpu::CostSample> samples;
    for (size_t i = 0; i < fit_views.size(); ++i) {
      const ViewCheck& c = checks[i];
      samples.push_back({triangles(c), double(c.draw_calls), pixels, std::max(0.0, c.*measured),
                         options.fill_term ? c.fill : 0.0});
    }
    return gpu::CostModel::fit(samples);
  };
  const auto counted = [](const ViewCheck& c) { return double(c.triangles); };
  const auto drawn = [](const ViewCheck& c) { return double(c.drawn_triangles); };
  result.cpu.model = fitTerm(&ViewCheck::measured_cpu_ms, counted);
  result.gpu.model = fitTerm(&ViewCheck::measured_gpu_ms, drawn);
  result.checks.assign(checks.begin() + std::ptrdiff_t(fit_views.size()), checks.end());
  for (ViewCheck& check : result.checks) {
    const double t = double(check.triangles), d = double(check.draw_calls);
    check.predicted_ms = profile.model.predict(t, d, pixels, check.fill);
    check.predicted_cpu_ms = result.cpu.model.predict(t, d, pixels, check.fill);
    check.predicted_gpu_ms = result.gpu.model.predict(double(check.drawn_triangles), d, pixels, check.fill);
  }
  const auto validateTerm = [&](TermValidation& term, auto&& measured, auto&& predicted) {
    std::vector<double> ratios;
    for (const ViewCheck& c : result.checks) {
      ratios.push_back(measured(c) / std::max(predicted(c), 1e-6));
      term.under_predicted += measured(c) > predicted(c) ? 1 : 0;
    }
    term.ratio_p50 = percentile(ratios, 50.0);
    term.ratio_p95 = percentile(ratios, 95.0);
    term.ratio_max = percentile(ratios, 100.0);
  };
  validateTerm(result.cpu, [](const ViewCheck& c) { return c.measured_cpu_ms; },
               [](const ViewCheck& c) { return c.predicted_cpu_ms; });
  validateTerm(result.gpu, [](const ViewCheck& c) { return c.measured_gpu_ms; },
               [](const ViewCheck& c) { return c.predicted_gpu_ms; });
  validateTerm(result.max_term, [](const ViewCheck& c) { return c.measured_ms; },
               [](const ViewCheck& c) { return std::max(c.predicted_cpu_ms, c.predicted_gpu_ms); });

  std::vector<double> ratios, errors;
  for (const ViewCheck& c : result.checks) {
    ratios.push_back(c.measured_ms / std::max(c.predicted_ms, 1e-6));
    errors.push_back(std::abs(c.measured_ms - c.predicted_ms));
    if (c.measured_ms > c.predicted_ms) ++result.under_predicted;
  }
  result.ratio_p50 = percentile(ratios, 50.0);
  result.ratio_p95 = percentile(ratios, 95.0);
  result.ratio_p99 = percentile(ratios, 99.0);
  result.ratio_max = percentile(ratios, 100.0);
  result.abs_error_p50_ms = percentile(errors, 50.0);
  result.abs_error_p95_ms = percentile(errors, 95.0);
  result.abs_error_max_ms = percentile(errors, 100.0);
  // Two bounds from the same views, each the quantile of what it must cover: a factor (measured / predicted) and an
  // additive margin (measured - predicted); the profile bounds by the smaller (gpu::CostProfile::boundOfPrediction).
  std::vector<double> excess;
  for (const ViewCheck& c : result.checks) excess.push_back(c.measured_ms - c.predicted_ms);
  profile.safety_factor = std::max(1.0, percentile(ratios, 100.0 * options.margin_quantile));
  profile.safety_margin_ms = std::max(0.0, percentile(excess, 100.0 * options.margin_quantile));
  for (const ViewCheck& c : result.checks) {
    // As ratios and differences, as the bounds were taken (prediction x factor may round a hair below the view).
    const bool over_factor = c.measured_ms / std::max(c.predicted_ms, 1e-6) > profile.safety_factor;
    const bool over_margin = c.measured_ms - c.predicted_ms > profile.safety_margin_ms;
    if (over_factor) ++result.over_factor;
    if (over_factor && over_margin) ++result.over_bound;
  }
  if (options.layered_samples > 0) {
    LayeredCalibrateOptions lo;
    lo.width = options.width;
    lo.height = options.height;
    lo.fov_deg = options.fov_deg;
    lo.error_px = options.layered_error_px;
    lo.layer_tiles = options.layer_tiles;
    lo.view_space = space;
    lo.fit_samples = options.layered_samples;
    lo.validation_samples = options.layered_samples;
    lo.repeats = options.repeats;
    lo.seed = options.seed + 17u;
    lo.progress = options.progress;
    result.layered = calibrateLayered(renderer, gpu_scene, scene, lo);
    profile.layered = result.layered.cost;
  }
  result.wall_s = wall.seconds();
  profile.validation = {{"views", result.checks.size()},
                        {"fill_term", options.fill_term},
                        {"frames", options.gpu_frames
                                       ? (placed ? "runtime (GPU-driven): visible set of the eye's region; whole objects"
                                                 : "runtime (GPU-driven): objects in the frustum; whole objects")
                                       : (placed ? "placed: visible set of the eye's region, occlusion-culled; whole "
                                                   "objects"
                                                 : "frustum-culled full geometry")},
                        {"repeats", options.repeats},
                        {"seed", options.seed},
                        {"view_space", {{"lo", {space.lo.x, space.lo.y, space.lo.z}}, {"hi", {space.hi.x, space.hi.y, space.hi.z}}}},
                        {"margin_quantile", options.margin_quantile},
                        {"ratio_p50", result.ratio_p50},
                        {"ratio_p95", result.ratio_p95},
                        {"ratio_p99", result.ratio_p99},
                        {"ratio_max", result.ratio_max},
                        {"abs_error_p50_ms", result.abs_error_p50_ms},
                        {"abs_error_p95_ms", result.abs_error_p95_ms},
                        {"abs_error_max_ms", result.abs_error_max_ms},
                        {"under_predicted", result.under_predicted},
                        {"margin_ms", profile.safety_margin_ms},
                        {"over_factor", result.over_factor},
                        {"over_bound", result.over_bound},
                        {"cpu_term", result.cpu.toJson()},
                        {"gpu_term", result.gpu.toJson()},
                        {"max_term", result.max_term.toJson()}};
  return result;
}

nlohmann::json TermValidation::toJson() const {
  return {{"model", model.toJson()}, {"ratio_p50", ratio_p50}, {"ratio_p95", ratio_p95}, {"ratio_max", ratio_max},
          {"under_predicted", under_predicted}};
}

void writeCalibrationCsv(const CalibrateResult& result, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw Error(path, "cannot write");
  out << "view,eye_x,eye_y,eye_z,dir_x,dir_y,dir_z,triangles,draw_calls,fill_pixels,region_fill_pixels,predicted_ms,"
         "measured_ms,predicted_cpu_ms,measured_cpu_ms,drawn_triangles,predicted_gpu_ms,measured_gpu_ms\n";
  for (size_t i = 0; i < result.checks.size(); ++i) {
    const ViewCheck& c = result.checks[i];
    const Vec3 d = c.camera.forward();
    out << i << ',' << c.camera.eye.x << ',' << c.camera.eye.y << ',' << c.camera.eye.z << ',' << d.x << ',' << d.y
        << ',' << d.z << ',' << c.triangles << ',' << c.draw_calls << ',' << c.fill << ',' << c.region_fill << ','
        << c.predicted_ms << ',' << c.measured_ms << ',' << c.predicted_cpu_ms << ',' << c.measured_cpu_ms << ','
        << c.drawn_triangles << ',' << c.predicted_gpu_ms << ',' << c.measured_gpu_ms << '\n';
  }
  if (!out) throw Error(path, "write failed");
}

}  // namespace farfield::eval
