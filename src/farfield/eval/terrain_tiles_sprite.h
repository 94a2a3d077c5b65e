// LOD-sprite over the CDLOD terrain paged from disk, the second frame of `farfield terrain tiles --render
// --lod-sprite` (terrain_tiles.h): Chen et al.'s LOD-sprite (terrain/lod_sprite.h) wholly on the paged terrain, with
// no quadtree LOD (a 16,385^2 grid is never held whole): keyframes and high frames are the paged CDLOD frames at the
// run's bound, sprite frames its selection at the low bound drawn with equation 3 per vertex on the GPU, and the
// per-frame choice between them made by a cost model fitted at start on views of the run's own path
// (terrain::calibrateCdlodCost). The run draws each camera as the CDLOD frame and as this one, timed apart, and
// compares them.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/paged_gpu_lod.h"
#include "farfield/terrain/terrain_cost.h"

namespace farfield::eval {

struct PagedSpriteOptions {
  double epsilon = 1.0;      // equation 2's threshold, pixels
  float pixel_error = 1.0f;  // keyframes' and high frames' bound, pixels
  float low_error = 4.0f;    // sprite frames' bound, pixels
  bool predict = false;      // keyframes rendered ahead, late, in slices (lod-sprite-gpu-predict)
  double max_magnification = 0.0;  // terrain::LodSpriteOptions::max_magnification (0: equation 2 alone)
  bool cost_correction = true;     // each frame's measured time to the renderer (LodSpriteRenderer::measured)
  int calibration_views = 5; // path cameras the cost model is fitted on (spread along the path)
};

struct PagedSpriteFrame {
  double ms = 0.0;  // the LOD-sprite frame: choice, metric, draws, to the GPU's end
  double own_ms = -1.0;  // of it, in Farfield's own code (wall less the time in GL calls); -1 without GL counters
  uint64_t triangles = 0;
  size_t page_loads = 0;  // pages its draws read themselves (the frame waited; a keyframe's wider view, say)
  terrain::LodSpriteFrameInfo info;
  double psnr_vs_high = -1.0;  // against the CDLOD frame of the same camera, where compared (-1: not)
};

// Farfield's own CPU time of a frame that took wall_ms since the GL counters read `before`: the wall time less the
// time inside GL calls (a final glFinish included) and the measurements' own, as frame_runner.cpp; -1 without the
// counters (gpu/gl_counters.h).
double ownCpuMs(double wall_ms, const gpu::GlCounters& before);
// {"median", "p95"} of the counted values (those >= 0); -1 for both with none.
nlohmann::ordered_json ownCpuSummary(std::vector<double> own_ms);

class PagedSpriteRun {
 public:
  // Needs a current context; terrain must have been made with keep_heights (its metric reads the held pages'
  // heights) and outlive this. Fits the cost model on views of `path` (frames of width x height). Throws
  // farfield::Error for an empty path or bad options.
  PagedSpriteRun(terrain::PagedGpuLodTerrain& terrain, std::span<const Camera> path, const PagedSpriteOptions& options);

  // The LOD-sprite frame at the camera into the target: cleared to the sky, drawn, to the GPU's end, timed.
  PagedSpriteFrame draw(const Camera& camera, gpu::RenderTarget& target);

  // The run's summary beside the CDLOD frames' times (the same frames, in order): "lod_sprite" of tiles.json and a
  // paragraph of tiles.md.
  // high_own_ms: the CDLOD frames' own CPU times (-1 uncounted).
  nlohmann::ordered_json summary(std::span<const PagedSpriteFrame> frames, std::span<const double> high_ms,
                                 std::span<const double> high_own_ms) const;
  static std::string markdown(const nlohmann::ordered_json& summary);

  const terrain::TerrainCost& cost() const { return cost_; }
  double calibrationSeconds() const { return calibration_seconds_; }

 private:
  terrain::PagedGpuLodTerrain& terrain_;
  PagedSpriteOptions options_;
  terrain::TerrainCost cost_;
  double calibration_seconds_ = 0.0;
  std::unique_ptr<terrain::LodSpriteRenderer> renderer_;
};

}  // namespace farfield::eval
