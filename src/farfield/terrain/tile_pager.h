// Terrain tiles paged under a memory budget (issue 18: large terrains held in tiles, the quadtree LOD built per
// tile; Chen et al. 1999 section 2.2's LOD). The pager keeps tiles of a tile cache (tile_cache.h), each read at a
// step and with its quadtree LOD, and evicts the least recently used tiles, by bytes, before it loads one: the bytes
// it holds never exceed the budget. A tile held at a step serves requests for that step or a coarser one; a request
// for a finer step replaces it.
//
// Prefetch: prefetch() hands tiles a coming frame will need to a worker thread, which reads them and builds their
// LOD while frames are drawn; acquire() then takes them without waiting (or waits for one still in flight rather
// than reading it twice). A prefetched tile's bytes count against the budget from the request on, and a request
// evicts only tiles that no acquire() has used since the previous prefetch() call (the frame just drawn keeps its
// tiles); a request that does not fit otherwise is dropped. acquire() and prefetch() are called from one thread.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <utility>

#include "farfield/image/image.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/tile_cache.h"

namespace farfield::terrain {

// What drawing a tile needs, made as it is loaded (TilePager::setPreparer; paged_terrain.h): the positions of its
// own points, the whole-grid point of the first and the points a row, and its texture with the uv transform.
struct TileDrawData {
  std::vector<Vec3> positions;
  IVec2 first{0};
  int width = 0;
  image::ColorImage texture;
  Vec2 uv_scale{1.0f}, uv_offset{0.0f};
};

struct TerrainTile {
  int tx = 0, ty = 0;
  TileGrid grid;
  std::unique_ptr<QuadtreeLod> lod;  // over grid.hf
  LodWindow window;                  // the tile's own blocks, indices of the whole grid
  size_t bytes = 0;                  // TileCache::residentBytes
  size_t used = 0;                   // the pager's prefetch round of its last acquire() (0: none yet)
  bool prefetched = false;           // loaded by the worker
  std::unique_ptr<TileDrawData> draw;  // with a preparer (setPreparer)
};

// Work done on every tile as it is loaded (on the worker for prefetched tiles), and the bytes it adds to a tile at
// a step, which count against the budget with the tile's own.
struct TilePreparer {
  std::function<std::unique_ptr<TileDrawData>(const TerrainTile&)> prepare;
  std::function<size_t(int tx, int ty, int step)> bytes;
};

struct TileRequest {
  int tx = 0, ty = 0, step = 1;
};

struct TilePagerStats {
  size_t requests = 0;
  size_t hits = 0;
  size_t loads = 0;            // read by acquire() itself, the frame waiting
  size_t evictions = 0;
  size_t resident_tiles = 0;
  size_t resident_bytes = 0;   // held, in flight and ready (prefetched) tiles
  size_t peak_resident_bytes = 0;
  size_t bytes_loaded = 0;
  double load_seconds = 0.0;   // reading tiles and building their LOD (acquire()'s and the worker's)
  size_t prefetched = 0;       // tiles the worker loaded
  size_t prefetch_hits = 0;    // prefetched tiles an acquire() used
  size_t prefetch_waits = 0;   // of them: the tile was still in flight
  size_t prefetch_dropped = 0; // requests that did not fit without evicting the last frame's tiles
};

class TilePager {
 public:
  // cache must outlive the pager. Throws farfield::Error when the budget cannot hold the largest tile at step 1
  // (a frame may need any tile at full resolution).
  TilePager(const TileCache& cache, size_t budget_bytes);
  ~TilePager();
  TilePager(const TilePager&) = delete;
  TilePager& operator=(const TilePager&) = delete;

  // Sets the work done on each tile as it is loaded (before the first acquire() or prefetch()). Throws
  // farfield::Error when the budget cannot hold the largest tile at step 1 with what the preparer adds.
  void setPreparer(TilePreparer preparer);

  // Tile (tx, ty) at `step` or finer. The reference is valid until the next acquire() or prefetch().
  const TerrainTile& acquire(int tx, int ty, int step);

  // Frees a held tile's preparer data once it is used (a patch uploaded): its bytes leave the tile's and the budget's.
  void releaseDrawData(int tx, int ty);

  // Loads these tiles ahead on the worker thread (see the file comment); requests already held at their step or
  // finer, or already asked for, are skipped. Starts a new prefetch round.
  void prefetch(std::span<const TileRequest> requests);

  const TilePagerStats& stats() const { return stats_; }
  size_t budget() const { return budget_; }
  const TileCache& cache() const { return cache_; }

 private:
  using Lru = std::list<std::unique_ptr<TerrainTile>>;
  std::unique_ptr<TerrainTile> load(int tx, int ty, int step) const;
  size_t bytesOf(int tx, int ty, int step) const;  // the cache's resident bytes and the preparer's
  void evict();
  // Frees room for `bytes`, evicting only tiles used before round `keep_from` (0: any); false when it cannot.
  bool makeRoom(size_t bytes, size_t keep_from);
  void hold(std::unique_ptr<TerrainTile> tile);  // into the LRU, most recent; replaces a coarser copy
  void adoptReady();                             // the worker's finished tiles into the LRU
  void work();

  const TileCache& cache_;
  size_t budget_;
  TilePreparer preparer_;
  TilePagerStats stats_;
  Lru lru_;  // most recently used first
  std::map<std::pair<int, int>, Lru::iterator> where_;
  size_t round_ = 1;

  // Shared with the worker, under mutex_.
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::deque<TileRequest> queue_;
  std::map<std::pair<int, int>, int> in_flight_;  // asked for (queued or loading), by step
  std::vector<std::unique_ptr<TerrainTile>> ready_;
  double worker_seconds_ = 0.0;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace farfield::terrain
