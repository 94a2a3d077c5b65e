// `farfield calibrate`: the rendering-time estimation of Jeschke et al. 2005 (section 3.2, after Wimmer and Wonka
// 2003) fitted on the running machine and validated. The cost model (gpu/cost_model.h) is fitted on `fit_views`
// random views of the view space, then checked on `views` other ones: each view's frustum-culled geometry is drawn
// and timed (minimum of `repeats` renders, each in its own pass over the views, to remove the machine's noise) and
// compared with the prediction from its triangles, draw calls, pixels and estimated fill (core/object_fill.h). The distribution of measured / predicted
// gives the profile's safety factor and that of measured - predicted its additive margin (the quantile
// `margin_quantile` of each, 1 = the largest seen), so that min(prediction x factor, prediction + margin) bounds the
// measured time of (that share of) the validation views.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/eval/layered_calibration.h"
#include "farfield/scene/scene.h"

namespace farfield::eval {

struct CalibrateOptions {
  int width = 512;             // the walkthrough's frames (Jeschke et al. 2005: 512 x 512, 45 degrees)
  int height = 512;
  float fov_deg = 45.0f;
  Box3 view_space;             // eyes are drawn uniformly from it; empty: the scene's bounds at 1.7 m above its floor
  size_t views = 500;          // validation views (the issue asks for at least 500)
  size_t fit_views = 100;      // random views of the view space the model is fitted on (other than the validation's)
  int repeats = 3;             // renders per view (passes over the views), the minimum kept
  double margin_quantile = 1.0;  // safety factor and margin: this quantile of measured / predicted and - (1 = max)
  // Fit the model's fill term (gpu/cost_model.h, core/object_fill.h) too, counted up to a cap chosen on the fitting
  // views (2 to 8 frames, or none: fitWithFillCap). Off: the views' estimated fill is still written to the CSV, and
  // the term is 0.
  // Uncapped, a region's fill bounded from its nearest point counts every adjacent building as a whole frame, and
  // placement's problem view space grew several times; capped and fitted on placed frames (visible_set) it gives the
  // tightest bound measured (docs/BENCHMARKS.md). `farfield calibrate` turns it on by default with a visibility
  // cache (the placed runtime's frames).
  bool fill_term = false;
  // Placed frames (`farfield calibrate --visibility-cache`): when set, a view draws the objects this returns for its
  // eye (the visible set of the region holding it; nullptr: every object) that its frustum meets, through the
  // occlusion culler, as the placed walkthrough draws its geometry; and its workload is counted as placement counts
  // it, over whole objects (gpu::GpuScene::objectDrawCosts). So the model and its safety factor are of the frames
  // placement must bound. Unset: frustum-culled full geometry, counted by the clusters drawn.
  std::function<const std::vector<uint32_t>*(const Vec3& eye)> visible_set;
  // With visible_set: the region holding an eye (placement's minimum-size region; none outside the view space).
  // Placement bounds a region's fill from its nearest point, so the fill cap is chosen for those sums
  // (fitWithFillCap's bounded fills): each fitting view's objects counted from its region.
  std::function<std::optional<Box3>(const Vec3& eye)> region_of;
  // The frames timed: the runtime's own, GPU-driven (eval/plan_geometry.h: the objects culled per cluster by
  // gpu::GpuCuller, as the walkthrough draws its plans and `culled` draws the scene), each view drawn once untimed
  // first; false: the CPU-culled frames of before (the visible set through the occlusion culler, or frustum-culled
  // clusters). Either way the views' workloads are counted as placement counts them, over whole objects, except the
  // CPU path without visible_set (its clusters).
  bool gpu_frames = true;
  uint32_t seed = 1;
  float near_plane = 0.5f;
  float far_plane = 20000.0f;
  bool progress = true;
  // The layered impostor's draw and capture terms (eval/layered_calibration.h) on clusters of the same scene and
  // view space, at the same frame size; 0 samples: none (the profile's layered cost stays uncalibrated).
  size_t layered_samples = 40;  // fitting samples; as many again validate
  double layered_error_px = 2.0;
  bool layer_tiles = true;      // the layers drawn as their tiles (false: whole quads; LayeredCalibrateOptions)
};

struct ViewCheck {
  Camera camera;
  uint64_t triangles = 0;
  size_t draw_calls = 0;
  double fill = 0.0;  // estimated pixels covered by the drawn objects (core/object_fill.h)
  // The same objects' fill from the nearest point of the eye's region (CalibrateOptions::region_of), as placement
  // bounds it; the view's own fill without a region.
  double region_fill = 0.0;
  double predicted_ms = 0.0;
  double measured_ms = 0.0;  // minimum of the repeats
  // The frame's two sides, each the minimum of the repeats (eval/frame_runner.h's FrameRecord): Farfield's own CPU
  // time and the GPU's (timer queries; on a software rasterizer the CPU clock to the frame's end), and their
  // predictions by the terms fitted on them (CalibrateResult::cpu, gpu).
  double measured_cpu_ms = 0.0, measured_gpu_ms = 0.0;
  double predicted_cpu_ms = 0.0, predicted_gpu_ms = 0.0;
  // Triangles the frame drew after its culling (the GPU culler's count, read once the frame finished; on the CPU
  // path the items drawn): the GPU term's triangle feature. The runtime knows it a frame or two late (the governor's
  // feature), placement not at all (it keeps `triangles`, counted over whole objects).
  uint64_t drawn_triangles = 0;
};

// One term of the frame's cost (CPU or GPU) fitted on the fitting views' measurements of it, and checked on the
// validation views: quantiles of measured / predicted. The CPU term's workload is the view's as placement counts it;
// the GPU term's triangles are those drawn after culling (ViewCheck::drawn_triangles).
struct TermValidation {
  gpu::CostModel model;
  double ratio_p50 = 0.0, ratio_p95 = 0.0, ratio_max = 0.0;
  size_t under_predicted = 0;  // views whose term took longer than predicted
  nlohmann::json toJson() const;
};

struct CalibrateResult {
  gpu::CostProfile profile;
  std::vector<ViewCheck> checks;
  // Quantiles of measured / predicted over the validation views, and of |measured - predicted| in ms.
  double ratio_p50 = 0.0, ratio_p95 = 0.0, ratio_p99 = 0.0, ratio_max = 0.0;
  double abs_error_p50_ms = 0.0, abs_error_p95_ms = 0.0, abs_error_max_ms = 0.0;
  size_t under_predicted = 0;  // views slower than predicted (before the safety factor)
  size_t over_factor = 0;      // views slower than predicted * safety factor
  size_t over_bound = 0;       // views slower than the profile's bound (the factor's and the margin's smaller)
  // The CPU and GPU terms (issue 43: a frame costs max(CPU, GPU) plus its synchronisations), each fitted on its own
  // measurements, and max_term: the frame's wall time against max(predicted CPU, predicted GPU) (its model unused).
  // Recorded in the profile's validation ("cpu_term", "gpu_term", "max_term"); placement and the governor use
  // `profile.model`, fitted on the wall time.
  TermValidation cpu, gpu, max_term;
  double wall_s = 0.0;
  LayeredCalibrateResult layered;  // empty when CalibrateOptions::layered_samples is 0
};

// The validation cameras: eyes uniform in the view space, yaw uniform, pitch within +-10 degrees. Deterministic in
// the seed.
std::vector<Camera> randomViews(const Box3& view_space, size_t count, uint32_t seed, int width, int height,
                                float fov_deg, float near_plane, float far_plane);

// The scene's default view space: its bounds in x and y, at 1.7 m above the lowest point of its bounds (a
// pedestrian over flat ground), 0.01 m thick.
Box3 defaultViewSpace(const scene::Scene& scene);

// The model with the fill term counted up to a cap (gpu::CostModel::fill_cap_pixels) of 2, 3, 4, 6 or 8 frames of
// `frame_pixels`, or uncapped, fitted by least squares on every sample; the cap kept is the one whose bound is
// smallest out of sample, summed over the workloads placement will bound. Each of kFillCapFolds folds (sample i in
// fold i % kFillCapFolds) is predicted by the model fitted on the others and bounded as the profile bounds
// (prediction x the largest measured / predicted over the fold, or + the largest measured - predicted where smaller;
// so a fit that leaves heavy views far under pays for it everywhere), its workloads being the samples with their fill
// replaced by `bounded_fill[i]` (the fill of sample i's objects from its region's nearest point, which counts near
// buildings as whole frames: there a cap decides the bound), or the samples themselves when `bounded_fill` is empty.
// Ties go to no cap, then to the smaller cap. Throws farfield::Error as gpu::CostModel::fit (each fold's fit needs 5
// samples), or for a bounded_fill of another size than the samples.
inline constexpr size_t kFillCapFolds = 5;
gpu::CostModel fitWithFillCap(std::span<const gpu::CostSample> samples, double frame_pixels,
                              std::span<const double> bounded_fill = {});

// Fits and validates. Makes `context` current. Throws farfield::Error for bad options (fewer than 8 views, repeats
// < 1, quantile outside (0, 1], an empty scene, a view space that is not finite).
CalibrateResult calibrate(gpu::Context& context, const scene::Scene& scene, const CalibrateOptions& options);

// view,eye_x,eye_y,eye_z,dir_x,dir_y,dir_z,triangles,draw_calls,fill_pixels,region_fill_pixels,predicted_ms,measured_ms,
// predicted_cpu_ms,measured_cpu_ms,drawn_triangles,predicted_gpu_ms,measured_gpu_ms
void writeCalibrationCsv(const CalibrateResult& result, const std::string& path);

}  // namespace farfield::eval
