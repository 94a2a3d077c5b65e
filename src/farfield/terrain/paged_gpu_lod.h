// The CDLOD terrain (cdlod.h) paged from a tile cache (tile_cache.h) to the GPU: for terrains larger than memory or
// than the driver's textures (a 16,385^2 grid is 1 GB of heights and exceeds llvmpipe's 16,384-texel limit).
//
// The node data come from the cache tile by tile, or from the file kept beside it (cdlod_tiles.h). The nodes of the
// finest levels (below F) read their tile's page: the tile's own points at full resolution and its original-texture
// texels, in a layer of texture arrays held under a GPU budget (gpu/cdlod_pages.h), the least recently used evicted
// first. The coarser nodes, whose
// vertices lie every 2^F points, read the overview (every 2^F-th point and a texel each), always held. Per frame: the
// selection, the pages it needs (read at once if missing: the frame waits, counted), one instanced draw. After each
// frame the pages the camera will need half and all of prefetch_frames frames ahead, moving as it last moved, are
// read on a worker thread, so that a steady flight rarely waits.
//
// It is a GpuLodTerrain (gpu_lod.h): a host may select and draw in steps (LOD-sprite, lod_sprite.h), each draw making
// the pages its nodes read resident; drawFrame is the whole frame of a host that draws the terrain alone.
//
// The same tree, ranges and pages give the same frame whatever the budget (the pixels do not depend on what was
// evicted: tested). Against the whole grid's CDLOD (gpu_lod.h) the frames differ where coarse nodes morph (the
// overview is sampled between their vertices) and in the coarse nodes' colours (a texel per overview point).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/cdlod_pages.h"
#include "farfield/gpu/cdlod_renderer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/tile_cache.h"

namespace farfield::terrain {

struct PagedGpuLodOptions {
  CdlodOptions lod;
  size_t gpu_budget_bytes = size_t(256) << 20;  // the pages' layers (heights and colours with mipmaps)
  int prefetch_frames = 32;  // pages read ahead along the camera's motion (0: only what a frame needs, at once)
  int overview_step = 0;     // 2^F; 0 = the largest power of two up to 16 that the cache and its tiles allow
  // Keep the heights of the pages held on the CPU as well (4 bytes a grid point of a page), for gridHeight
  // (LOD-sprite's error metric); without them gridHeight answers from the overview.
  bool keep_heights = false;
};

struct PagedGpuLodStats {
  size_t page_loads = 0;     // pages read by draw() itself: the frame waited
  size_t prefetched = 0;     // pages read by the worker
  size_t prefetch_hits = 0;  // of them, taken into a frame
  size_t evictions = 0;
  size_t pages = 0;          // held now
  size_t peak_pages = 0;
  double load_seconds = 0.0;  // reading tiles and making their colours (both threads)
};

// A frame's counts: GpuLodFrame's paged_nodes, pages_needed and page_loads (read in the frame: it waited).
using PagedGpuLodFrame = GpuLodFrame;

class PagedGpuLodTerrain : public GpuLodTerrain {
 public:
  // Needs a current context; cache must outlive this. Reads the cache's node data (every tile once) and overview.
  // Throws farfield::Error when the budget holds no page, or as cdlodFromTileCache does.
  PagedGpuLodTerrain(const TileCache& cache, const PagedGpuLodOptions& options = {});
  ~PagedGpuLodTerrain() override;

  // A frame: draws the terrain for the camera under the bound (pixels) into the bound target (not cleared; no wait),
  // then reads ahead (prefetch). Every draw (GpuLodTerrain's draw, drawSelection, drawNodes) throws farfield::Error
  // when its nodes need more pages than the budget holds.
  PagedGpuLodFrame drawFrame(const Camera& camera, float pixel_error, gpu::RenderTarget& target);
  // Queues the pages the camera will need half and all of prefetch_frames frames ahead under the bound, moving as it
  // moved since the last call, for the worker to read (once a frame, with the frame's camera).
  void prefetch(const Camera& camera, float pixel_error);

  // Waits for the GPU (glFinish): the end of a timed frame.
  void finish() { renderer_->finish(); }

  void gridHeights(std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own = {}) const override;
  bool holdsGridHeights() const override { return options_.keep_heights; }
  uint64_t heightsVersion() const override { return heights_version_; }
  float groundHeight(double x, double y) const override;

  const PagedGpuLodStats& stats() const { return stats_; }
  int fineLevels() const { return fine_levels_; }
  int overviewStep() const { return overview_step_; }
  int pageLayers() const { return pages_->layers(); }
  size_t pageBytes() const { return pages_->layerBytes(); }  // one page's GPU bytes
  size_t gpuBytes() const override;

 protected:
  void placeNodes(std::span<const CdlodNode> nodes, std::vector<gpu::CdlodInstance>& out,
                  GpuLodFrame& frame) override;

 private:
  struct Page {
    std::vector<float> heights;
    std::vector<image::ColorImage> colour;  // mip chain
    double seconds = 0.0;
  };
  using TileKey = std::pair<int, int>;
  Page makePage(int tx, int ty) const;
  TileKey tileOf(const CdlodNode& node) const;
  size_t tileIndex(const TileKey& tile) const;
  int residentLayer(const TileKey& tile, const std::set<TileKey>& needed, size_t& loads);
  void work();

  const TileCache& cache_;
  PagedGpuLodOptions options_;
  int overview_step_ = 1, fine_levels_ = 0, tile_cells_ = 1;
  Heightfield overview_;
  image::ColorImage overview_colour_;
  std::unique_ptr<gpu::CdlodPages> pages_;
  CdlodSelection ahead_;
  PagedGpuLodStats stats_;
  std::map<TileKey, int> layer_of_;  // resident tiles
  // With keep_heights: the held tiles' heights, (S + 1)^2 each, by tile index tx + ty * tilesX (empty: not held).
  std::vector<std::vector<float>> heights_of_;
  uint64_t heights_version_ = 0;  // a page's heights came
  mutable std::vector<const float*> lookup_;  // gridHeights' scratch (one thread draws)
  std::list<TileKey> lru_;           // most recently used first
  std::vector<int> free_layers_;
  std::optional<Camera> last_camera_;
  // Shared with the worker, under mutex_.
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::deque<TileKey> queue_;
  std::set<TileKey> in_flight_;
  std::map<TileKey, Page> ready_;
  size_t prefetched_ = 0;
  double worker_seconds_ = 0.0;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace farfield::terrain
