#include "farfield/terrain/paged_gpu_lod.h"

#include <algorithm>
#include <string>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/terrain/cdlod_tiles.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain {
namespace {

int defaultOverviewStep(const TileCache& cache, const CdlodOptions& lod) {
  const int tile_level = cdlodTileLevel(cache.layout(), lod);
  int step = 1;
  while (step * 2 <= 16 && step * 2 <= cache.layout().block / 2 && step * 2 <= (1 << (tile_level + 1))) step *= 2;
  return step;
}

}  // namespace

PagedGpuLodTerrain::PagedGpuLodTerrain(const TileCache& cache, const PagedGpuLodOptions& options)
    : GpuLodTerrain(cdlodFromTileCacheKept(cache, options.lod)), cache_(cache), options_(options) {
  const TileLayout& l = cache.layout();
  overview_step_ = options.overview_step > 0 ? options.overview_step : defaultOverviewStep(cache, options.lod);
  fine_levels_ = 0;
  while ((1 << fine_levels_) < overview_step_) ++fine_levels_;
  if ((1 << fine_levels_) != overview_step_ || overview_step_ > l.block / 2 ||
      fine_levels_ > cdlodTileLevel(l, options.lod) + 1 || fine_levels_ > lod_.topLevel())
    throw Error(cache.path(), "overview step " + std::to_string(overview_step_) +
                                  ": needs a power of two up to half a block whose nodes fit in a tile");
  if (options.prefetch_frames < 0) throw Error("paged CDLOD terrain", "prefetch frames must be 0 or more");
  overview_ = cache.overview(overview_step_);
  TextureOptions to;
  to.ramp_lo = cache.minHeight();
  to.ramp_hi = cache.maxHeight();
  to.step = overview_step_;
  overview_colour_ = terrainTexture(overview_, to);
  const int page_cells = l.tile_blocks * l.block;
  tile_cells_ = page_cells;
  if (options.keep_heights) heights_of_.resize(size_t(l.tilesX()) * size_t(l.tilesY()));
  const size_t layer_bytes = gpu::CdlodPages(page_cells, 1).layerBytes();
  const int layers = int(std::min<size_t>(options.gpu_budget_bytes / layer_bytes, 2048));
  if (layers < 1)
    throw Error("paged CDLOD terrain", "a GPU budget of " + std::to_string(options.gpu_budget_bytes >> 20) +
                                           " MiB holds no page of " + std::to_string(layer_bytes >> 20) + " MiB");
  pages_ = std::make_unique<gpu::CdlodPages>(page_cells, layers);
  for (int k = layers - 1; k >= 0; --k) free_layers_.push_back(k);
  gpu::CdlodOverview ov;
  ov.step = overview_step_;
  ov.width = overview_.width;
  ov.height = overview_.height;
  ov.heights = overview_.heights;
  ov.colour = &overview_colour_;
  attachRenderer(std::make_unique<gpu::CdlodRenderer>(l.width, l.height, Vec2(float(l.cell_x), float(l.cell_y)),
                                                      options.lod.patch_cells, ov, *pages_));
  worker_ = std::thread([this] { work(); });
}

PagedGpuLodTerrain::~PagedGpuLodTerrain() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

size_t PagedGpuLodTerrain::gpuBytes() const { return renderer_->gpuBytes() + pages_->bytes(); }

void PagedGpuLodTerrain::gridHeights(std::span<const IVec2> points, std::span<float> out,
                                     std::span<uint8_t> own) const {
  const TileLayout& l = cache_.layout();
  const int t = tile_cells_;
  // First where each height lies, its cache line asked for at once; then the heights. The points are scattered over
  // megabytes of pages, and the cache is cold after a frame's rasterization: read one by one between the metric's
  // arithmetic, their misses did not overlap (0.5 ms for 830 cells on the 2-core machine, 0.16 ms warm).
  std::vector<const float*>& at = lookup_;
  at.assign(points.size(), nullptr);
  for (size_t k = 0; k < points.size() && !heights_of_.empty(); ++k) {
    const int i = std::clamp(points[k].x, 0, l.width - 1), j = std::clamp(points[k].y, 0, l.height - 1);
    // A point on a tile's edge is in both tiles' pages.
    for (const int tx : {i / t, i / t - 1}) {
      for (const int ty : {j / t, j / t - 1}) {
        if (tx < 0 || ty < 0 || tx >= l.tilesX() || ty >= l.tilesY() || i - tx * t > t || j - ty * t > t) continue;
        const std::vector<float>& held = heights_of_[tileIndex({tx, ty})];
        if (held.empty()) continue;
        at[k] = &held[size_t(i - tx * t) + size_t(j - ty * t) * size_t(t + 1)];
        __builtin_prefetch(at[k]);
        break;
      }
      if (at[k]) break;
    }
  }
  // The overview's rows under the other points (its bilinear sample reads two of them).
  const int step = overview_step_;
  for (size_t k = 0; k < points.size(); ++k) {
    if (at[k]) continue;
    const int i = std::clamp(points[k].x, 0, l.width - 1) / step, j = std::clamp(points[k].y, 0, l.height - 1) / step;
    const size_t row = size_t(std::min(j, overview_.height - 1)) * size_t(overview_.width);
    __builtin_prefetch(&overview_.heights[row + size_t(std::min(i, overview_.width - 1))]);
    __builtin_prefetch(&overview_.heights[std::min(row + size_t(overview_.width), overview_.heights.size() - 1) +
                                          size_t(std::min(i, overview_.width - 1))]);
  }
  for (size_t k = 0; k < points.size(); ++k) {
    if (!own.empty()) own[k] = at[k] ? 1 : 0;
    if (at[k]) {
      out[k] = *at[k];
      continue;
    }
    const int i = std::clamp(points[k].x, 0, l.width - 1), j = std::clamp(points[k].y, 0, l.height - 1);
    out[k] = overview_.sample(double(i) * l.cell_x, double(j) * l.cell_y);
  }
}

float PagedGpuLodTerrain::groundHeight(double x, double y) const { return overview_.sample(x, y); }

PagedGpuLodTerrain::Page PagedGpuLodTerrain::makePage(int tx, int ty) const {
  const Stopwatch clock;
  const TileLayout& l = cache_.layout();
  const TileGrid g = cache_.readHeights(tx, ty, 1);
  // The tile's own points in g.hf: blocks [x0, x1) of its stored blocks, their last points included.
  const int x0 = g.blocks.x0 * l.block, y0 = g.blocks.y0 * l.block;
  const int x1 = g.blocks.x1 * l.block, y1 = g.blocks.y1 * l.block;
  const int n = l.tile_blocks * l.block + 1;
  Page page;
  page.heights.resize(size_t(n) * size_t(n));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      page.heights[size_t(i) + size_t(j) * size_t(n)] = g.hf.at(std::min(x0 + i, x1), std::min(y0 + j, y1));
  // Its colours: the original texture's texels at its points, made with a point of margin for the slopes at its
  // edges (as the whole grid's texture sees them).
  const int mx0 = std::max(x0 - 1, 0), my0 = std::max(y0 - 1, 0);
  const int mx1 = std::min(x1 + 1, g.hf.width - 1), my1 = std::min(y1 + 1, g.hf.height - 1);
  const Heightfield part = g.hf.crop(mx0, my0, mx1 - mx0 + 1, my1 - my0 + 1);
  TextureOptions to;
  to.ramp_lo = cache_.minHeight();
  to.ramp_hi = cache_.maxHeight();
  to.origin = g.origin + IVec2(mx0, my0);
  const image::ColorImage texels = terrainTexture(part, to);
  image::ColorImage colour(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) colour.at(i, j) = texels.at(std::min(x0 + i, x1) - mx0, std::min(y0 + j, y1) - my0);
  page.colour = gpu::CdlodPages::colourMips(std::move(colour));
  page.seconds = clock.seconds();
  return page;
}

size_t PagedGpuLodTerrain::tileIndex(const TileKey& tile) const {
  return size_t(tile.first) + size_t(tile.second) * size_t(cache_.layout().tilesX());
}

PagedGpuLodTerrain::TileKey PagedGpuLodTerrain::tileOf(const CdlodNode& node) const {
  const int cells = lod_.patchCells() << node.level;
  const int tile = cache_.layout().tile_blocks * cache_.layout().block;
  return {node.x * cells / tile, node.y * cells / tile};
}

void PagedGpuLodTerrain::work() {
  for (;;) {
    TileKey tile;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      tile = queue_.front();
      queue_.pop_front();
    }
    Page page = makePage(tile.first, tile.second);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      worker_seconds_ += page.seconds;
      ++prefetched_;
      ready_[tile] = std::move(page);
      in_flight_.erase(tile);
    }
    done_.notify_all();
  }
}

int PagedGpuLodTerrain::residentLayer(const TileKey& tile, const std::set<TileKey>& needed, size_t& loads) {
  auto held = layer_of_.find(tile);
  if (held != layer_of_.end()) {
    lru_.remove(tile);
    lru_.push_front(tile);
    return held->second;
  }
  // Its data: ready from the worker, still in flight (wait for it), or read now.
  std::optional<Page> page;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    // Still queued: the worker has not started it, so it is read here. Being read: wait for it.
    const auto queued = std::find(queue_.begin(), queue_.end(), tile);
    if (queued != queue_.end()) {
      queue_.erase(queued);
      in_flight_.erase(tile);
    }
    done_.wait(lock, [&] { return !in_flight_.count(tile); });
    auto r = ready_.find(tile);
    if (r != ready_.end()) {
      page = std::move(r->second);
      ready_.erase(r);
      ++stats_.prefetch_hits;
    }
  }
  if (!page) {
    page = makePage(tile.first, tile.second);
    stats_.load_seconds += page->seconds;
    ++stats_.page_loads;
    ++loads;
  }
  int layer = -1;
  if (!free_layers_.empty()) {
    layer = free_layers_.back();
    free_layers_.pop_back();
  } else {
    // The least recently used page this frame does not need.
    for (auto it = lru_.rbegin(); it != lru_.rend(); ++it)
      if (!needed.count(*it)) {
        layer = layer_of_.at(*it);
        layer_of_.erase(*it);
        if (options_.keep_heights) heights_of_[tileIndex(*it)] = std::vector<float>();  // its memory given back
        lru_.erase(std::next(it).base());
        ++stats_.evictions;
        break;
      }
  }
  FF_CHECK(layer >= 0);  // draw() checked that the frame's pages fit
  pages_->upload(layer, page->heights, page->colour);
  if (options_.keep_heights) {
    heights_of_[tileIndex(tile)] = std::move(page->heights);
    ++heights_version_;
  }
  layer_of_[tile] = layer;
  lru_.push_front(tile);
  stats_.pages = layer_of_.size();
  stats_.peak_pages = std::max(stats_.peak_pages, stats_.pages);
  return layer;
}

void PagedGpuLodTerrain::placeNodes(std::span<const CdlodNode> nodes, std::vector<gpu::CdlodInstance>& out,
                                    GpuLodFrame& frame) {
  std::set<TileKey> needed;
  for (const CdlodNode& n : nodes)
    if (n.level < fine_levels_) needed.insert(tileOf(n));
  if (needed.size() > size_t(pages_->layers()))
    throw Error("paged CDLOD terrain", "this view needs " + std::to_string(needed.size()) +
                                           " pages; the GPU budget holds " + std::to_string(pages_->layers()) +
                                           ": raise it");
  std::map<TileKey, int> layers;  // each page the draw reads, made resident once
  for (const TileKey& t : needed) layers[t] = residentLayer(t, needed, frame.page_loads);
  for (const CdlodNode& n : nodes) {
    const int layer = n.level < fine_levels_ ? layers.at(tileOf(n)) : -1;
    frame.paged_nodes += layer >= 0 ? 1 : 0;
    out.push_back(cdlodInstance(n, lod_.patchCells(), layer));
  }
  frame.pages_needed = needed.size();
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.prefetched = prefetched_;
  stats_.load_seconds += worker_seconds_;
  worker_seconds_ = 0.0;
}

PagedGpuLodFrame PagedGpuLodTerrain::drawFrame(const Camera& camera, float pixel_error, gpu::RenderTarget& target) {
  const PagedGpuLodFrame frame = draw(camera, pixel_error, target);
  prefetch(camera, pixel_error);
  return frame;
}

void PagedGpuLodTerrain::prefetch(const Camera& camera, float pixel_error) {
  const std::optional<Camera> last = last_camera_;
  last_camera_ = camera;
  if (options_.prefetch_frames == 0 || !last) return;
  const Vec3 eye_step = camera.eye - last->eye, at_step = camera.at - last->at;
  if (glm::length(eye_step) < 1e-6f && glm::length(at_step) < 1e-6f) return;
  std::set<TileKey> wanted;
  CdlodSelection& ahead = ahead_;  // its ranges are remade only when the bound or the camera model change
  for (const float frames : {0.5f * float(options_.prefetch_frames), float(options_.prefetch_frames)}) {
    Camera c = camera;
    c.eye += eye_step * frames;
    c.at += at_step * frames;
    lod_.select(c, pixel_error, true, ahead);
    for (const CdlodNode& n : ahead.nodes)
      if (n.level < fine_levels_) wanted.insert(tileOf(n));
  }
  size_t room = size_t(pages_->layers());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const TileKey& t : wanted) {
      if (layer_of_.count(t) || in_flight_.count(t) || ready_.count(t)) continue;
      if (in_flight_.size() + ready_.size() >= room) break;  // no more read ahead than the pages could take
      queue_.push_back(t);
      in_flight_.insert(t);
    }
  }
  wake_.notify_all();
}

}  // namespace farfield::terrain
