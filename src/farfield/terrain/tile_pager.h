// Terrain tiles paged under a memory budget (issue 18: large terrains held in tiles, the quadtree LOD built per
// tile; Chen et al. 1999 section 2.2's LOD). The pager keeps tiles of a tile cache (tile_cache.h), each read at a
// step and with its quadtree LOD, and evicts the least recently used tiles, by bytes, before it loads one: the bytes
// it holds never exceed the budget. A tile held at a step serves requests for that step or a coarser one; a request
// for a finer step replaces it.
#pragma once

#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <utility>

#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/tile_cache.h"

namespace farfield::terrain {

struct TerrainTile {
  int tx = 0, ty = 0;
  TileGrid grid;
  std::unique_ptr<QuadtreeLod> lod;  // over grid.hf
  LodWindow window;                  // the tile's own blocks, indices of the whole grid
  size_t bytes = 0;                  // TileCache::residentBytes
};

struct TilePagerStats {
  size_t requests = 0;
  size_t hits = 0;
  size_t loads = 0;
  size_t evictions = 0;
  size_t resident_tiles = 0;
  size_t resident_bytes = 0;
  size_t peak_resident_bytes = 0;
  size_t bytes_loaded = 0;
  double load_seconds = 0.0;  // reading tiles and building their LOD
};

class TilePager {
 public:
  // cache must outlive the pager. Throws farfield::Error when the budget cannot hold the largest tile at step 1
  // (a frame may need any tile at full resolution).
  TilePager(const TileCache& cache, size_t budget_bytes);

  // Tile (tx, ty) at `step` or finer. The reference is valid until the next acquire.
  const TerrainTile& acquire(int tx, int ty, int step);

  const TilePagerStats& stats() const { return stats_; }
  size_t budget() const { return budget_; }
  const TileCache& cache() const { return cache_; }

 private:
  void evict();

  const TileCache& cache_;
  size_t budget_;
  TilePagerStats stats_;
  std::list<std::unique_ptr<TerrainTile>> lru_;  // most recently used first
  std::map<std::pair<int, int>, std::list<std::unique_ptr<TerrainTile>>::iterator> where_;
};

}  // namespace farfield::terrain
