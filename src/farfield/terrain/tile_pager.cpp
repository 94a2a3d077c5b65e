// Terrain tiles paged under a byte budget, least recently used first, with tiles loaded ahead on a worker thread
// (see tile_pager.h).
#include "farfield/terrain/tile_pager.h"

#include <algorithm>
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

TilePager::~TilePager() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

size_t TilePager::bytesOf(int tx, int ty, int step) const {
  return cache_.residentBytes(tx, ty, step) + (preparer_.bytes ? preparer_.bytes(tx, ty, step) : 0);
}

void TilePager::setPreparer(TilePreparer preparer) {
  FF_CHECK(stats_.requests == 0 && lru_.empty() && in_flight_.empty());
  preparer_ = std::move(preparer);
  size_t largest = 0;
  for (int ty = 0; ty < cache_.layout().tilesY(); ++ty)
    for (int tx = 0; tx < cache_.layout().tilesX(); ++tx) largest = std::max(largest, bytesOf(tx, ty, 1));
  if (largest > budget_)
    throw Error(cache_.path(), "a tile budget of " + std::to_string(budget_) +
                                   " bytes cannot hold one tile at full resolution ready to draw (" +
                                   std::to_string(largest) + " bytes); raise the budget or use smaller tiles");
}

std::unique_ptr<TerrainTile> TilePager::load(int tx, int ty, int step) const {
  auto tile = std::make_unique<TerrainTile>();
  tile->tx = tx;
  tile->ty = ty;
  tile->grid = cache_.read(tx, ty, step);
  TileGrid& g = tile->grid;
  tile->lod = std::make_unique<QuadtreeLod>(g.hf, cache_.layout().block / step, g.origin, step, std::move(g.error),
                                            std::move(g.radius));
  tile->window = {g.blocks.x0, g.blocks.y0, g.blocks.x1, g.blocks.y1, uint32_t(cache_.layout().width)};
  tile->bytes = bytesOf(tx, ty, step);
  if (preparer_.prepare) tile->draw = preparer_.prepare(*tile);
  return tile;
}

void TilePager::evict() {
  FF_CHECK(!lru_.empty());
  const TerrainTile& t = *lru_.back();
  stats_.resident_bytes -= t.bytes;
  where_.erase({t.tx, t.ty});
  lru_.pop_back();
  ++stats_.evictions;
  stats_.resident_tiles = lru_.size();
}

bool TilePager::makeRoom(size_t bytes, size_t keep_from) {
  while (stats_.resident_bytes + bytes > budget_) {
    if (!lru_.empty() && (keep_from == 0 || lru_.back()->used < keep_from)) {
      evict();
      continue;
    }
    if (keep_from != 0) return false;
    // Everything held is gone; what remains are prefetches: drop the queued ones, then take the one loading.
    std::unique_lock lock(mutex_);
    if (!queue_.empty()) {
      for (const TileRequest& r : queue_) {
        stats_.resident_bytes -= bytesOf(r.tx, r.ty, r.step);
        in_flight_.erase({r.tx, r.ty});
        ++stats_.prefetch_dropped;
      }
      queue_.clear();
      continue;
    }
    if (in_flight_.empty() && ready_.empty()) return false;
    done_.wait(lock, [&] { return in_flight_.empty(); });
    lock.unlock();
    adoptReady();
  }
  return true;
}

void TilePager::hold(std::unique_ptr<TerrainTile> tile) {
  auto found = where_.find({tile->tx, tile->ty});
  if (found != where_.end()) {
    if ((*found->second)->grid.step <= tile->grid.step) {  // already held as fine: the new copy is not needed
      stats_.resident_bytes -= tile->bytes;
      return;
    }
    stats_.resident_bytes -= (*found->second)->bytes;  // held too coarse: replaced (not counted as an eviction)
    lru_.erase(found->second);
    where_.erase(found);
  }
  lru_.push_front(std::move(tile));
  where_[{lru_.front()->tx, lru_.front()->ty}] = lru_.begin();
  stats_.resident_tiles = lru_.size();
}

void TilePager::adoptReady() {
  std::vector<std::unique_ptr<TerrainTile>> ready;
  {
    const std::lock_guard lock(mutex_);
    ready.swap(ready_);
    stats_.load_seconds += worker_seconds_;
    worker_seconds_ = 0.0;
  }
  for (auto& tile : ready) {
    if (!tile->lod) {  // the worker could not load it: its room is given back, and acquire() reads it (and says why)
      stats_.resident_bytes -= tile->bytes;
      continue;
    }
    ++stats_.prefetched;
    stats_.bytes_loaded += tile->bytes;
    tile->prefetched = true;
    hold(std::move(tile));
  }
}

const TerrainTile& TilePager::acquire(int tx, int ty, int step) {
  ++stats_.requests;
  adoptReady();
  auto resident = [&]() -> TerrainTile* {
    auto found = where_.find({tx, ty});
    if (found == where_.end() || (*found->second)->grid.step > step) return nullptr;
    lru_.splice(lru_.begin(), lru_, found->second);
    TerrainTile& t = *lru_.front();
    if (t.prefetched && t.used == 0) ++stats_.prefetch_hits;
    t.used = round_;
    return &t;
  };
  if (TerrainTile* t = resident()) {
    ++stats_.hits;
    return *t;
  }
  // Asked for ahead: the worker takes it next (if it has not started it), and the frame waits for it rather than
  // reading it a second time.
  {
    std::unique_lock lock(mutex_);
    auto flying = in_flight_.find({tx, ty});
    if (flying != in_flight_.end() && flying->second <= step) {
      auto queued = std::find_if(queue_.begin(), queue_.end(),
                                 [&](const TileRequest& r) { return r.tx == tx && r.ty == ty; });
      if (queued != queue_.end()) {
        const TileRequest r = *queued;
        queue_.erase(queued);
        queue_.push_front(r);
      }
      done_.wait(lock, [&] { return !in_flight_.count({tx, ty}); });
      lock.unlock();
      adoptReady();
      if (TerrainTile* t = resident()) {
        ++stats_.hits;
        ++stats_.prefetch_waits;
        return *t;
      }
    }
  }
  const size_t bytes = bytesOf(tx, ty, step);
  // A coarser copy held is replaced: its bytes are freed first.
  auto coarse = where_.find({tx, ty});
  if (coarse != where_.end()) {
    stats_.resident_bytes -= (*coarse->second)->bytes;
    lru_.erase(coarse->second);
    where_.erase(coarse);
    stats_.resident_tiles = lru_.size();
  }
  FF_CHECK(makeRoom(bytes, 0));
  const Stopwatch timer;
  std::unique_ptr<TerrainTile> tile = load(tx, ty, step);
  stats_.load_seconds += timer.seconds();
  ++stats_.loads;
  stats_.bytes_loaded += bytes;
  stats_.resident_bytes += bytes;
  stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
  tile->used = round_;
  hold(std::move(tile));
  return *lru_.front();
}

void TilePager::releaseDrawData(int tx, int ty) {
  auto found = where_.find({tx, ty});
  if (found == where_.end() || !(*found->second)->draw) return;
  TerrainTile& t = **found->second;
  const size_t extra = preparer_.bytes ? preparer_.bytes(tx, ty, t.grid.step) : 0;
  t.draw.reset();
  t.bytes -= extra;
  stats_.resident_bytes -= extra;
}

void TilePager::prefetch(std::span<const TileRequest> requests) {
  adoptReady();
  size_t queued = 0;
  for (const TileRequest& r : requests) {
    auto found = where_.find({r.tx, r.ty});
    if (found != where_.end() && (*found->second)->grid.step <= r.step) continue;
    {
      const std::lock_guard lock(mutex_);
      // Asked for already, at this step or another: that load goes on (acquire() refines a coarser one).
      if (in_flight_.count({r.tx, r.ty})) continue;
    }
    const size_t bytes = bytesOf(r.tx, r.ty, r.step);
    if (!makeRoom(bytes, round_)) {
      ++stats_.prefetch_dropped;
      continue;
    }
    stats_.resident_bytes += bytes;
    stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
    {
      const std::lock_guard lock(mutex_);
      queue_.push_back(r);
      in_flight_[{r.tx, r.ty}] = r.step;
    }
    ++queued;
  }
  ++round_;
  if (queued == 0) return;
  if (!worker_.joinable()) worker_ = std::thread([this] { work(); });
  wake_.notify_one();
}

void TilePager::work() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    const TileRequest r = queue_.front();
    queue_.pop_front();
    lock.unlock();
    const Stopwatch timer;
    std::unique_ptr<TerrainTile> tile;
    try {
      tile = load(r.tx, r.ty, r.step);
    } catch (const std::exception&) {
      // A damaged tile: reported when a frame acquires it, on the frame's thread.
      tile = std::make_unique<TerrainTile>();
      tile->tx = r.tx;
      tile->ty = r.ty;
      tile->bytes = bytesOf(r.tx, r.ty, r.step);
    }
    const double seconds = timer.seconds();
    lock.lock();
    worker_seconds_ += seconds;
    ready_.push_back(std::move(tile));
    in_flight_.erase({r.tx, r.ty});
    done_.notify_all();
  }
}

}  // namespace farfield::terrain
