// The tiled-terrain experiment (issue 18: large terrains held in tiles and paged under a memory budget, the
// quadtree LOD of Chen et al. 1999 section 2.2 built per tile): a DEM or fractal is written as a tile cache
// (terrain/tile_cache.h). A DEM file is read tile by tile and never held whole, and the flythrough is planned on the
// cache's overview, unless the whole grid's LOD is asked for (the check, the sprites per tile); a fractal is
// generated whole, written, and dropped. The flythrough builds the LOD every frame from tiles paged under the budget
// (terrain/tile_pager.h, terrain/tiled_lod.h). Reports per frame the triangles, the tiles in view and at full
// resolution, the resident bytes, loads and evictions, and the process's peak resident set; optionally checks the
// mesh against the whole grid's LOD on every K-th frame (small terrains: that LOD holds the whole grid), and
// compares sprites per tile with the whole-frame sprite (terrain/tile_sprites.h).
#pragma once

#include <cstddef>
#include <string>

namespace farfield::eval {

struct TerrainTilesOptions {
  std::string dem;         // DEM file or fractal:SIZE[:SEED][...] (terrain_data.h)
  std::string out_dir;     // tiles.json, tiles.md, tiles_frames.csv (and terrain.tiles unless cache is set)
  std::string cache;       // tile cache path; "" = OUT/terrain.tiles
  bool reuse_cache = false;  // read an existing cache instead of writing it
  int block = 128;         // LOD block, cells
  int tile_blocks = 8;     // blocks per tile side
  double budget_mb = 256;  // the pager's budget, MiB
  int frames = 600;
  float clearance = 0.0f;  // flythrough clearance, m (0 = the generator's default)
  int width = 512, height = 512;
  float pixel_error = 1.0f;  // LOD threshold, pixels (the high LOD)
  size_t check_stride = 0;   // compare with the whole grid's LOD (no culling) every K-th frame; 0 = never
  // Sprites per tile (terrain/tile_sprites.h) against the whole-frame sprite on the same frames, render-free:
  // tiles of this many cells (0 = not run; needs the whole grid's LOD in memory), at epsilon pixels, the low LOD at
  // low_error pixels and keyframes at pixel_error.
  int sprite_tile_cells = 0;
  double epsilon = 1.0;
  float low_error = 4.0f;
  // Draw every frame from the tiles' GPU patches (terrain/paged_terrain.h) paged under gpu_budget_mb, timed to the
  // end of the GPU's work, with every sample_stride-th frame written to OUT/frames; tiles prefetched on a worker
  // thread prefetch_frames ahead.
  bool render = false;
  double gpu_budget_mb = 256;
  int prefetch_frames = 32;  // with render: tiles loaded ahead along the camera's motion (0 = every tile on demand)
  size_t sample_stride = 100;
  // With render: draw with the CDLOD terrain paged from the cache (terrain/paged_gpu_lod.h: pages of full-resolution
  // heights and colours under gpu_budget_mb, an overview for the far nodes; no per-frame CPU mesh), the default;
  // false: the quadtree LOD per tile, its patches remade on the CPU and uploaded (--cpu-lod).
  bool gpu_lod = true;
  int patch_cells = 16;
  // With the CDLOD terrain: each frame drawn a second time as LOD-sprite wholly on the same paged terrain
  // (terrain_tiles_sprite.h: keyframes and high frames the CDLOD frames at pixel_error, sprite frames at low_error,
  // equation 2 at epsilon, the per-frame choice by a cost model fitted at start on the path's views), timed apart
  // from the CDLOD frame, the pages read ahead outside both; every psnr_stride-th frame compared with the CDLOD frame
  // (untimed). lod_sprite_predict: keyframes rendered ahead, late, in slices.
  bool lod_sprite = false;
  bool lod_sprite_predict = false;
  double max_magnification = 0.0;  // with lod_sprite: terrain::LodSpriteOptions::max_magnification
  bool cost_correction = true;     // with lod_sprite: the choice's model corrected by the measured frames
  size_t psnr_stride = 10;
};

struct TerrainTilesResult {
  std::string markdown;
  double seconds = 0.0;
  size_t check_mismatches = 0;  // checked frames whose mesh differed from the whole grid's
};

// Throws farfield::Error for bad options or input.
TerrainTilesResult runTerrainTiles(const TerrainTilesOptions& options);

}  // namespace farfield::eval
