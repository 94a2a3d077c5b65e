// farfield terrain info DEM
// farfield terrain path DEM -o FILE [--frames N] [--fov DEG]
// farfield terrain bench DEM [--path FILE | --frames N] [--epsilon PX] -o OUTDIR [--size WxH] [--high-error PX]
//                        [--low-error PX] [--reference] [--quality-stride K] [--sweep-epsilons LIST]
//                        [--sweep-frames LIST] [--no-sweeps] [--no-section5] [--no-plots] [--no-choice]
//                        [--clearance M] [--full-max-triangles N] [--sprite-tile-cells N]
// farfield terrain tiles DEM -o OUTDIR [--budget-mb MB] [--block N] [--tile-blocks N] [--frames N] [--cache FILE]
//                        [--reuse-cache] [--pixel-error PX] [--check-stride K] [--clearance M] [--size WxH]
//                        [--sprite-tiles CELLS] [--epsilon PX] [--low-error PX] [--render [--cpu-lod]
//                        [--gpu-budget-mb MB] [--prefetch-frames N] [--lod-sprite [--predict] [--psnr-stride K]]]
// DEM: a GeoTIFF / netCDF / 16-bit PNG file or fractal:SIZE[:SEED].
//
// The LOD-sprite experiment (Chen et al. 1999) is eval::runTerrainBench (eval/terrain_bench.h). Its modes are
// registered at start-up here (the executable always links this file), so `farfield bench` can run them too with
// --mode-option terrain=DEM (and high_error=, low_error=, epsilon=).
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"
#include "farfield/eval/terrain_bench.h"
#include "farfield/eval/terrain_modes.h"
#include "farfield/eval/terrain_paths.h"
#include "farfield/eval/terrain_tiles.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/terrain_data.h"

namespace farfield::app {
namespace {

const bool kTerrainModes = (eval::registerTerrainModes(), true);

std::vector<double> parseList(const std::string& option, const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !(v > 0.0)) throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw Error(option, "expected a comma-separated list of positive numbers, got '" + text + "'");
    }
  }
  return out;
}

// The options of `terrain bench` that are text on the command line.
struct BenchText {
  eval::TerrainBenchOptions o;
  std::string size = "512x512";
  std::string sweep_epsilons = "0.25,0.5,1,2,4,8";
  std::string sweep_frames = "75,150,300,600,1200,2400";
  std::string modes =
      "high,high-gpu,low,lod-sprite,lod-sprite-gpu,lod-sprite-gpu-predict,lod-sprite-always,lod-sprite-predict,"
      "lod-sprite-cache";
  bool no_sweeps = false, no_plots = false, no_choice = false, no_section5 = false;
};

void runBench(BenchText& a) {
  configureTimingAllocator();  // frame times, not page faults
  const IVec2 size = parseSize("--size", a.size);
  a.o.width = size.x;
  a.o.height = size.y;
  a.o.modes.clear();
  std::stringstream ss(a.modes);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) a.o.modes.push_back(item);
  a.o.sweep_epsilons = parseList("--sweep-epsilons", a.sweep_epsilons);
  a.o.sweep_frames.clear();
  for (double v : parseList("--sweep-frames", a.sweep_frames))
    a.o.sweep_frames.push_back(wholeNumber<size_t>(v, "--sweep-frames", "frame count"));
  a.o.sweeps = !a.no_sweeps;
  a.o.plots = !a.no_plots;
  a.o.choice = !a.no_choice;
  a.o.section5 = !a.no_section5;
  const eval::TerrainBenchResult result = eval::runTerrainBench(a.o);
  std::printf("\n%s\n", result.markdown.c_str());
  std::printf("wrote %s/{bench.json,terrain.json,terrain.md,figures/} in %.0f s\n", a.o.out_dir.c_str(),
              result.seconds);
}

void runInfo(const std::string& dem, int block) {
  terrain::TerrainLoadOptions o;
  o.block = block;
  const auto data = terrain::TerrainData::load(dem, o);
  std::printf("%s\n", data->describe().c_str());
  std::printf("georeferenced origin of grid point (0, 0): (%.3f, %.3f)\n", data->source.geo_origin.x,
              data->source.geo_origin.y);
  std::printf("LOD: %dx%d grid points in blocks of %d cells, %zu full-resolution triangles\n", data->hf.width,
              data->hf.height, data->lod->block(), size_t(data->hf.width - 1) * size_t(data->hf.height - 1) * 2);
}

void runPath(const std::string& dem, const std::string& output, int frames, float fov) {
  if (frames < 2) throw Error("--frames", "need at least 2 frames");
  if (!(fov > 1.0f && fov < 170.0f)) throw Error("--fov", "must be between 1 and 170 degrees");
  const auto data = terrain::TerrainData::load(dem);
  terrain::FlythroughOptions o;
  o.frames = frames;
  o.fov_deg = fov;
  terrain::FlythroughLandmarks l;
  const gen::CameraPath path = eval::flythroughCameraPath(data->hf, o, &l);
  ensureParentDirectory(output);
  gen::saveCameraPath(path, output);
  std::printf("wrote %s: %d frames; plain (%.0f, %.0f) m, mountains (%.0f, %.0f) m, beyond (%.0f, %.0f) m (terrain "
              "frame: grid point (0, 0) of the cropped grid at the origin)\n",
              output.c_str(), frames, l.plain.x, l.plain.y, l.mountains.x, l.mountains.y, l.beyond.x, l.beyond.y);
}

void runTiles(eval::TerrainTilesOptions& o, const std::string& size) {
  const IVec2 s = parseSize("--size", size);
  o.width = s.x;
  o.height = s.y;
  const eval::TerrainTilesResult result = eval::runTerrainTiles(o);
  std::printf("%s\nwrote %s/{tiles.json,tiles.md,tiles_frames.csv%s%s} in %.0f s\n", result.markdown.c_str(),
              o.out_dir.c_str(), o.lod_sprite ? ",lod_sprite_frames.csv" : "", o.render ? ",frames/" : "",
              result.seconds);
  if (result.check_mismatches > 0) throw Error("--check-stride", "the tiled LOD differed from the whole grid's");
}

const RegisterCommand reg("terrain", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("terrain", "Terrain: DEM info, flythrough paths, LOD-sprite benchmark");
  cmd->require_subcommand(1);

  auto info_dem = std::make_shared<std::string>();
  auto info_block = std::make_shared<int>(128);
  auto* info = cmd->add_subcommand("info", "Load a DEM (or fractal:SIZE:SEED) and describe it");
  info->add_option("dem", *info_dem, "DEM file or fractal:SIZE[:SEED]")->required();
  info->add_option("--block", *info_block, "LOD block size in cells")->capture_default_str();
  info->callback([info_dem, info_block] { runInfo(*info_dem, *info_block); });

  auto export_args = std::make_shared<std::pair<std::string, std::string>>();
  auto* exp = cmd->add_subcommand("export", "Write a DEM (or fractal:SIZE[:SEED][...]) as a Float32 GeoTIFF, e.g. "
                                            "a large fractal for `terrain tiles`, which reads it tile by tile");
  exp->add_option("dem", export_args->first, "DEM file or fractal:SIZE[:SEED][...]")->required();
  exp->add_option("-o,--output", export_args->second, "GeoTIFF to write")->required();
  exp->callback([export_args] {
    const terrain::Heightfield hf = terrain::loadHeightfield(export_args->first);
    terrain::writeDem(hf, export_args->second);
    std::printf("wrote %s: %dx%d points, %.1f m cells, heights %.1f..%.1f m\n", export_args->second.c_str(),
                hf.width, hf.height, hf.cell_x, double(hf.minHeight()), double(hf.maxHeight()));
  });

  struct PathArgs {
    std::string dem, output;
    int frames = 600;
    float fov = 60.0f;
  };
  auto pa = std::make_shared<PathArgs>();
  auto* path = cmd->add_subcommand("path", "Write a Figure-8-style flythrough path (start away, zoom in, plain, "
                                           "mountains, plain beyond)");
  path->add_option("dem", pa->dem, "DEM file or fractal:SIZE[:SEED]")->required();
  path->add_option("-o,--output", pa->output, "Path JSON")->required();
  path->add_option("--frames", pa->frames, "Frames")->capture_default_str();
  path->add_option("--fov", pa->fov, "Vertical field of view, degrees")->capture_default_str();
  path->callback([pa] { runPath(pa->dem, pa->output, pa->frames, pa->fov); });

  auto a = std::make_shared<BenchText>();
  eval::TerrainBenchOptions& o = a->o;
  auto* bench = cmd->add_subcommand("bench", "LOD-sprite benchmark (Chen et al. 1999): high, low and lod-sprite "
                                             "modes through the bench harness, plus the paper's figures");
  bench->add_option("dem", o.dem, "DEM file or fractal:SIZE[:SEED]")->required();
  auto* path_opt = bench->add_option("--path", o.path, "Camera path JSON (default: a flythrough)");
  bench->add_option("--frames", o.frames, "Frames of the generated flythrough")
      ->capture_default_str()
      ->excludes(path_opt);
  bench->add_option("--clearance", o.clearance,
                    "Flythrough height above the ground near it, m (0 = 2% of the diagonal)")
      ->capture_default_str();
  bench->add_option("--epsilon", o.epsilon, "LOD-sprite error threshold, pixels")->capture_default_str();
  bench->add_option("--max-magnification", o.max_magnification,
                    "LOD-sprite: a keyframe also once the sprite is magnified more than this on average (0 = Chen et "
                    "al.'s metric alone)")
      ->capture_default_str();
  bench->add_flag("--no-cost-correction{false}", o.cost_correction,
                  "LOD-sprite's per-frame choice by its cost model alone, not corrected by the measured frames (for "
                  "comparison)");
  bench->add_option("-o,--output", o.out_dir, "Output directory")->required();
  bench->add_option("--size", a->size, "Frame size WxH")->capture_default_str();
  bench->add_option("--high-error", o.high_error, "High-resolution LOD threshold, pixels")->capture_default_str();
  bench->add_option("--low-error", o.low_error, "Low-resolution LOD threshold, pixels")->capture_default_str();
  bench->add_option("--modes", a->modes, "Modes (must include high, low, lod-sprite)")->capture_default_str();
  bench->add_flag("--reference", o.reference, "Also compare every mode with full-geometry frames (harness)");
  bench->add_option("--quality-stride", o.quality_stride, "Measure PSNR against high on every K-th frame")
      ->capture_default_str();
  bench->add_option("--sweep-epsilons", a->sweep_epsilons, "Thresholds for Figures 13 and 14")->capture_default_str();
  bench->add_option("--sweep-frames", a->sweep_frames, "Frame counts for Figure 12")->capture_default_str();
  bench->add_flag("--no-sweeps", a->no_sweeps, "Skip Figures 12-14");
  bench->add_flag("--no-plots", a->no_plots, "CSV only");
  bench->add_flag("--no-section5", a->no_section5, "Skip section 5's variants on the back-and-forth stretch");
  bench->add_flag("--no-choice", a->no_choice,
                  "No cost calibration: lod-sprite takes the sprite path on every frame (as lod-sprite-always)");
  bench->add_option("--python", o.python, "Python interpreter for the plots");
  bench->add_option("--block", o.block, "LOD block size in cells")->capture_default_str();
  bench->add_option("--sprite-tile-cells", o.sprite_tile_cells, "Tile side of the lod-sprite-tiles mode, cells")
      ->capture_default_str();
  bench->add_option("--full-max-triangles", o.full_max_triangles,
                    "Above this many full-resolution triangles the harness's full baseline draws nothing")
      ->capture_default_str();
  bench->callback([a] { runBench(*a); });

  auto t = std::make_shared<std::pair<eval::TerrainTilesOptions, std::string>>();
  t->second = "512x512";
  eval::TerrainTilesOptions& to = t->first;
  auto* tiles = cmd->add_subcommand("tiles", "Large terrain in tiles paged under a memory budget: write the tile "
                                             "cache, fly through it building the LOD per tile, report the paging");
  tiles->add_option("dem", to.dem, "DEM file or fractal:SIZE[:SEED]")->required();
  tiles->add_option("-o,--output", to.out_dir, "Output directory")->required();
  tiles->add_option("--budget-mb", to.budget_mb, "Tile memory budget, MiB")->capture_default_str();
  tiles->add_option("--block", to.block, "LOD block size in cells")->capture_default_str();
  tiles->add_option("--tile-blocks", to.tile_blocks, "LOD blocks per tile side")->capture_default_str();
  tiles->add_option("--frames", to.frames, "Frames of the flythrough")->capture_default_str();
  tiles->add_option("--cache", to.cache, "Tile cache file (default OUTDIR/terrain.tiles)");
  tiles->add_flag("--reuse-cache", to.reuse_cache, "Read the existing tile cache instead of writing it");
  tiles->add_option("--pixel-error", to.pixel_error, "LOD threshold, pixels")->capture_default_str();
  tiles->add_option("--check-stride", to.check_stride, "Compare with the whole grid's LOD every K-th frame")
      ->capture_default_str();
  tiles->add_option("--clearance", to.clearance, "Flythrough clearance, m (0 = the default)")->capture_default_str();
  tiles->add_option("--size", t->second, "Frame size WxH")->capture_default_str();
  tiles->add_option("--sprite-tiles", to.sprite_tile_cells, "Compare sprites per tile of this many cells with the "
                                                            "whole-frame sprite (0 = no)")->capture_default_str();
  tiles->add_option("--epsilon", to.epsilon, "Sprite error threshold, pixels")->capture_default_str();
  tiles->add_option("--low-error", to.low_error, "Low-resolution LOD threshold, pixels")->capture_default_str();
  tiles->add_flag("--render", to.render, "Draw every frame (the CDLOD terrain paged under --gpu-budget-mb; --cpu-lod: "
                                         "the quadtree LOD per tile), timed, with sample frames in OUTDIR/frames");
  tiles->add_option("--gpu-budget-mb", to.gpu_budget_mb, "GPU memory budget of the tiles' patches, MiB")
      ->capture_default_str();
  tiles->add_option("--prefetch-frames", to.prefetch_frames, "With --render: load tiles this many frames ahead of the "
                                                             "camera's motion on a worker thread (0 = on demand)")
      ->capture_default_str();
  tiles->add_flag_callback(
      "--cpu-lod", [t] { t->first.gpu_lod = false; },
      "With --render: draw the quadtree LOD per tile (its patches remade on the CPU and uploaded under "
      "--gpu-budget-mb) instead of the CDLOD terrain paged from the cache (pages of full-resolution heights under "
      "--gpu-budget-mb, an overview for far nodes; the default)");
  tiles->add_flag_callback(
      "--gpu-lod", [t] { t->first.gpu_lod = true; },
      "With --render: the CDLOD terrain (the default; kept for older commands)");
  tiles->add_option("--patch-cells", to.patch_cells, "With --render: quads per CDLOD patch side (a power of two)");
  tiles->add_flag("--lod-sprite", to.lod_sprite,
                  "With --render: draw every frame a second time as LOD-sprite on the same paged terrain (sprite "
                  "frames at --low-error, keyframes at --pixel-error, --epsilon; the choice by a cost model fitted on "
                  "the path's views), timed apart, compared with the CDLOD frame");
  tiles->add_flag("--predict", to.lod_sprite_predict,
                  "With --lod-sprite: keyframes rendered ahead, late, in slices (as lod-sprite-gpu-predict)");
  tiles->add_option("--max-magnification", to.max_magnification,
                    "With --lod-sprite: a keyframe also once the sprite is magnified more than this on average (its "
                    "texels cover more pixels: it blurs); 0 = Chen et al.'s metric alone")
      ->capture_default_str();
  tiles->add_flag("--no-cost-correction{false}", to.cost_correction,
                  "With --lod-sprite: the choice by the cost model alone, not corrected by the measured frames");
  tiles->add_option("--psnr-stride", to.psnr_stride,
                    "With --lod-sprite: compare every K-th frame with the CDLOD frame (0 = never)")
      ->capture_default_str();
  tiles->callback([t] { runTiles(t->first, t->second); });
});

}  // namespace
}  // namespace farfield::app
