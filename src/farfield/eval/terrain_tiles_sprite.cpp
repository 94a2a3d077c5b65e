// LOD-sprite over the CDLOD terrain paged from disk (see terrain_tiles_sprite.h).
#include "farfield/eval/terrain_tiles_sprite.h"

#include <algorithm>
#include <cstdio>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/gl_counters.h"

namespace farfield::eval {
namespace {

const Vec4 kSky{0.62f, 0.74f, 0.88f, 1.0f};  // the terrain bench's sky (terrain_modes.h)

struct Spread {
  double mean = 0.0, median = 0.0, p99 = 0.0, max = 0.0;
  size_t over_twice_median = 0;
};

Spread spread(std::vector<double> v) {
  Spread s;
  if (v.empty()) return s;
  for (double x : v) s.mean += x;
  s.mean /= double(v.size());
  std::sort(v.begin(), v.end());
  s.median = v[v.size() / 2];
  s.p99 = v[std::min(v.size() - 1, v.size() * 99 / 100)];
  s.max = v.back();
  for (double x : v) s.over_twice_median += x > 2.0 * s.median ? 1 : 0;
  return s;
}

nlohmann::ordered_json spreadJson(const Spread& s) {
  return {{"frame_ms_mean", s.mean},
          {"frame_ms_median", s.median},
          {"frame_ms_p99", s.p99},
          {"frame_ms_max", s.max},
          {"frames_over_twice_the_median", s.over_twice_median}};
}

}  // namespace

double ownCpuMs(double wall_ms, const gpu::GlCounters& before) {
  if (!gpu::glCountersInstalled()) return -1.0;
  const gpu::GlCounters used = gpu::glCounters() - before;
  return std::max(0.0, wall_ms - used.driver_ms - used.measure_ms);
}

nlohmann::ordered_json ownCpuSummary(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return x < 0.0; }), v.end());
  if (v.empty()) return {{"median", -1.0}, {"p95", -1.0}};
  std::sort(v.begin(), v.end());
  return {{"median", v[v.size() / 2]}, {"p95", v[std::min(v.size() - 1, v.size() * 95 / 100)]}};
}

PagedSpriteRun::PagedSpriteRun(terrain::PagedGpuLodTerrain& terrain, std::span<const Camera> path,
                               const PagedSpriteOptions& options)
    : terrain_(terrain), options_(options) {
  if (path.empty()) throw Error("--lod-sprite", "needs a path");
  if (options.calibration_views < 1) throw Error("--lod-sprite", "needs at least one calibration view");
  const Camera& first = path.front();
  // The cost model of this machine's CDLOD frames and sprite frames, from views spread over the path (untimed,
  // before the run), at the bounds the bench's lod-sprite-gpu calibrates (terrain_modes.cpp's spriteCostOptions).
  terrain::TerrainCostOptions c;
  const size_t n = path.size(), k = size_t(options.calibration_views);
  for (size_t v = 0; v < k; ++v) c.views.push_back(path[std::min(n - 1, (2 * v + 1) * n / (2 * k))]);
  const Camera key =
      terrain::guardBandCamera(first, first.width, first.height, terrain::LodSpriteOptions{}.keyframe_margin);
  c.keyframe_width = key.width;
  c.keyframe_height = key.height;
  c.pixel_errors = {options.pixel_error, 2.0f * options.pixel_error, options.low_error, 4.0f * options.low_error};
  const Stopwatch clock;
  cost_ = terrain::calibrateCdlodCost(terrain, c);
  calibration_seconds_ = clock.seconds();

  terrain::LodSpriteOptions o;
  o.gpu_low = true;
  o.epsilon = options.epsilon;
  o.max_magnification = options.max_magnification;
  o.high_error = options.pixel_error;
  o.low_error = options.low_error;
  o.sky_color = kSky;
  o.cost = &cost_;
  if (options.predict) {  // as lod-sprite-gpu-predict (terrain_modes.cpp)
    o.predict = true;
    o.predict_late = true;
    o.predict_chunks = 16;
  }
  renderer_ = std::make_unique<terrain::LodSpriteRenderer>(terrain, first.width, first.height, o);
}

PagedSpriteFrame PagedSpriteRun::draw(const Camera& camera, gpu::RenderTarget& target) {
  PagedSpriteFrame frame;
  target.clear(kSky);
  const size_t loads = terrain_.stats().page_loads;
  const gpu::GlCounters before = gpu::glCounters();
  const Stopwatch clock;
  frame.triangles = renderer_->render(camera, target, &frame.info).triangles;
  terrain_.finish();
  frame.ms = clock.milliseconds();
  frame.own_ms = ownCpuMs(frame.ms, before);
  frame.page_loads = terrain_.stats().page_loads - loads;
  // The model corrected by what it got wrong, each measurement taken 2 frames late (as a timer query would come).
  if (options_.cost_correction) renderer_->measured(frame.info.frame, frame.ms);
  return frame;
}

nlohmann::ordered_json PagedSpriteRun::summary(std::span<const PagedSpriteFrame> frames,
                                               std::span<const double> high_ms,
                                               std::span<const double> high_own_ms) const {
  std::vector<double> ms, own;
  for (const PagedSpriteFrame& f : frames) own.push_back(f.own_ms);
  double psnr_min = 1e9, psnr_sum = 0.0, triangles = 0.0;
  size_t compared = 0, sprite_frames = 0, page_loads = 0, waited = 0;
  for (const PagedSpriteFrame& f : frames) {
    ms.push_back(f.ms);
    page_loads += f.page_loads;
    waited += f.page_loads > 0 ? 1 : 0;
    triangles += double(f.triangles);
    sprite_frames += f.info.path == terrain::TerrainPath::Sprite ? 1 : 0;
    if (f.psnr_vs_high < 0.0) continue;
    psnr_min = std::min(psnr_min, f.psnr_vs_high);
    psnr_sum += f.psnr_vs_high;
    ++compared;
  }
  const Spread s = spread(ms), h = spread(std::vector<double>(high_ms.begin(), high_ms.end()));
  const terrain::LodSpriteCounters& c = renderer_->counters();
  nlohmann::ordered_json j = spreadJson(s);
  j["speedup_vs_cdlod_mean"] = s.mean > 0.0 ? h.mean / s.mean : 0.0;
  j["speedup_vs_cdlod_median"] = s.median > 0.0 ? h.median / s.median : 0.0;
  j["own_cpu_ms"] = ownCpuSummary(own);
  j["cdlod"] = spreadJson(h);
  j["cdlod"]["own_cpu_ms"] = ownCpuSummary(std::vector<double>(high_own_ms.begin(), high_own_ms.end()));
  j["triangles_mean"] = frames.empty() ? 0.0 : triangles / double(frames.size());
  j["sprite_frames"] = sprite_frames;
  j["page_loads_waited_for"] = page_loads;
  j["frames_that_waited_for_pages"] = waited;
  j["high_frames"] = c.high_frames;
  j["fresh_keyframes"] = c.fresh_keyframes;
  j["keyframes_rendered_ahead"] = c.predicted_rendered;
  j["keyframes_rendered_ahead_used"] = c.predicted_used;
  j["keyframes_finished_at_a_trip"] = c.predicted_finished;
  // Equation 2's sample kept between measures (terrain/cdlod_sprite_error.h): per measure, the cells whose heights
  // came from an earlier one, those asked of the terrain, and the C' made anew (machine-independent, as draw calls).
  const terrain::CdlodSpriteError::Counters& e = renderer_->errorCounters();
  const double measures = double(std::max<size_t>(e.measures, 1));
  j["error_measures"] = e.measures;
  j["error_cells_kept_per_measure"] = double(e.cells_kept) / measures;
  j["error_cells_gathered_per_measure"] = double(e.cells_gathered) / measures;
  j["error_projections_made_per_measure"] =
      double(e.cells_kept + e.cells_gathered - std::min(e.projections_kept, e.cells_kept + e.cells_gathered)) /
      measures;
  j["psnr_vs_cdlod_frames"] = compared;
  j["psnr_vs_cdlod_min_db"] = compared ? psnr_min : 0.0;
  j["psnr_vs_cdlod_mean_db"] = compared ? psnr_sum / double(compared) : 0.0;
  j["epsilon"] = options_.epsilon;
  j["low_error"] = options_.low_error;
  j["predict"] = options_.predict;
  j["max_magnification"] = options_.max_magnification;
  j["cost_correction_on"] = options_.cost_correction;
  j["calibration_seconds"] = calibration_seconds_;
  j["cost"] = cost_.toJson();
  const terrain::CostCorrection& cc = renderer_->costCorrection();
  for (const auto kind : {terrain::TerrainFrameKind::High, terrain::TerrainFrameKind::Sprite,
                          terrain::TerrainFrameKind::Keyframe, terrain::TerrainFrameKind::Slice})
    j["cost_correction"][terrain::terrainFrameKindName(kind)] = cc.factor(kind);
  j["cost_correction"]["measurements"] = cc.measurementsUsed();
  return j;
}

std::string PagedSpriteRun::markdown(const nlohmann::ordered_json& j) {
  char line[2048];
  std::snprintf(line, sizeof line,
                "\nLOD-sprite on the same paged terrain%s (epsilon %.2g px, sprite frames at %.2g px; the same frames, "
                "timed apart, the pages read ahead outside both): %.2f ms mean, %.2f median, %.2f p99, %.2f max; "
                "%zu frames over twice its median; own CPU %.3f ms median, %.3f p95 (the CDLOD frame's %.3f, %.3f); "
                "**%.2fx the CDLOD frame's mean** (%.2f ms; median %.2fx); "
                "%zu sprite frames, %zu high frames, %zu keyframes drawn at once, %zu rendered ahead (%zu used, "
                "%zu finished at a trip); PSNR against the CDLOD frame %.1f dB mean, %.1f min over %zu frames; "
                "cost model fitted in %.1f s; %zu pages read in its frames (%zu frames waited); equation 2 measured "
                "%zu times, a measure %.0f cells kept and %.0f gathered, %.0f C' made\n",
                bool(j["predict"]) ? ", keyframes rendered ahead" : "", double(j["epsilon"]), double(j["low_error"]),
                double(j["frame_ms_mean"]), double(j["frame_ms_median"]), double(j["frame_ms_p99"]),
                double(j["frame_ms_max"]), size_t(j["frames_over_twice_the_median"]),
                double(j["own_cpu_ms"]["median"]), double(j["own_cpu_ms"]["p95"]),
                double(j["cdlod"]["own_cpu_ms"]["median"]), double(j["cdlod"]["own_cpu_ms"]["p95"]),
                double(j["speedup_vs_cdlod_mean"]), double(j["cdlod"]["frame_ms_mean"]),
                double(j["speedup_vs_cdlod_median"]), size_t(j["sprite_frames"]), size_t(j["high_frames"]),
                size_t(j["fresh_keyframes"]), size_t(j["keyframes_rendered_ahead"]),
                size_t(j["keyframes_rendered_ahead_used"]), size_t(j["keyframes_finished_at_a_trip"]),
                double(j["psnr_vs_cdlod_mean_db"]),
                double(j["psnr_vs_cdlod_min_db"]), size_t(j["psnr_vs_cdlod_frames"]), double(j["calibration_seconds"]),
                size_t(j["page_loads_waited_for"]), size_t(j["frames_that_waited_for_pages"]),
                size_t(j["error_measures"]), double(j["error_cells_kept_per_measure"]),
                double(j["error_cells_gathered_per_measure"]), double(j["error_projections_made_per_measure"]));
  return line;
}

}  // namespace farfield::eval
