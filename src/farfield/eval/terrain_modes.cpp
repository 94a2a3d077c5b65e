// Benchmark modes of Chen et al. 1999, LOD-sprite terrain (section 3 and section 5's future work).
#include "farfield/eval/terrain_modes.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <filesystem>
#include <stdexcept>

#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"
#include "farfield/eval/city_on_terrain_mode.h"
#include "farfield/eval/mode_options.h"
#include "farfield/terrain/tiled_lod.h"

namespace farfield::eval {

std::shared_ptr<TerrainRun> terrainRunFor(const ModeContext& context, const std::string& mode) {
  std::shared_ptr<TerrainRun>& run = currentTerrainRun();
  if (!run) {
    auto loaded = std::make_shared<TerrainRun>();
    terrain::TerrainLoadOptions load;
    if (!context.option("terrain_scale").empty())
      load.centred_scale =
          checkedCast<float>(positiveOption(context, "terrain_scale", 1.0), "--mode-option terrain_scale", "value");
    loaded->data = terrain::TerrainData::load(context.requireOption("terrain", mode), load);
    loaded->high_error =
        checkedCast<float>(positiveOption(context, "high_error", loaded->high_error), "--mode-option high_error", "value");
    loaded->low_error =
        checkedCast<float>(positiveOption(context, "low_error", loaded->low_error), "--mode-option low_error", "value");
    loaded->epsilon = positiveOption(context, "epsilon", loaded->epsilon);
    loaded->max_magnification = numberOption(context, "max_magnification", 0.0, 0.0);
    loaded->sprite_tile_cells = intOption(context, "tile_cells", loaded->sprite_tile_cells, 1, 1 << 20);
    loaded->cost_correction = switchOption(context, "cost_correction", loaded->cost_correction);
    if (context.renderer) loaded->sky = context.renderer->light().sky_color;
    run = std::move(loaded);
  }
  return run;
}


gpu::TerrainRenderer& TerrainRun::gpuRenderer() {
  if (!renderer) {
    Vec2 scale, offset;
    terrain::texCoordTransform(data->hf, scale, offset);
    renderer = std::make_unique<gpu::TerrainRenderer>(data->lod->positions(), data->texture, scale, offset);
  }
  return *renderer;
}

terrain::GpuLodTerrain& TerrainRun::gpuLod(int patch_cells) {
  if (!gpu_lod_) {
    terrain::CdlodOptions options;
    options.patch_cells = patch_cells;
    gpu_lod_ = std::make_unique<terrain::GpuLodTerrain>(data->hf, data->texture, options);
  }
  return *gpu_lod_;
}

std::shared_ptr<TerrainRun>& currentTerrainRun() {
  static std::shared_ptr<TerrainRun> run;
  return run;
}

void LodMode::prepare(const ModeContext& context) {
  run_ = terrainRunFor(context, name_);
  frames_ = nodes_ = 0;
  if (!gpu_) {
    run_->gpuRenderer();
    return;
  }
  const int patch = intOption(context, "patch_cells", 16, 2, 128);
  if ((patch & (patch - 1)) != 0)
    throw Error("--mode-option patch_cells", "must be a power of two, got " + std::to_string(patch));
  run_->gpuLod(patch);
}

void LodMode::frame(FrameContext& frame) {
  gpu::RenderTarget& target = frame.beginOwnPass();
  const float error = high_ ? run_->high_error : run_->low_error;
  if (gpu_) {
    const terrain::GpuLodFrame drawn = run_->gpuLod().draw(frame.camera(), error, target);
    frame.addStats(drawn.draw);
    ++frames_;
    nodes_ += drawn.nodes;
    return;
  }
  frame.addStats(terrain::renderLodFrame(*run_->data->lod, run_->gpuRenderer(), frame.camera(),
                                         terrain::LodSettings{error, true, false}, target, mesh_));
}

std::map<std::string, double> LodMode::info() const {
  std::map<std::string, double> out{{"pixel_error", high_ ? run_->high_error : run_->low_error}};
  if (gpu_) {
    terrain::GpuLodTerrain& lod = run_->gpuLod();
    out["patch_cells"] = double(lod.lod().patchCells());
    out["levels"] = double(lod.lod().levels());
    out["nodes_mean"] = frames_ ? double(nodes_) / double(frames_) : 0.0;
    out["gpu_bytes"] = double(lod.gpuBytes());
  }
  return out;
}

TiledLodMode::~TiledLodMode() {
  paged_.reset();
  pager_.reset();
  cache_.reset();
  if (!cache_path_.empty()) {
    std::error_code ec;
    std::filesystem::remove(cache_path_, ec);
  }
}

void TiledLodMode::prepare(const ModeContext& context) {
  run_ = terrainRunFor(context, name());
  run_->gpuRenderer();
  const int tile_blocks = intOption(context, "tile_blocks", 4, 1, 1 << 16);
  const uint64_t budget = mebibytesOption(context, "tile_budget_mb", uint64_t(256) << 20);
  static std::atomic<int> serial{0};
  cache_path_ = (std::filesystem::temp_directory_path() /
                 ("farfield-high-tiles-" + std::to_string(::getpid()) + "-" + std::to_string(serial++) + ".tiles"))
                    .string();
  terrain::TileCache::write(run_->data->hf, run_->data->lod->block(), tile_blocks, cache_path_);
  cache_ = std::make_unique<terrain::TileCache>(cache_path_);
  pager_ = std::make_unique<terrain::TilePager>(*cache_, size_t(budget));
  paged_ = std::make_unique<terrain::PagedTerrainRenderer>(
      *pager_, size_t(mebibytesOption(context, "gpu_budget_mb", uint64_t(256) << 20)));
}

void TiledLodMode::frame(FrameContext& frame) {
  gpu::RenderTarget& target = frame.beginOwnPass();
  frame.addStats(paged_->draw(frame.camera(), terrain::LodSettings{run_->high_error, true, false}, target).draw);
}

std::map<std::string, double> TiledLodMode::info() const {
  const terrain::TilePagerStats& s = pager_->stats();
  return {{"pixel_error", run_->high_error},
          {"tile_loads", double(s.loads)},
          {"tile_evictions", double(s.evictions)},
          {"tile_peak_resident_bytes", double(s.peak_resident_bytes)},
          {"tile_budget_bytes", double(pager_->budget())},
          {"patch_loads", double(paged_->stats().loads)},
          {"patch_evictions", double(paged_->stats().evictions)},
          {"patch_peak_gpu_bytes", double(paged_->stats().peak_gpu_bytes)},
          {"patch_gpu_budget_bytes", double(paged_->budget())}};
}

terrain::LodSpriteOptions spriteOptions(const TerrainRun& run, SpriteVariant variant, double epsilon,
                                        terrain::GpuLodTerrain* gpu_high) {
  terrain::LodSpriteOptions o;
  o.gpu_high = gpu_high;
  o.gpu_low = gpu_high != nullptr;
  o.epsilon = epsilon;
  o.max_magnification = run.max_magnification;
  o.high_error = run.high_error;
  o.low_error = run.low_error;
  o.sky_color = run.sky;
  // On the GPU, keyframes rendered ahead keep the per-frame choice: the variant is the best this path has.
  const bool choose = variant == SpriteVariant::Paper || (gpu_high && variant == SpriteVariant::Predict);
  if (choose && run.cost && (!gpu_high || (run.cost->gpu_high && run.cost->gpu_sprite))) o.cost = &*run.cost;
  if (variant == SpriteVariant::Predict) o.predict = true;
  // A CDLOD keyframe costs several sprite frames (llvmpipe: 3-7): it is spread over up to 16 of them, sized by the
  // cost model, and rendered ahead late, when the current sprite is about to trip: a short extrapolation.
  if (variant == SpriteVariant::Predict && gpu_high) {
    o.predict_chunks = 16;
    o.predict_late = true;
  }
  if (variant == SpriteVariant::Cache) o.cache_size = 8;
  return o;
}

terrain::TerrainCostOptions spriteCostOptions(const TerrainRun& run, std::vector<Camera> views, int width, int height,
                                              terrain::GpuLodTerrain* gpu_high) {
  terrain::TerrainCostOptions c;
  c.gpu_high = gpu_high;
  c.views = std::move(views);
  const Camera key = terrain::guardBandCamera(Camera{}, width, height, terrain::LodSpriteOptions{}.keyframe_margin);
  c.keyframe_width = key.width;
  c.keyframe_height = key.height;
  c.pixel_errors = {run.high_error, 2.0f * run.high_error, run.low_error, 4.0f * run.low_error};
  return c;
}

bool spriteVariantOf(const std::string& mode_name, SpriteVariant& variant, bool* gpu_high) {
  if (gpu_high) *gpu_high = mode_name == "lod-sprite-gpu" || mode_name == "lod-sprite-gpu-predict";
  if (mode_name == "lod-sprite" || mode_name == "lod-sprite-gpu") variant = SpriteVariant::Paper;
  else if (mode_name == "lod-sprite-gpu-predict") variant = SpriteVariant::Predict;
  else if (mode_name == "lod-sprite-always") variant = SpriteVariant::Always;
  else if (mode_name == "lod-sprite-predict") variant = SpriteVariant::Predict;
  else if (mode_name == "lod-sprite-cache") variant = SpriteVariant::Cache;
  else return false;
  return true;
}

void SpriteMode::prepare(const ModeContext& context) {
  run_ = terrainRunFor(context, name_);
  const terrain::LodSpriteOptions o = spriteOptions(*run_, variant_, epsilon_ > 0.0 ? epsilon_ : run_->epsilon,
                                                    gpu_high_ ? &run_->gpuLod() : nullptr);
  sprite_ = std::make_unique<terrain::LodSpriteRenderer>(*run_->data->lod, run_->gpuRenderer(), context.width,
                                                         context.height, o);
}

void SpriteMode::frame(FrameContext& frame) {
  // A path frame at or before the last one starts a new pass (the harness's warm-up frame was the first pass).
  if (started_ && frame.pathFrame() <= last_frame_) {
    sprite_->reset();
    run_->logs[name_].clear();
  }
  started_ = true;
  last_frame_ = frame.pathFrame();
  gpu::RenderTarget& target = frame.beginOwnPass();
  SpriteLog log;
  log.path_frame = frame.pathFrame();
  frame.addStats(sprite_->render(frame.camera(), target, &log.info));
  last_sprite_frame_ = log.info.frame;
  run_->logs[name_].push_back(log);
}

void SpriteMode::frameMeasured(size_t /*path_frame*/, double wall_ms) {
  if (run_->cost_correction) sprite_->measured(last_sprite_frame_, wall_ms);
}

std::map<std::string, double> SpriteMode::info() const {
  const terrain::LodSpriteCounters& c = sprite_->counters();
  const double frames = double(std::max<size_t>(c.frames, 1));
  return {{"epsilon_px", sprite_->options().epsilon},
          {"frames", double(c.frames)},
          {"keyframes", double(c.fresh_keyframes)},
          {"keyframe_fraction", double(c.fresh_keyframes) / frames},
          {"high_resolution_renders", double(c.highResolutionRenders())},
          {"predicted_rendered", double(c.predicted_rendered)},
          {"predicted_used", double(c.predicted_used)},
          {"predicted_discarded", double(c.predicted_discarded)},
          {"predicted_finished", double(c.predicted_finished)},
          {"cache_hits", double(c.cache_hits)},
          {"high_frames", double(c.high_frames)},
          {"high_frame_fraction", double(c.high_frames) / frames},
          {"virtual_keyframes", double(c.virtual_keyframes)},
          {"switches", double(c.switches)},
          {"keyframe_decisions", double(c.fresh_keyframes - c.switches + c.virtual_keyframes)},
          {"correction_high", sprite_->costCorrection().factor(terrain::TerrainFrameKind::High)},
          {"correction_sprite", sprite_->costCorrection().factor(terrain::TerrainFrameKind::Sprite)},
          {"correction_keyframe", sprite_->costCorrection().factor(terrain::TerrainFrameKind::Keyframe)},
          {"correction_slice", sprite_->costCorrection().factor(terrain::TerrainFrameKind::Slice)},
          {"correction_measurements", double(sprite_->costCorrection().measurementsUsed())}};
}

bool isTileSpriteMode(const std::string& mode_name, bool* choose) {
  if (mode_name != "lod-sprite-tiles" && mode_name != "lod-sprite-tiles-always" &&
      mode_name != "lod-sprite-tiles-each-frame")
    return false;
  if (choose) *choose = mode_name != "lod-sprite-tiles-always";
  return true;
}

terrain::TileSpriteRenderOptions tileSpriteOptions(const TerrainRun& run, const std::string& mode_name) {
  terrain::TileSpriteRenderOptions o;
  bool choose = false;
  isTileSpriteMode(mode_name, &choose);
  if (choose && run.cost) o.cost = &*run.cost;
  if (mode_name == "lod-sprite-tiles-each-frame") o.max_carried_high = 0;
  o.tile_cells = run.sprite_tile_cells;
  o.epsilon = run.epsilon;
  o.high_error = run.high_error;
  o.low_error = run.low_error;
  o.sky_color = run.sky;
  return o;
}

void TileSpriteMode::prepare(const ModeContext& context) {
  run_ = terrainRunFor(context, name());
  sprite_ = std::make_unique<terrain::TileSpriteRenderer>(*run_->data->lod, run_->gpuRenderer(), context.width,
                                                          context.height,
                                                          tileSpriteOptions(*run_, name_));
}

void TileSpriteMode::frame(FrameContext& frame) {
  // A path frame at or before the last one starts a new pass (the harness's warm-up frame was the first pass).
  if (started_ && frame.pathFrame() <= last_frame_) sprite_->reset();
  started_ = true;
  last_frame_ = frame.pathFrame();
  frame.addStats(sprite_->render(frame.camera(), frame.beginOwnPass()));
}

std::map<std::string, double> TileSpriteMode::info() const {
  const terrain::TileSpriteCounters& c = sprite_->counters();
  const double frames = double(std::max<size_t>(c.frames, 1));
  return {{"epsilon_px", sprite_->options().epsilon},
          {"tile_cells", double(sprite_->options().tile_cells)},
          {"frames", double(c.frames)},
          {"tile_keyframes", double(c.tile_keyframes)},
          {"frames_with_keyframes", double(c.frames_with_keyframes)},
          {"keyframe_fraction", double(c.frames_with_keyframes) / frames},
          {"tile_frames_in_view", double(c.tile_frames_in_view)},
          {"tile_keyframe_fraction", double(c.tile_keyframes) / double(std::max<size_t>(c.tile_frames_in_view, 1))},
          {"view_framed_keyframes", double(c.view_framed_keyframes)},
          {"keyframe_triangles_per_frame", double(c.keyframe_triangles) / frames},
          {"sprite_triangle_share", double(c.sprite_triangles) / double(std::max<uint64_t>(c.low_triangles, 1))},
          {"peak_sprites", double(c.peak_sprites)},
          {"peak_sprite_bytes", double(c.peak_sprite_bytes)},
          {"high_frames", double(c.high_frames)},
          {"high_frame_fraction", double(c.high_frames) / frames},
          {"carried_high_frames", double(c.carried_high_frames)}};
}

void registerTerrainModes() {
  registerMode("high", "terrain: high-resolution quadtree LOD (--mode-option terrain=DEM)",
               [](const ModeContext&) { return std::make_unique<LodMode>("high", true); });
  registerMode("high-gpu", "terrain: CDLOD on the GPU at the high threshold (--mode-option terrain=DEM)",
               [](const ModeContext&) { return std::make_unique<LodMode>("high-gpu", true, true); });
  registerMode("low-gpu", "terrain: CDLOD on the GPU at the low threshold (--mode-option terrain=DEM)",
               [](const ModeContext&) { return std::make_unique<LodMode>("low-gpu", false, true); });
  registerMode("high-tiles",
               "terrain: the high LOD built per tile from tiles paged under a budget (--mode-option terrain=DEM, "
               "tile_blocks=N, tile_budget_mb=MB)",
               [](const ModeContext&) { return std::make_unique<TiledLodMode>(); });
  registerMode("low", "terrain: low-resolution quadtree LOD (--mode-option terrain=DEM)",
               [](const ModeContext&) { return std::make_unique<LodMode>("low", false); });
  registerMode("lod-sprite",
               "terrain: LOD-sprite, Chen et al. 1999, choosing per frame between it and the high LOD by the calibrated "
               "cost (terrain bench; --mode-option terrain=DEM, epsilon=PX)",
               [](const ModeContext&) { return std::make_unique<SpriteMode>("lod-sprite", SpriteVariant::Paper); });
  registerMode("lod-sprite-gpu",
               "terrain: LOD-sprite drawn by the CDLOD terrain on the GPU (keyframes, high frames, and sprite frames tested "
               "against the keyframe's depth in the vertex shader), choosing per frame by the costs of those frames "
               "(terrain bench)",
               [](const ModeContext&) {
                 return std::make_unique<SpriteMode>("lod-sprite-gpu", SpriteVariant::Paper, 0.0, true);
               });
  registerMode("lod-sprite-gpu-predict",
               "terrain: lod-sprite-gpu with keyframes rendered ahead (section 5), late and in slices of a third of a "
               "sprite frame by the cost model, so that no frame draws a whole keyframe (terrain bench)",
               [](const ModeContext&) {
                 return std::make_unique<SpriteMode>("lod-sprite-gpu-predict", SpriteVariant::Predict, 0.0, true);
               });
  registerMode("lod-sprite-always", "terrain: LOD-sprite on every frame, the paper's technique without the choice",
               [](const ModeContext&) {
                 return std::make_unique<SpriteMode>("lod-sprite-always", SpriteVariant::Always);
               });
  registerMode("lod-sprite-predict", "terrain: LOD-sprite with keyframes rendered ahead (section 5)",
               [](const ModeContext&) {
                 return std::make_unique<SpriteMode>("lod-sprite-predict", SpriteVariant::Predict);
               });
  registerMode("lod-sprite-cache", "terrain: LOD-sprite with a cache of 8 keyframes (section 5)",
               [](const ModeContext&) {
                 return std::make_unique<SpriteMode>("lod-sprite-cache", SpriteVariant::Cache);
               });
  registerCityOnTerrainModes();
  registerMode("lod-sprite-tiles",
               "terrain: LOD-sprite with a sprite per terrain tile, choosing per frame between it and the high LOD "
               "by the calibrated cost (--mode-option tile_cells=N)",
               [](const ModeContext&) { return std::make_unique<TileSpriteMode>("lod-sprite-tiles"); });
  registerMode("lod-sprite-tiles-always", "terrain: LOD-sprite with a sprite per terrain tile on every frame",
               [](const ModeContext&) { return std::make_unique<TileSpriteMode>("lod-sprite-tiles-always"); });
  registerMode("lod-sprite-tiles-each-frame",
               "terrain: lod-sprite-tiles deciding on every frame, without runs of frames carried on a choice of "
               "the high LOD (the baseline of those runs)",
               [](const ModeContext&) { return std::make_unique<TileSpriteMode>("lod-sprite-tiles-each-frame"); });
}

}  // namespace farfield::eval
