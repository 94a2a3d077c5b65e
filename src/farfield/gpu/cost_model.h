// Frame-time cost model (Decoret et al. 1999, section 5.5: "An analysis of the primitive count in the near geometry
// together with its associated MMIs allows us to predict an accurate expected frame time for each viewing cell").
//
// The prediction is linear in three workload terms, with coefficients fitted by measurement on the running machine
// (the paper's platforms differed by an order of magnitude, and so do a GPU and llvmpipe here):
//
//   ms = base_ms + ms_per_mtriangle * triangles / 1e6 + ms_per_draw * draw_calls + ms_per_mpixel * pixels / 1e6
//        + ms_per_mfill * fill / 1e6
//
// - triangles: triangles submitted (FrameStats::triangles), visible or not;
// - draw_calls: draw calls issued (FrameStats::draw_calls);
// - pixels: pixels of the render target that the frame clears and draws into, i.e. width * height. Not the
//   fragments shaded: those depend on coverage and overdraw, which are unknown before drawing. The calibration
//   draws views that fill much of the target, so the term stands for "a frame of that size";
// - fill: the frame pixels the drawn objects may cover, estimated before drawing from their bounds and distances
//   (core/object_fill.h), summed over the objects, so overdraw counts. 0 where the caller does not estimate it (the
//   term then fits to 0 and predicts nothing). `farfield calibrate` fits it on street views, where it is what
//   separates a view past a near facade from one down an open street;
// - ms: wall time of the frame from the first command to glFinish (FrameStats::wall_ms of Renderer::render).
//
// A scheduler (section 5.5: "From the desired and the predicted frame times we can determine how much time we have
// to accomplish such updates") subtracts predict() of a cell's near geometry and impostors from the frame budget.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/gpu/renderer.h"

namespace farfield::gpu {

// One measured workload.
struct CostSample {
  double triangles = 0;
  double draw_calls = 0;
  double pixels = 0;  // target width * height
  double ms = 0;      // measured wall time
  double fill = 0;    // estimated pixels covered by the drawn objects (core/object_fill.h), 0: not estimated
};

struct CostModel {
  // Coefficients, all >= 0 (a negative cost is measurement noise, not a property of the machine).
  double base_ms = 0;           // fixed cost of a frame (clear, state, the wait)
  double ms_per_mtriangle = 0;  // per million triangles
  double ms_per_draw = 0;       // per draw call
  double ms_per_mpixel = 0;     // per million target pixels
  double ms_per_mfill = 0;      // per million estimated pixels covered (CostSample::fill)
  // > 0: the fill counts up to this many pixels (min(fill, cap)); 0: no cap. A frame drawn through an occlusion
  // culler shades a few layers of the frame however many objects its estimate sums, so the fill saturates; the cap
  // also keeps a bound over a region (which sums every object near it) within what a view of it can cost.
  double fill_cap_pixels = 0;
  // Fit quality, over the samples the model was fitted to.
  size_t samples = 0;
  double rms_error_ms = 0;  // root mean square of the residuals
  double r2 = 0;            // coefficient of determination (1 = perfect; 1 also when every sample took the same time
                            // and the fit reproduces it)

  // Predicted frame time (ms) of a workload; the arguments are in the units of CostSample.
  double predict(double triangles, double draw_calls, double pixels, double fill = 0.0) const;
  // The fill pixels (in the units of CostSample::fill) that the prediction stops counting when `removed` of a
  // workload's `total` fill is taken away: counted(total) - counted(total - removed), with counted the capped fill.
  // It is `removed` under the cap and what takes the total back under it above. As a function of `removed` it is
  // convex and 0 at 0, so it is superadditive: credits of disjoint parts computed one by one against the same total
  // add up to at most the credit of their union (placement sums them and stays an upper bound of the time).
  double fillCredit(double total, double removed) const;

  // Least squares on the five terms with every coefficient constrained to be >= 0 (non-negative least squares).
  // Terms the samples cannot tell apart (e.g. every sample at the same size: pixels and base are collinear) are
  // resolved towards the fewest non-zero terms. Throws farfield::Error with fewer than 5 samples, or for a sample with
  // a non-finite or negative value.
  static CostModel fit(std::span<const CostSample> samples);

  // {"base_ms", "ms_per_mtriangle", "ms_per_draw", "ms_per_mpixel", "ms_per_mfill", "fill_cap_pixels", "samples",
  //  "rms_error_ms", "r2"}.
  nlohmann::json toJson() const;
};

struct CalibrationOptions {
  int repeats = 3;                    // timed renders per workload and view; the median is kept (warm-up untimed)
  std::vector<int> sizes{128, 256, 512};  // square target sizes (pixels): the pixel term's spread
  size_t max_triangles = 2'000'000;   // cap on the triangles of one workload (keeps big scenes quick)
  bool progress = false;              // progress line on stderr (core/progress.h)
  // Views each workload is timed from (their width and height are replaced by each size); a sample's time is the
  // mean over the views. Empty: an overview of the scene's bounds and two low views across it (see the .cpp). A
  // caller that knows its frames (a camera path) should pass a few of their cameras: coverage, overdraw and how much
  // is clipped away shape the coefficients.
  std::vector<Camera> views;
};

// Fits a CostModel to workloads measured on this machine with the scene's own draw items (so material, texture and
// mesh-size mix are the scene's): subsets of the items with growing triangle counts (up to max_triangles), the
// smallest item repeated to vary draw calls independently of triangles, and an empty frame and the largest subset at
// each target size for the pixel term.
// Each workload is timed as a whole frame: Renderer::render (clear, Renderer::draw, glFinish; the gpu module's only
// public wait) around a wall-clock stopwatch, median of `repeats`, from each of the views (CalibrationOptions::views).
// Must not be called inside a timed frame (it waits for the GPU). With a tiny scene the triangle term is
// poorly determined (it comes out small or 0); that is the honest answer for such a scene.
//
// Cost: about ((4 + 2 * (sizes - 1)) * repeats + 2 * sizes) * views frames of up to min(scene triangles,
// max_triangles) triangles, i.e. ~50 such frames with the defaults: 0.6-0.9 s for the default 100-block city (75k
// triangles) on llvmpipe with 2 cores; lower max_triangles for big scenes on a software rasteriser.
//
// Accuracy measured on llvmpipe (default city, frustum-culled street frames of 31k triangles): 5.2 ms predicted for
// 5.3 ms at 256 x 256, 7.8 ms for 11.3 ms at 512 x 512 (a street view overdraws more than the default views do).
//
// Needs a current context. Throws farfield::Error for a scene without draw items or bad options (repeats < 1, no
// sizes, a size outside 1..16384, max_triangles 0, an unusable view).
CostModel calibrateCostModel(gpu::Renderer& renderer, const gpu::GpuScene& gpu_scene,
                             const CalibrationOptions& options = {});

}  // namespace farfield::gpu
