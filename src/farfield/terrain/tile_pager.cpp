// Terrain tiles paged under a byte budget, least recently used first (see tile_pager.h).
#include "farfield/terrain/tile_pager.h"

#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::terrain {

TilePager::TilePager(const TileCache& cache, size_t budget_bytes) : cache_(cache), budget_(budget_bytes) {
  size_t largest = 0;
  for (int ty = 0; ty < cache.layout().tilesY(); ++ty)
    for (int tx = 0; tx < cache.layout().tilesX(); ++tx) largest = std::max(largest, cache.residentBytes(tx, ty, 1));
  if (largest > budget_bytes)
    throw Error(cache.path(), "a tile budget of " + std::to_string(budget_bytes) +
                                  " bytes cannot hold one tile at full resolution (" + std::to_string(largest) +
                                  " bytes); raise the budget or use smaller tiles");
}

void TilePager::evict() {
  FF_CHECK(!lru_.empty());
  const TerrainTile& t = *lru_.back();
  stats_.resident_bytes -= t.bytes;
  --stats_.resident_tiles;
  where_.erase({t.tx, t.ty});
  lru_.pop_back();
  ++stats_.evictions;
}

const TerrainTile& TilePager::acquire(int tx, int ty, int step) {
  ++stats_.requests;
  auto found = where_.find({tx, ty});
  if (found != where_.end()) {
    auto it = found->second;
    if ((*it)->grid.step <= step) {
      lru_.splice(lru_.begin(), lru_, it);
      ++stats_.hits;
      return *lru_.front();
    }
    stats_.resident_bytes -= (*it)->bytes;  // held too coarse: replaced (not counted as an eviction)
    lru_.erase(it);
    where_.erase(found);
  }
  const size_t bytes = cache_.residentBytes(tx, ty, step);
  while (!lru_.empty() && stats_.resident_bytes + bytes > budget_) evict();
  FF_CHECK(stats_.resident_bytes + bytes <= budget_);

  const Stopwatch timer;
  auto tile = std::make_unique<TerrainTile>();
  tile->tx = tx;
  tile->ty = ty;
  tile->grid = cache_.read(tx, ty, step);
  TileGrid& g = tile->grid;
  tile->lod = std::make_unique<QuadtreeLod>(g.hf, cache_.layout().block / step, g.origin, step, std::move(g.error),
                                            std::move(g.radius));
  tile->window = {g.blocks.x0, g.blocks.y0, g.blocks.x1, g.blocks.y1, uint32_t(cache_.layout().width)};
  tile->bytes = bytes;
  stats_.load_seconds += timer.seconds();
  ++stats_.loads;
  stats_.bytes_loaded += bytes;
  stats_.resident_bytes += bytes;
  stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
  lru_.push_front(std::move(tile));
  where_[{tx, ty}] = lru_.begin();
  stats_.resident_tiles = lru_.size();
  return *lru_.front();
}

}  // namespace farfield::terrain
