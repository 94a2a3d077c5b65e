// A large terrain drawn from paged tiles, each from its own GPU patch (issue 18; see paged_terrain.h).
#include "farfield/terrain/paged_terrain.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain {
namespace {

// A tile's own points at its step: [x0, x1] x [y0, y1] of its grid (the apron left out: no triangle of the tile
// reaches it).
struct OwnPoints {
  int x0, y0, x1, y1;
  int width() const { return x1 - x0 + 1; }
  int height() const { return y1 - y0 + 1; }
};

OwnPoints ownPoints(const TileLayout& layout, const BlockRect& own_blocks_in_stored, int step) {
  const int per_block = layout.block / step;
  return {own_blocks_in_stored.x0 * per_block, own_blocks_in_stored.y0 * per_block,
          own_blocks_in_stored.x1 * per_block, own_blocks_in_stored.y1 * per_block};
}

// Points of tile (tx, ty)'s own blocks at step, along x and y.
std::pair<size_t, size_t> ownSize(const TileLayout& l, int tx, int ty, int step) {
  const BlockRect own = l.tileBlocks(tx, ty);
  const size_t per_block = size_t(l.block / step);
  return {size_t(own.x1 - own.x0) * per_block + 1, size_t(own.y1 - own.y0) * per_block + 1};
}

size_t mipmappedBytes(size_t w, size_t h) {
  size_t bytes = 0;
  while (true) {
    bytes += w * h * 4;
    if (w == 1 && h == 1) return bytes;
    w = std::max<size_t>(w / 2, 1);
    h = std::max<size_t>(h / 2, 1);
  }
}

// The tile's own points at its step, with a texture over them and one more point on each side where the tile's
// grid has them, so that the normals at the tile's edge see both sides (as the whole texture's do).
std::unique_ptr<TileDrawData> tileDrawData(const TileCache& cache, const TerrainTile& tile) {
  const TileLayout& l = cache.layout();
  const TileGrid& g = tile.grid;
  const int step = g.step;
  const OwnPoints own = ownPoints(l, g.blocks, step);
  auto d = std::make_unique<TileDrawData>();
  d->first = g.origin + IVec2(own.x0, own.y0) * step;
  d->width = own.width();
  d->positions.reserve(size_t(own.width()) * size_t(own.height()));
  for (int y = own.y0; y <= own.y1; ++y)
    for (int x = own.x0; x <= own.x1; ++x) {
      const int gx = g.origin.x + x * step, gy = g.origin.y + y * step;
      d->positions.emplace_back(float(gx * l.cell_x), float(gy * l.cell_y), g.hf.at(x, y));
    }
  const int tx0 = std::max(own.x0 - 1, 0), ty0 = std::max(own.y0 - 1, 0);
  const int tx1 = std::min(own.x1 + 1, g.hf.width - 1), ty1 = std::min(own.y1 + 1, g.hf.height - 1);
  const Heightfield part = g.hf.crop(tx0, ty0, tx1 - tx0 + 1, ty1 - ty0 + 1);
  TextureOptions to;
  to.ramp_lo = cache.minHeight();
  to.ramp_hi = cache.maxHeight();
  to.origin = g.origin + IVec2(tx0, ty0) * step;
  to.step = step;
  d->texture = terrainTexture(part, to);
  // uv of world x: texel i of the part is centred on its point i, at world (origin.x + (tx0 + i) * step) * cell.
  const double cx = l.cell_x * step, cy = l.cell_y * step;
  const double wx0 = double(to.origin.x) * l.cell_x, wy0 = double(to.origin.y) * l.cell_y;
  d->uv_scale = Vec2(float(1.0 / (cx * part.width)), float(1.0 / (cy * part.height)));
  d->uv_offset = Vec2(float((0.5 - wx0 / cx) / part.width), float((0.5 - wy0 / cy) / part.height));
  return d;
}

// The bytes tileDrawData adds to a tile at a step: positions and the texture, at most two points wider each way.
size_t tileDrawBytes(const TileLayout& l, int tx, int ty, int step) {
  const auto [w, h] = ownSize(l, tx, ty, step);
  return w * h * sizeof(Vec3) + (w + 2) * (h + 2) * 4;
}

}  // namespace

PagedTerrainRenderer::PagedTerrainRenderer(TilePager& pager, size_t gpu_budget_bytes, int prefetch_frames)
    : pager_(pager), budget_(gpu_budget_bytes), prefetch_frames_(prefetch_frames) {
  // Tiles arrive with their positions and texture made where they are loaded (the prefetch's worker thread), so
  // that a patch costs its upload only.
  const TileCache& cache = pager.cache();
  pager.setPreparer({[&cache](const TerrainTile& tile) { return tileDrawData(cache, tile); },
                     [&cache](int tx, int ty, int step) { return tileDrawBytes(cache.layout(), tx, ty, step); }});
  const TileLayout& l = pager.cache().layout();
  size_t largest = 0;
  for (int ty = 0; ty < l.tilesY(); ++ty)
    for (int tx = 0; tx < l.tilesX(); ++tx) largest = std::max(largest, patchBytes(tx, ty, 1));
  if (largest > budget_) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "a GPU budget of %.2f MiB cannot hold a tile at full resolution (%.2f MiB); raise it or use "
                  "smaller tiles",
                  double(budget_) / double(1 << 20), double(largest) / double(1 << 20));
    throw Error(pager.cache().path(), text);
  }
}

PagedTerrainRenderer::~PagedTerrainRenderer() = default;

size_t PagedTerrainRenderer::patchBytes(int tx, int ty, int step) const {
  const auto [w, h] = ownSize(pager_.cache().layout(), tx, ty, step);
  // The texture spans the own points and one more on each side where the grid continues: at most w + 2, h + 2.
  const size_t index_store = (w - 1) * (h - 1) * 2 * 3 * sizeof(uint32_t);
  return w * h * sizeof(Vec3) + mipmappedBytes(w + 2, h + 2) + index_store + index_store / 2;
}

void PagedTerrainRenderer::evict() {
  FF_CHECK(!lru_.empty());
  const Patch& p = lru_.back();
  stats_.gpu_bytes -= p.bytes;
  where_.erase({p.tx, p.ty});
  lru_.pop_back();
  ++stats_.evictions;
  stats_.patches = lru_.size();
}

PagedTerrainRenderer::Patch& PagedTerrainRenderer::acquire(const TerrainTile& tile) {
  const int step = tile.grid.step;
  auto found = where_.find({tile.tx, tile.ty});
  if (found != where_.end()) {
    if (found->second->step == step) {
      lru_.splice(lru_.begin(), lru_, found->second);
      return lru_.front();
    }
    // Another step: the tile's LOD indexes its grid at the pager's step, which the patch must match.
    stats_.gpu_bytes -= found->second->bytes;
    lru_.erase(found->second);
    where_.erase(found);
  }
  const size_t bytes = patchBytes(tile.tx, tile.ty, step);
  while (!lru_.empty() && stats_.gpu_bytes + bytes > budget_) evict();
  FF_CHECK(stats_.gpu_bytes + bytes <= budget_);

  const Stopwatch timer;
  std::unique_ptr<TileDrawData> made;
  // A tile whose data went with an earlier patch (released on upload), should that patch have been evicted.
  if (!tile.draw) made = tileDrawData(pager_.cache(), tile);
  const TileDrawData& d = tile.draw ? *tile.draw : *made;
  Patch p;
  p.tx = tile.tx;
  p.ty = tile.ty;
  p.step = step;
  p.first = d.first;
  p.width = d.width;
  p.bytes = bytes;
  p.gpu = std::make_unique<gpu::TerrainPatch>(d.positions, d.texture, d.uv_scale, d.uv_offset);
  // On the GPU now: the tile keeps its heights and LOD only (made again should the patch go and the tile stay).
  pager_.releaseDrawData(tile.tx, tile.ty);
  stats_.load_seconds += timer.seconds();
  ++stats_.loads;
  stats_.gpu_bytes += bytes;
  stats_.peak_gpu_bytes = std::max(stats_.peak_gpu_bytes, stats_.gpu_bytes);
  lru_.push_front(std::move(p));
  where_[{tile.tx, tile.ty}] = lru_.begin();
  stats_.patches = lru_.size();
  return lru_.front();
}

PagedTerrainFrame PagedTerrainRenderer::draw(const Camera& camera, const LodSettings& settings,
                                             gpu::RenderTarget& target) {
  PagedTerrainFrame frame;
  const size_t loads_before = stats_.loads;
  const uint32_t grid_width = uint32_t(pager_.cache().layout().width);
  frame.tiles = visitTiledLod(pager_, camera, settings, [&](const TerrainTile& tile, const LodMesh& piece) {
    if (piece.indices.empty()) return;
    Patch& p = acquire(tile);
    // Whole-grid indices to the patch's: every vertex of the piece lies on the tile's step lattice, inside its
    // own points.
    local_.resize(piece.indices.size());
    const int step = p.step;
    for (size_t k = 0; k < piece.indices.size(); ++k) {
      const uint32_t v = piece.indices[k];
      const int x = (int(v % grid_width) - p.first.x) / step, y = (int(v / grid_width) - p.first.y) / step;
      local_[k] = uint32_t(x + y * p.width);
    }
    p.gpu->setIndices(local_);
    gpu::addDraw(frame.draw, renderer_.draw(camera, target, *p.gpu));
  });
  frame.patch_loads = stats_.loads - loads_before;
  prefetchAhead(camera, settings);
  return frame;
}

void PagedTerrainRenderer::prefetchAhead(const Camera& camera, const LodSettings& settings) {
  if (prefetch_frames_ > 0 && last_camera_) {
    const Vec3 motion = camera.eye - last_camera_->eye;
    std::vector<TileRequest> requests;
    for (int k : {std::max(1, prefetch_frames_ / 2), prefetch_frames_}) {
      Camera ahead = camera;
      ahead.eye += motion * float(k);
      ahead.at += motion * float(k);
      const std::vector<TileRequest> r = tilesInView(pager_.cache(), ahead, settings);
      requests.insert(requests.end(), r.begin(), r.end());
    }
    pager_.prefetch(requests);
  }
  last_camera_ = camera;
}

}  // namespace farfield::terrain
