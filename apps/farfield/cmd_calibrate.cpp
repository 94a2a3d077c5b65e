// farfield calibrate SCENE -o profile.json [--size WxH] [--fov DEG] [--views N] [--repeats N]
//                    [--view-min X,Y,Z --view-max X,Y,Z] [--seed S] [--margin-quantile Q] [--csv FILE]
//                    [--fill-term | --no-fill-term] [--visibility-cache FILE] [--cpu-frames]
// Fits the frame-time cost model on this machine and validates it on random views of the view space
// (eval/calibration.h); writes the cost profile that placement bounds frame times with.
#include <cstdio>
#include <memory>
#include <optional>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/core/error.h"
#include "farfield/eval/calibration.h"
#include "farfield/gpu/context.h"
#include "farfield/placement/visibility_cache.h"
#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

struct CalibrateArgs {
  std::string scene;
  std::string out;
  std::string size = "512x512";
  std::string view_min, view_max, around;
  float margin = 50.0f;
  std::string csv;
  std::string visibility_cache;
  std::optional<bool> fill_term;  // --fill-term / --no-fill-term; unset: on for the placed runtime's frames
  eval::CalibrateOptions options;
};

void runCalibrateCommand(CalibrateArgs& args) {
  const AllocatorSettings allocator = configureTimingAllocator();
  eval::CalibrateOptions& o = args.options;
  const IVec2 size = parseSize("--size", args.size);
  o.width = size.x;
  o.height = size.y;
  o.view_space = parseViewSpace(args.view_min, args.view_max, args.around, args.margin);
  const scene::Scene scene = scene::loadScene(args.scene);
  placement::VisibilityCache cache;
  if (!args.visibility_cache.empty()) {
    cache = placement::readVisibilityCache(args.visibility_cache);
    const size_t objects = cache.key.value("scene_objects", size_t(0));
    if (objects != scene.objects.size())
      throw Error(args.visibility_cache, "made for a scene of " + std::to_string(objects) + " objects, not " +
                                             std::to_string(scene.objects.size()));
    if (o.view_space.empty()) o.view_space = cache.viewSpace();  // its regions' views
    o.visible_set = [&cache](const Vec3& eye) { return cache.visibleFrom(eye); };
    o.region_of = [&cache](const Vec3& eye) { return cache.regionOf(eye); };
  }
  // The fill term by default where the frames are the placed walkthrough's (the GPU-driven frame over a region's
  // visible set): there it is what the views differ by besides triangles (docs/DESIGN-NOTES.md, "A fill term").
  o.fill_term = args.fill_term.value_or(!args.visibility_cache.empty() && o.gpu_frames);
  const eval::CalibrateResult r = eval::calibrate(gpu::sharedHeadlessContext(), scene, o);
  ensureParentDirectory(args.out);
  gpu::saveCostProfile(r.profile, args.out);
  if (!args.csv.empty()) {
    ensureParentDirectory(args.csv);
    eval::writeCalibrationCsv(r, args.csv);
  }
  const gpu::CostModel& m = r.profile.model;
  std::printf("scene:              %s\n", args.scene.c_str());
  std::printf("renderer:           %s\n", r.profile.renderer.c_str());
  std::printf("malloc:             %s\n", allocator.description.c_str());
  std::printf("frames:             %s\n", r.profile.validation.value("frames", std::string()).c_str());
  std::printf("model:              %.3f ms + %.3f ms/Mtri + %.4f ms/draw + %.3f ms/Mpixel + %.3f ms/Mpixel of "
              "estimated fill (fit r2 %.3f, %zu samples)\n",
              m.base_ms, m.ms_per_mtriangle, m.ms_per_draw, m.ms_per_mpixel, m.ms_per_mfill, m.r2, m.samples);
  const char* const counted_as =
      o.region_of ? "fitting views' objects counted from their regions, as placement counts them" : "fitting views";
  if (m.ms_per_mfill > 0.0 && m.fill_cap_pixels > 0.0)
    std::printf("fill counted up to: %.0f frames (the smallest bound summed over the %s)\n",
                m.fill_cap_pixels / (double(o.width) * double(o.height)), counted_as);
  else if (m.ms_per_mfill > 0.0)
    std::printf("fill counted up to: no cap (the smallest bound summed over the %s)\n", counted_as);
  std::printf("validation:         %zu views at %dx%d, %.0f deg, min of %d renders each\n", r.checks.size(), o.width,
              o.height, double(o.fov_deg), o.repeats);
  std::printf("measured/predicted: p50 %.3f  p95 %.3f  p99 %.3f  max %.3f\n", r.ratio_p50, r.ratio_p95, r.ratio_p99,
              r.ratio_max);
  std::printf("|error| ms:         p50 %.3f  p95 %.3f  max %.3f\n", r.abs_error_p50_ms, r.abs_error_p95_ms,
              r.abs_error_max_ms);
  std::printf("safety factor:      %.3f (quantile %.3f of measured/predicted); views over prediction x factor: %zu of %zu\n",
              r.profile.safety_factor, o.margin_quantile, r.over_factor, r.checks.size());
  const double margin = r.profile.safety_margin_ms;
  std::printf("safety margin:      %.3f ms (quantile %.3f of measured - predicted); the bound is the smaller: "
              "prediction x %.3f up to %.2f ms predicted, + %.3f ms above\n",
              margin, o.margin_quantile, r.profile.safety_factor,
              r.profile.safety_factor > 1.0 ? margin / (r.profile.safety_factor - 1.0) : 0.0, margin);
  std::printf("views over the bound: %zu of %zu\n", r.over_bound, r.checks.size());
  if (o.margin_quantile >= 1.0)
    // Each bound is the largest of n exchangeable views, so a further view of the same view space exceeds it with
    // probability at most 1 / (n + 1); the profile's bound (the smaller) is exceeded when either is.
    std::printf("a further random view of the view space is over the bound with probability at most 2 / (n + 1) = "
                "%.2f %% (n = %zu; more --views lower it)\n",
                200.0 / double(r.checks.size() + 1), r.checks.size());
  std::printf("views slower than predicted (before the factor): %zu\n", r.under_predicted);
  const auto term = [](const char* name, const eval::TermValidation& t) {
    std::printf("%-20s%.4f ms + %.3f ms/Mtri + %.5f ms/draw + %.3f ms/Mpixel of fill (fit r2 %.3f); measured/predicted "
                "p50 %.3f  p95 %.3f  max %.3f\n", name, t.model.base_ms, t.model.ms_per_mtriangle, t.model.ms_per_draw,
                t.model.ms_per_mfill, t.model.r2,
                t.ratio_p50, t.ratio_p95, t.ratio_max);
  };
  term("CPU term:", r.cpu);
  term("GPU term:", r.gpu);
  std::printf("max(CPU, GPU):      the frame's wall time / max of the two predictions: p50 %.3f  p95 %.3f  max %.3f "
              "(placement and the governor use the wall model above)\n",
              r.max_term.ratio_p50, r.max_term.ratio_p95, r.max_term.ratio_max);
  if (r.profile.layered.calibrated) {
    const gpu::LayeredCost& l = r.profile.layered;
    const eval::LayeredCalibrateResult& lr = r.layered;
    std::printf("layered draw:       %.3f ms + %.4f ms/layer + %.3f ms/Mpixel of %s (fit r2 %.3f, %zu samples)\n",
                l.draw.base_ms, l.draw.ms_per_draw, l.draw.ms_per_mpixel,
                args.options.layer_tiles ? "tiles" : "whole quads", l.draw.r2, l.draw.samples);
    std::printf("layered capture:    %.3f ms + %.3f ms/Mtri + %.4f ms/layer + %.3f ms/Mtexel (fit r2 %.3f)\n",
                l.capture.base_ms, l.capture.ms_per_mtriangle, l.capture.ms_per_draw, l.capture.ms_per_mpixel,
                l.capture.r2);
    std::printf("layered tiles:      drawn as their tiles / as whole quads, the same impostors and views: p50 %.3f, "
                "all samples' sum %.3f\n", lr.tiles_over_whole_p50, lr.tiles_over_whole_sum);
    std::printf("layered validation: %zu clusters; draw measured/predicted p50 %.3f p95 %.3f max %.3f (factor %.3f); "
                "capture p50 %.3f p95 %.3f max %.3f (factor %.3f); %zu plans skipped\n",
                lr.checks.size(), lr.draw_ratio_p50, lr.draw_ratio_p95, lr.draw_ratio_max, l.draw_safety_factor,
                lr.capture_ratio_p50, lr.capture_ratio_p95, lr.capture_ratio_max, l.capture_safety_factor,
                lr.skipped);
  }
  std::printf("wall:               %.1f s\n", r.wall_s);
  std::printf("profile:            %s\n", args.out.c_str());
  if (!args.csv.empty()) std::printf("csv:                %s\n", args.csv.c_str());
}

const RegisterCommand reg("calibrate", [](CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand("calibrate", "Fit the frame-time cost model on this machine and validate it on "
                                              "random views; writes a cost profile (JSON).");
  cmd->add_option("scene", args->scene, "Scene file (glTF, OBJ, ...) or builtin:NAME")->required();
  cmd->add_option("-o,--out", args->out, "Cost profile to write (JSON)")->required();
  cmd->add_option("--size", args->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--fov", args->options.fov_deg, "Vertical field of view, degrees")->capture_default_str();
  cmd->add_option("--views", args->options.views, "Validation views")->capture_default_str();
  cmd->add_option("--fit-views", args->options.fit_views, "Views the model is fitted on")->capture_default_str();
  cmd->add_option("--repeats", args->options.repeats, "Renders per view (the minimum is kept)")->capture_default_str();
  cmd->add_option("--view-min", args->view_min, "View space corner X,Y,Z (default: the scene's bounds at 1.7 m)");
  cmd->add_option("--view-max", args->view_max, "View space corner X,Y,Z");
  cmd->add_option("--around", args->around, "View space: the district along a camera path (its eyes' bounds "
                                           "grown by --margin)");
  cmd->add_option("--margin", args->margin, "Margin of --around on the ground, metres")->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Seed of the random views")->capture_default_str();
  cmd->add_option("--margin-quantile", args->options.margin_quantile,
                  "Safety factor and margin = this quantile of measured/predicted and measured - predicted (1 = the maximum)")->capture_default_str();
  cmd->add_option("--csv", args->csv, "Per-view predicted and measured times");
  cmd->add_option("--visibility-cache", args->visibility_cache,
                  "Time placed frames: the visible sets `farfield place --visibility-cache` saved, drawn as the "
                  "walkthrough draws them, counted over whole objects as placement counts them (the view space "
                  "defaults to the cache's)");
  cmd->add_flag("!--cpu-frames", args->options.gpu_frames,
                "Time the CPU-culled frames of before (occlusion culler or frustum-culled clusters) instead of the "
                "runtime's GPU-driven ones");
  cmd->add_flag_function(
      "--fill-term,!--no-fill-term", [args](int64_t count) { args->fill_term = count > 0; },
      "Fit the estimated-fill term too, counted up to a cap chosen on the fitting views (with --visibility-cache: "
      "the tightest model placement can bound; see docs/BENCHMARKS.md). Default: on with --visibility-cache (the "
      "placed walkthrough's frames), off otherwise");
  cmd->add_option("--layered-samples", args->options.layered_samples,
                  "Layered impostors the draw and capture terms are fitted on (as many validate them; 0: none)")
      ->capture_default_str();
  cmd->add_option("--layered-error-px", args->options.layered_error_px,
                  "Error bound of the layered impostors calibrated on, pixels")->capture_default_str();
  cmd->add_flag("!--no-layer-tiles", args->options.layer_tiles,
                "Time the layers drawn as whole quads, their fill counted over them (a profile for place "
                "--no-layer-tiles, for comparisons)");
  cmd->callback([args] { runCalibrateCommand(*args); });
});

}  // namespace
}  // namespace farfield::app
