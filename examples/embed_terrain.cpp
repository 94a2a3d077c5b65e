// Embedding Farfield's terrain in a render loop, the way an engine does (docs/EMBEDDING.md, "Add a large terrain"):
//
//   embed_terrain TERRAIN CACHE [FRAMES] [OUT.png]
//
// TERRAIN is a DEM file (GeoTIFF, netCDF, 16-bit PNG) or fractal:SIZE[:SEED][...]; CACHE the tile cache, written
// from it once when missing (the DEM read window by window, never whole). The program flies FRAMES frames (at least
// 10; default 120) of a flythrough at 640x360, drawing each frame with LOD-sprite (Chen et al. 1999) wholly on the
// CDLOD terrain paged from the cache: keyframes and high frames are CDLOD frames at 1 px, sprite frames its 4 px
// selection with the keyframe's visibility tested per vertex on the GPU; a cost model fitted on a few views of the
// path chooses per frame between them, corrected by the frames' GPU times read a few frames late (a timer query per
// frame, no wait); pages are read ahead on a worker. It prints what LOD-sprite chose and writes the last frame.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/late_readback.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/png_io.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/flythrough.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/paged_gpu_lod.h"
#include "farfield/terrain/terrain_cost.h"
#include "farfield/terrain/terrain_data.h"
#include "farfield/terrain/tile_cache.h"

using namespace farfield;

namespace {

const Vec4 kSky{0.62f, 0.74f, 0.88f, 1.0f};
constexpr int kWidth = 640, kHeight = 360;

// The tile cache: blocks of 128 cells, tiles of 4 x 4 blocks (smaller for a small terrain).
void writeCache(const std::string& terrain, const std::string& cache) {
  const Stopwatch clock;
  if (terrain::isFractalSpec(terrain)) {
    const terrain::Heightfield whole = terrain::loadHeightfield(terrain);
    const int block = whole.width > 1024 ? 128 : 32;
    terrain::TileCache::write(terrain::cropForBlocks(whole, block), block, 4, cache);
  } else {
    terrain::TileCache::write(terrain::DemReader(terrain), 128, 4, cache);
  }
  std::printf("wrote the tile cache %s in %.1f s\n", cache.c_str(), clock.seconds());
}

// The camera of a flythrough viewpoint, with clip planes for a terrain of this extent.
Camera cameraAt(const terrain::Viewpoint& v, float far_plane) {
  Camera c;
  c.eye = v.eye;
  c.at = v.at;
  c.up = Vec3(0.0f, 0.0f, 1.0f);
  c.fov_y = v.fov_y;
  c.width = kWidth;
  c.height = kHeight;
  c.near_plane = 1.0f;
  c.far_plane = far_plane;
  return c;
}

int run(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: embed_terrain TERRAIN CACHE [FRAMES] [OUT.png]\n");
    return 2;
  }
  const std::string terrain_spec = argv[1], cache_path = argv[2];
  int frames = 120;
  if (argc > 3) {
    size_t used = 0;
    try {
      frames = std::stoi(argv[3], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || argv[3][used] != '\0' || frames < 10)
      throw Error("FRAMES", std::string("expected a whole number of frames, at least 10; got '") + argv[3] + "'");
  }
  if (!std::filesystem::exists(cache_path)) writeCache(terrain_spec, cache_path);
  const terrain::TileCache cache(cache_path);

  // The flight, planned on the cache's overview (every 8th point: the whole grid is never held).
  const terrain::Heightfield overview = cache.overview(std::min(8, cache.layout().block / 2));
  terrain::FlythroughOptions fo;
  fo.frames = frames;
  const std::vector<terrain::Viewpoint> path = terrain::flythroughPath(overview, fo);
  const float far_plane = float(4.0 * (overview.extentX() + overview.extentY()));

  gpu::sharedHeadlessContext().makeCurrent();
  terrain::PagedGpuLodOptions po;
  po.gpu_budget_bytes = size_t(256) << 20;
  po.keep_heights = true;  // LOD-sprite's error metric reads the held pages' heights
  terrain::PagedGpuLodTerrain ground(cache, po);

  // The cost model of this machine's CDLOD frames and sprite frames, on five views of the path (the engine's loading
  // screen); keyframes are the frame's size with LOD-sprite's guard band.
  terrain::TerrainCostOptions co;
  for (int k = 0; k < 5; ++k) co.views.push_back(cameraAt(path[size_t((2 * k + 1) * frames / 10)], far_plane));
  const Camera key = terrain::guardBandCamera(co.views.front(), kWidth, kHeight, 0.1f);
  co.keyframe_width = key.width;
  co.keyframe_height = key.height;
  const Stopwatch calibration;
  const terrain::TerrainCost cost = terrain::calibrateCdlodCost(ground, co);
  std::printf("cost model fitted in %.1f s: CDLOD frame %.3f ms + %.1f ms per million triangles, sprite frame %.3f ms + "
              "%.1f ms per million\n",
              calibration.seconds(), cost.gpu_high->base_ms, cost.gpu_high->ms_per_mtriangle,
              cost.gpu_sprite->base_ms, cost.gpu_sprite->ms_per_mtriangle);

  terrain::LodSpriteOptions so;
  so.sky_color = kSky;
  so.gpu_low = true;  // the sprite frame on the GPU: required without a quadtree LOD
  so.cost = &cost;
  so.predict = so.predict_late = true;  // keyframes rendered ahead, in slices
  so.max_magnification = 1.5;           // a keyframe also once the sprite is magnified 1.5x
  terrain::LodSpriteRenderer sprite(ground, kWidth, kHeight, so);

  gpu::RenderTarget target(kWidth, kHeight);
  gpu::LateTimer gpu_time;  // each frame's GPU time, read when the GPU has finished it (frames later)
  size_t sprite_frames = 0, slowest = 0;
  double slowest_ms = 0.0, total_ms = 0.0;
  for (int f = 0; f < frames; ++f) {
    const Camera camera = cameraAt(path[size_t(f)], far_plane);
    const Stopwatch frame;
    target.clear(kSky);
    terrain::LodSpriteFrameInfo info;
    gpu_time.begin(uint64_t(f) + 1);  // the renderer counts its frames from 1 (LodSpriteFrameInfo::frame)
    sprite.render(camera, target, &info);
    gpu_time.end();
    if (info.frame != uint64_t(f) + 1) throw Error("embed_terrain", "frame count out of step");
    // The cost model corrected by what it got wrong: each frame's time as it comes back (LodSpriteRenderer::measured).
    gpu_time.finished([&](uint64_t drawn, double gpu_ms) { sprite.measured(drawn, gpu_ms); });
    ground.prefetch(camera, so.high_error);  // pages read ahead for the frames to come
    ground.finish();                         // (a program that presents the frame does not wait here)
    const double ms = frame.milliseconds();
    total_ms += ms;
    if (ms > slowest_ms) {
      slowest_ms = ms;
      slowest = size_t(f);
    }
    sprite_frames += info.path == terrain::TerrainPath::Sprite ? 1 : 0;
  }
  const terrain::LodSpriteCounters& c = sprite.counters();
  const terrain::PagedGpuLodStats& s = ground.stats();
  std::printf("%d frames: %zu sprite frames, %zu high frames; %zu keyframes drawn at once, %zu rendered ahead (%zu "
              "used); %.2f ms a frame on average, the slowest %.2f ms (frame %zu)\n",
              frames, sprite_frames, c.high_frames, c.fresh_keyframes, c.predicted_rendered, c.predicted_used,
              total_ms / double(frames), slowest_ms, slowest);
  const terrain::CostCorrection& cc = sprite.costCorrection();
  std::printf("the cost model against the measured frames (measured / predicted): high %.2f, sprite %.2f, keyframe "
              "part %.2f, slice part %.2f (%zu frames measured)\n",
              cc.factor(terrain::TerrainFrameKind::High), cc.factor(terrain::TerrainFrameKind::Sprite),
              cc.factor(terrain::TerrainFrameKind::Keyframe), cc.factor(terrain::TerrainFrameKind::Slice),
              cc.measurementsUsed());
  std::printf("pages: %zu held at most, %zu read by a draw (the calibration's included), %zu read ahead (%zu used)\n",
              s.peak_pages, s.page_loads, s.prefetched, s.prefetch_hits);
  if (argc > 4) {
    image::writePng(argv[4], target.readColor());
    std::printf("wrote %s\n", argv[4]);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
