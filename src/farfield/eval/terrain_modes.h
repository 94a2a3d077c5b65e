// The terrain benchmark modes of Chen et al. 1999 (LOD-sprite terrain): "high" and "low" (the quadtree LOD mesh at
// two pixel thresholds, original texture), "lod-sprite" (the paper, section 3, choosing per frame between the high
// LOD and the sprite path by the run's calibrated cost model when it has one: terrain/path_choice.h),
// "lod-sprite-always" (the paper's technique on every frame), "lod-sprite-predict" and "lod-sprite-cache"
// (section 5's future work: keyframes rendered ahead; a cache of 8 keyframes).
//
// The modes of one run share one TerrainRun: the terrain, its GPU buffers, the thresholds and the per-frame logs of
// the sprite modes. `farfield terrain bench` (terrain_bench.h) sets it with ScopedTerrainRun; under `farfield bench`
// the first terrain mode loads it from the mode options: terrain=DEM (required), high_error=, low_error=, epsilon=
// (pixels, positive).
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/eval/mode.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/paged_terrain.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_cost.h"
#include "farfield/terrain/terrain_data.h"
#include "farfield/terrain/tile_cache.h"
#include "farfield/terrain/tile_pager.h"
#include "farfield/terrain/tile_sprite_renderer.h"

namespace farfield::eval {

// One frame of a sprite mode: its path frame and what the LOD-sprite renderer decided and drew.
struct SpriteLog {
  size_t path_frame = 0;
  terrain::LodSpriteFrameInfo info;
};

// What the terrain modes of one run share.
struct TerrainRun {
  std::unique_ptr<terrain::TerrainData> data;
  std::unique_ptr<gpu::TerrainRenderer> renderer;  // made by the first gpuRenderer() (needs a current context)
  float high_error = 1.0f;  // LOD thresholds, pixels
  float low_error = 4.0f;
  double epsilon = 1.0;     // LOD-sprite error threshold, pixels
  double max_magnification = 0.0;  // LodSpriteOptions::max_magnification (0: equation 2 alone)
  bool cost_correction = true;     // the sprite modes report each frame's measured time (LodSpriteRenderer::measured;
                                   // --mode-option cost_correction=off to compare)
  int sprite_tile_cells = 128;  // tile side of lod-sprite-tiles, grid cells
  Vec4 sky{0.62f, 0.74f, 0.88f, 1.0f};
  std::optional<terrain::TerrainCost> cost;  // calibrated on this machine; "lod-sprite" chooses per frame with it
  std::map<std::string, std::vector<SpriteLog>> logs;  // sprite mode name -> frames of its last pass

  gpu::TerrainRenderer& gpuRenderer();
  // The CDLOD terrain on the GPU (terrain/gpu_lod.h), made by the first call (needs a current context) with that
  // call's patch size.
  terrain::GpuLodTerrain& gpuLod(int patch_cells = 16);

 private:
  std::unique_ptr<terrain::GpuLodTerrain> gpu_lod_;
};

// The run the terrain modes use; null when none is set (the first terrain mode then loads one from its options).
std::shared_ptr<TerrainRun>& currentTerrainRun();
// The current run, or one loaded from the mode options when none is set: terrain=SPEC (required), high_error=,
// low_error=, epsilon= (pixels), tile_cells=N, terrain_scale=S (heights relative to the terrain's centre times S,
// terrain_data.h: the ground of a city made with `gen city --terrain SPEC --terrain-scale S`).
std::shared_ptr<TerrainRun> terrainRunFor(const ModeContext& context, const std::string& mode);

// Sets the current run for its lifetime and clears it afterwards (also when an exception leaves the scope).
class ScopedTerrainRun {
 public:
  explicit ScopedTerrainRun(std::shared_ptr<TerrainRun> run) { currentTerrainRun() = std::move(run); }
  ~ScopedTerrainRun() { currentTerrainRun().reset(); }
  ScopedTerrainRun(const ScopedTerrainRun&) = delete;
  ScopedTerrainRun& operator=(const ScopedTerrainRun&) = delete;
};

// `high` and `low`: the LOD mesh with the original texture. With gpu, `high-gpu` and `low-gpu`: the CDLOD terrain
// (terrain/cdlod.h) at the same thresholds, selected on the CPU and drawn as one instanced draw whose vertex shader
// fetches heights and morphs between levels; mode option patch_cells=P (quads per patch side, a power of two,
// default 16). info(): pixel_error, and with gpu patch_cells, levels, nodes_mean (drawn per frame), gpu_bytes.
class LodMode : public Mode {
 public:
  LodMode(std::string name, bool high, bool gpu = false) : name_(std::move(name)), high_(high), gpu_(gpu) {}
  std::string name() const override { return name_; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::map<std::string, double> info() const override;

 private:
  std::string name_;
  bool high_, gpu_;
  std::shared_ptr<TerrainRun> run_;
  terrain::LodMesh mesh_;
  size_t frames_ = 0, nodes_ = 0;
};

// `high-tiles`: the high LOD built per tile from a tile cache of the run's terrain paged under a budget
// (terrain/tiled_lod.h; the same mesh as `high` up to triangles outside the frustum), each tile drawn from its own
// GPU patch paged under a GPU budget (terrain/paged_terrain.h; its texture computed from its heights at one texel a
// point of its step, not a texture given to the run). Mode options: tile_blocks=N (LOD blocks per tile side,
// default 4), tile_budget_mb=MB (default 256), gpu_budget_mb=MB (default 256). The cache is written at prepare() to
// a temporary file, removed with the mode. info(): pixel_error, tile and patch loads, evictions, peak bytes.
class TiledLodMode : public Mode {
 public:
  TiledLodMode() = default;
  ~TiledLodMode() override;
  std::string name() const override { return "high-tiles"; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::map<std::string, double> info() const override;

 private:
  std::shared_ptr<TerrainRun> run_;
  std::string cache_path_;
  std::unique_ptr<terrain::TileCache> cache_;
  std::unique_ptr<terrain::TilePager> pager_;
  std::unique_ptr<terrain::PagedTerrainRenderer> paged_;
};

// Paper: "lod-sprite" (with the run's cost model, the per-frame choice); Always: "lod-sprite-always" (every frame the
// sprite path, whatever it costs).
enum class SpriteVariant { Paper, Always, Predict, Cache };

// The LOD-sprite options of a variant with the run's thresholds (epsilon, pixels, > 0); the one place the
// variants are defined, shared by the modes and the terrain bench's quality pass.
// gpu_high: the sprite renderer draws with that CDLOD terrain: its keyframes and high frames
// (LodSpriteOptions::gpu_high), and for the variants without prediction or cache its sprite frames too (gpu_low);
// with the choice, the run's cost model must then have their frames (gpu_high and gpu_sprite fitted).
terrain::LodSpriteOptions spriteOptions(const TerrainRun& run, SpriteVariant variant, double epsilon,
                                        terrain::GpuLodTerrain* gpu_high = nullptr);
// What calibrateTerrainCost times for lod-sprite's choice on `views` (frames of width x height): the keyframe target
// with the guard band, and LOD thresholds spread around the run's high and low ones.
// gpu_high: also time that CDLOD terrain's frames (TerrainCost::gpu_high).
terrain::TerrainCostOptions spriteCostOptions(const TerrainRun& run, std::vector<Camera> views, int width, int height,
                                              terrain::GpuLodTerrain* gpu_high = nullptr);
// "lod-sprite" -> Paper, "lod-sprite-always" -> Always, "lod-sprite-predict" -> Predict, "lod-sprite-cache" -> Cache; false for other names.
// "lod-sprite-gpu" is the Paper variant drawn by the CDLOD terrain on the GPU: keyframes, high and sprite frames;
// "lod-sprite-gpu-predict" the Predict variant drawn so, which keeps the per-frame choice.
bool spriteVariantOf(const std::string& mode_name, SpriteVariant& variant, bool* gpu_high = nullptr);

// `lod-sprite` and its section 5 variants. Each pass over the path (the harness's warm-up frame is one) starts
// from scratch, so the measured pass renders its own first keyframe. epsilon 0 = the run's.
class SpriteMode : public Mode {
 public:
  SpriteMode(std::string name, SpriteVariant variant, double epsilon = 0.0, bool gpu_high = false)
      : name_(std::move(name)), variant_(variant), epsilon_(epsilon), gpu_high_(gpu_high) {}
  std::string name() const override { return name_; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  // epsilon_px, frames, keyframes (fresh), keyframe_fraction, high_resolution_renders, predicted_rendered,
  // predicted_used, predicted_discarded, predicted_finished, cache_hits, high_frames, high_frame_fraction,
  // virtual_keyframes, switches, keyframe_decisions (fresh - switches + virtual: where the error metric tripped)
  // (of the last pass).
  // correction_high, correction_sprite, correction_keyframe, correction_slice: the cost model's measured / predicted
  // per kind of frame at the end (1: none measured), and correction_measurements.
  std::map<std::string, double> info() const override;
  // The harness's wall time of the frame just drawn, to the renderer's cost correction (LodSpriteRenderer::measured).
  void frameMeasured(size_t path_frame, double wall_ms) override;
  terrain::LodSpriteRenderer& sprite() { return *sprite_; }

 private:
  std::string name_;
  SpriteVariant variant_;
  double epsilon_;
  bool gpu_high_;
  std::shared_ptr<TerrainRun> run_;
  std::unique_ptr<terrain::LodSpriteRenderer> sprite_;
  bool started_ = false;
  size_t last_frame_ = 0;
  uint64_t last_sprite_frame_ = 0;  // the renderer's count of the frame just drawn
};

// The options of the tile mode `mode_name` with the run's thresholds (the mode's and the quality pass's), with the
// run's cost model (the per-frame choice) for the modes that choose, when the run has one.
terrain::TileSpriteRenderOptions tileSpriteOptions(const TerrainRun& run, const std::string& mode_name);
// "lod-sprite-tiles" (with the per-frame choice), "lod-sprite-tiles-each-frame" (the choice made on every frame, no
// carried runs of the high LOD) and "lod-sprite-tiles-always" (the tile path on every frame).
bool isTileSpriteMode(const std::string& mode_name, bool* choose = nullptr);

// `lod-sprite-tiles`: a sprite per terrain tile (terrain/tile_sprite_renderer.h), choosing per frame between the tiles
// and the high LOD by the run's calibrated cost; `lod-sprite-tiles-each-frame`: the same choice made on every frame
// (TileSpriteRenderOptions::max_carried_high 0); `lod-sprite-tiles-always`: the tile path on every frame. Each pass
// over the path starts from scratch, as SpriteMode's. Under `farfield bench`: --mode-option tile_cells=N.
class TileSpriteMode : public Mode {
 public:
  explicit TileSpriteMode(std::string name) : name_(std::move(name)) {}
  std::string name() const override { return name_; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  // epsilon_px, tile_cells, frames, tile_keyframes, frames_with_keyframes (share too), tile_frames_in_view,
  // tile_keyframe_fraction (of tile-frames in view), view_framed_keyframes, keyframe_triangles_per_frame,
  // sprite_triangle_share (of the low mesh's triangles), peak_sprites, peak_sprite_bytes (of the last pass),
  // high_frames and high_frame_fraction (frames drawn as the high LOD by the choice), carried_high_frames (of those,
  // drawn on an earlier frame's choice without deciding).
  std::map<std::string, double> info() const override;

 private:
  std::string name_;
  std::shared_ptr<TerrainRun> run_;
  std::unique_ptr<terrain::TileSpriteRenderer> sprite_;
  bool started_ = false;
  size_t last_frame_ = 0;
};

// Adds high, high-tiles, low, lod-sprite, lod-sprite-always, lod-sprite-predict, lod-sprite-cache, lod-sprite-tiles,
// lod-sprite-tiles-each-frame and lod-sprite-tiles-always to the mode registry (mode.h). Idempotent.
// Called by runTerrainBench and by the executable at start-up (the eval library is static: a static registration
// object in it would be dropped by the linker).
void registerTerrainModes();

}  // namespace farfield::eval
