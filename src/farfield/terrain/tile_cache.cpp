// Tile cache of a large terrain: per-tile heights with the full-resolution quadtree LOD's errors (Chen et al. 1999
// section 2.2's LOD), written once and read back by tile and step (see tile_cache.h).
#include "farfield/terrain/tile_cache.h"

#include <fcntl.h>
#include <unistd.h>
// xxHash inlined from its header (libxxhash-dev): no library to link.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {
namespace {

constexpr char kMagic[8] = {'F', 'F', 'T', 'I', 'L', 'E', 'S', '1'};
constexpr uint32_t kVersion = 3;
const char* const kPlaneNames[3] = {"heights", "errors", "radii"};

// XXH3 (64 bits) over one row of a plane: a reader checks every row it reads (a far tile reads only some rows).
// Version 2 hashed byte by byte (FNV-1a), and TileCache::read was then the largest cost in a profile of a paged flight.
uint64_t rowChecksum(const float* row, size_t n) { return XXH3_64bits(row, n * sizeof(float)); }

int storedWidth(const BlockRect& r, int block) { return (r.x1 - r.x0) * block + 1; }
int storedHeight(const BlockRect& r, int block) { return (r.y1 - r.y0) * block + 1; }

template <class T>
void put(std::ofstream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

struct Reader {
  const std::string& path;
  const std::vector<char>& bytes;
  size_t at = 0;
  template <class T>
  T get() {
    if (at + sizeof(T) > bytes.size()) throw Error(path, "tile cache index ends early (at byte " + std::to_string(at) + ")");
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
};

size_t headerBytes() { return 8 + 4 + 4 * 5 + 8 * 2; }
size_t indexRecordBytes(int levels) { return 4 * 2 + size_t(levels) * 8 + 8; }

}  // namespace

int TileLayout::levels() const {
  int n = 0;
  for (int s = 2; s <= block; s *= 2) ++n;
  return n;
}

BlockRect TileLayout::tileBlocks(int tx, int ty) const {
  BlockRect r;
  r.x0 = tx * tile_blocks;
  r.y0 = ty * tile_blocks;
  r.x1 = std::min(r.x0 + tile_blocks, blocksX());
  r.y1 = std::min(r.y0 + tile_blocks, blocksY());
  return r;
}

BlockRect TileLayout::storedBlocks(int tx, int ty) const {
  BlockRect r = tileBlocks(tx, ty);
  r.x0 = std::max(r.x0 - 1, 0);
  r.y0 = std::max(r.y0 - 1, 0);
  r.x1 = std::min(r.x1 + 1, blocksX());
  r.y1 = std::min(r.y1 + 1, blocksY());
  return r;
}

void TileCache::write(const Heightfield& hf, int block, int tile_blocks, const std::string& path) {
  TileLayout layout;
  layout.width = hf.width;
  layout.height = hf.height;
  layout.block = block;
  layout.tile_blocks = tile_blocks;
  layout.cell_x = hf.cell_x;
  layout.cell_y = hf.cell_y;
  write(layout, hf.source, [&](int i0, int j0, int w, int h) { return hf.crop(i0, j0, w, h); }, path);
}

void TileCache::write(const DemReader& dem, int block, int tile_blocks, const std::string& path) {
  if (block < 2 || (block & (block - 1)) != 0) throw Error(path, "LOD block must be a power of two >= 2");
  const int a = (dem.width() - 1) / block, b = (dem.height() - 1) / block;
  if (a < 1 || b < 1)
    throw Error(dem.header().source, std::to_string(dem.width()) + "x" + std::to_string(dem.height()) +
                                         " raster is smaller than one LOD block of " + std::to_string(block + 1) +
                                         "x" + std::to_string(block + 1) + " points");
  TileLayout layout;
  layout.width = a * block + 1;
  layout.height = b * block + 1;
  layout.block = block;
  layout.tile_blocks = tile_blocks;
  layout.cell_x = dem.header().cell_x;
  layout.cell_y = dem.header().cell_y;
  // Centred, as cropForBlocks crops the whole raster.
  const int ci = (dem.width() - layout.width) / 2, cj = (dem.height() - layout.height) / 2;
  write(layout, dem.header().source, [&](int i0, int j0, int w, int h) { return dem.read(ci + i0, cj + j0, w, h); },
        path);
}

void TileCache::write(const TileLayout& layout, const std::string& source, const HeightWindow& window,
                      const std::string& path) {
  const int block = layout.block;
  if (layout.tile_blocks < 1) throw Error(path, "tiles must be at least one LOD block wide");
  if (block < 2 || (block & (block - 1)) != 0 || (layout.width - 1) % block != 0 ||
      (layout.height - 1) % block != 0 || layout.width < 3 || layout.height < 3)
    throw Error(source, std::to_string(layout.width) + "x" + std::to_string(layout.height) +
                            " grid is not made of whole LOD blocks of " + std::to_string(block) + " cells");
  const int levels = layout.levels();
  const int tiles = layout.tilesX() * layout.tilesY();

  const std::string tmp = path + ".tmp";
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path, "cannot write the tile cache (" + tmp + ")");
  out.write(kMagic, 8);
  put(out, kVersion);
  put(out, int32_t(layout.width));
  put(out, int32_t(layout.height));
  put(out, int32_t(layout.block));
  put(out, int32_t(layout.tile_blocks));
  put(out, int32_t(levels));
  put(out, layout.cell_x);
  put(out, layout.cell_y);
  // The index is written after the data are known; reserve its room.
  const uint64_t index_at = uint64_t(out.tellp());
  std::vector<char> zeros(indexRecordBytes(levels) * size_t(tiles), 0);
  out.write(zeros.data(), std::streamsize(zeros.size()));

  std::vector<TileInfo> infos;
  // A bar for grids of more than 16 M points (an 8,193 x 8,193 raster's cache takes a minute).
  std::unique_ptr<Progress> progress;
  if (uint64_t(layout.width) * uint64_t(layout.height) > (uint64_t(1) << 24))
    progress = std::make_unique<Progress>("tile cache", uint64_t(tiles));
  for (int ty = 0; ty < layout.tilesY(); ++ty)
    for (int tx = 0; tx < layout.tilesX(); ++tx) {
      const BlockRect stored = layout.storedBlocks(tx, ty), own = layout.tileBlocks(tx, ty);
      const Heightfield grid = window(stored.x0 * block, stored.y0 * block, storedWidth(stored, block),
                                      storedHeight(stored, block));
      FF_CHECK(grid.width == storedWidth(stored, block) && grid.height == storedHeight(stored, block));
      const QuadtreeLod lod(grid, block, IVec2(stored.x0 * block, stored.y0 * block));
      TileInfo info;
      info.tx = tx;
      info.ty = ty;
      info.level_error.assign(size_t(levels), 0.0f);
      info.level_radius.assign(size_t(levels), 0.0f);
      info.z_min = std::numeric_limits<float>::max();
      info.z_max = std::numeric_limits<float>::lowest();
      const int x0 = (own.x0 - stored.x0) * block, x1 = (own.x1 - stored.x0) * block;
      const int y0 = (own.y0 - stored.y0) * block, y1 = (own.y1 - stored.y0) * block;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const size_t v = grid.index(x, y);
          info.z_min = std::min(info.z_min, grid.heights[v]);
          info.z_max = std::max(info.z_max, grid.heights[v]);
          int scale = 0;
          if (lodVertexKind(x, y, block, &scale) == LodVertexKind::BlockCorner) continue;
          const size_t l = size_t(std::countr_zero(unsigned(scale))) - 1;
          info.level_error[l] = std::max(info.level_error[l], lod.objectError(uint32_t(v)));
          info.level_radius[l] = std::max(info.level_radius[l], lod.radius(uint32_t(v)));
        }
      info.offset = uint64_t(out.tellp());
      out.write(reinterpret_cast<const char*>(grid.heights.data()), std::streamsize(grid.size() * sizeof(float)));
      out.write(reinterpret_cast<const char*>(lod.objectErrors().data()),
                std::streamsize(grid.size() * sizeof(float)));
      out.write(reinterpret_cast<const char*>(lod.radii().data()), std::streamsize(grid.size() * sizeof(float)));
      for (const float* plane : {grid.heights.data(), lod.objectErrors().data(), lod.radii().data()})
        for (int y = 0; y < grid.height; ++y) {
          const uint64_t sum = rowChecksum(plane + size_t(y) * size_t(grid.width), size_t(grid.width));
          put(out, sum);
        }
      infos.push_back(std::move(info));
      if (progress) progress->advance();
    }
  out.seekp(std::streamoff(index_at));
  for (const TileInfo& info : infos) {
    put(out, info.z_min);
    put(out, info.z_max);
    for (float e : info.level_error) put(out, e);
    for (float r : info.level_radius) put(out, r);
    put(out, info.offset);
  }
  out.flush();
  if (!out) throw Error(path, "writing the tile cache failed (" + tmp + ")");
  out.close();
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw Error(path, "cannot move the tile cache into place: " + ec.message());
}

TileCache::TileCache(const std::string& path) : path_(path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw Error(path, "cannot open the tile cache");
  file_size_ = uint64_t(in.tellg());
  in.seekg(0);
  std::vector<char> head(std::min<uint64_t>(file_size_, headerBytes()));
  in.read(head.data(), std::streamsize(head.size()));
  Reader r{path, head};
  if (head.size() < 8 || std::memcmp(head.data(), kMagic, 8) != 0) throw Error(path, "not a Farfield tile cache");
  r.at = 8;
  const uint32_t version = r.get<uint32_t>();
  if (version != kVersion)
    throw Error(path, "tile cache version " + std::to_string(version) + ", expected " + std::to_string(kVersion));
  layout_.width = r.get<int32_t>();
  layout_.height = r.get<int32_t>();
  layout_.block = r.get<int32_t>();
  layout_.tile_blocks = r.get<int32_t>();
  const int levels = r.get<int32_t>();
  layout_.cell_x = r.get<double>();
  layout_.cell_y = r.get<double>();
  const TileLayout& l = layout_;
  if (l.block < 2 || l.block > (1 << 16) || (l.block & (l.block - 1)) != 0 || l.width < 3 || l.height < 3 ||
      (l.width - 1) % l.block != 0 || (l.height - 1) % l.block != 0 || l.tile_blocks < 1 || levels != l.levels() ||
      !(l.cell_x > 0.0) || !(l.cell_y > 0.0) || !std::isfinite(l.cell_x) || !std::isfinite(l.cell_y))
    throw Error(path, "tile cache header is inconsistent (grid " + std::to_string(l.width) + "x" +
                          std::to_string(l.height) + ", block " + std::to_string(l.block) + ", tile " +
                          std::to_string(l.tile_blocks) + " blocks)");
  const size_t tiles = size_t(l.tilesX()) * size_t(l.tilesY());
  std::vector<char> index(indexRecordBytes(levels) * tiles);
  if (headerBytes() + index.size() > file_size_) throw Error(path, "tile cache index ends early");
  in.read(index.data(), std::streamsize(index.size()));
  Reader ir{path, index};
  tiles_.resize(tiles);
  for (int ty = 0; ty < l.tilesY(); ++ty)
    for (int tx = 0; tx < l.tilesX(); ++tx) {
      TileInfo& info = tiles_[size_t(tx) + size_t(ty) * size_t(l.tilesX())];
      info.tx = tx;
      info.ty = ty;
      info.z_min = ir.get<float>();
      info.z_max = ir.get<float>();
      info.level_error.resize(size_t(levels));
      info.level_radius.resize(size_t(levels));
      for (float& e : info.level_error) e = ir.get<float>();
      for (float& rr : info.level_radius) rr = ir.get<float>();
      info.offset = ir.get<uint64_t>();
      const BlockRect s = l.storedBlocks(tx, ty);
      const uint64_t bytes = uint64_t(storedWidth(s, l.block)) * uint64_t(storedHeight(s, l.block)) * 12 +
                             uint64_t(storedHeight(s, l.block)) * 3 * sizeof(uint64_t);
      if (info.offset < headerBytes() + index.size() || info.offset + bytes > file_size_ ||
          !(info.z_min <= info.z_max))
        throw Error(path, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) +
                              "): index record is damaged or its data lie past the end of the file");
    }
}

Box3 TileCache::tileBox(int tx, int ty) const {
  const BlockRect r = layout_.tileBlocks(tx, ty);
  const TileInfo& i = info(tx, ty);
  const double b = layout_.block;
  return Box3::fromPoints(Vec3(float(r.x0 * b * layout_.cell_x), float(r.y0 * b * layout_.cell_y), i.z_min),
                          Vec3(float(r.x1 * b * layout_.cell_x), float(r.y1 * b * layout_.cell_y), i.z_max));
}

float TileCache::minHeight() const {
  float z = std::numeric_limits<float>::max();
  for (const TileInfo& i : tiles_) z = std::min(z, i.z_min);
  return z;
}

float TileCache::maxHeight() const {
  float z = std::numeric_limits<float>::lowest();
  for (const TileInfo& i : tiles_) z = std::max(z, i.z_max);
  return z;
}

int TileCache::stepFor(int tx, int ty, const Vec3& eye, double lambda, float tau) const {
  const Box3 box = tileBox(tx, ty);
  const DVec3 e(eye), nearest = glm::clamp(e, DVec3(box.lo), DVec3(box.hi));
  // A little closer than measured, so that rounding in QuadtreeLod::active cannot make a vertex active that this
  // test left out.
  const double distance = glm::length(e - nearest) * (1.0 - 1e-6) - 1e-3;
  const TileInfo& i = info(tx, ty);
  // The finest scale that may hold an active vertex (QuadtreeLod::active with |eye - v| >= distance); 2 * block
  // when none may.
  int finest = 2 * layout_.block;
  for (int l = int(i.level_error.size()) - 1; l >= 0; --l) {
    const double delta = i.level_error[size_t(l)];
    if (delta > 0.0 && lambda * delta > double(tau) * (distance - double(i.level_radius[size_t(l)])))
      finest = 2 << l;
  }
  return std::clamp(finest / 4, 1, layout_.block / 2);
}

Heightfield TileCache::overview(int step) const {
  const TileLayout& l = layout_;
  if (step < 1 || step > l.block / 2 || (step & (step - 1)) != 0)
    throw Error(path_, "overview step " + std::to_string(step) + " is not a power of two from 1 to " +
                           std::to_string(l.block / 2));
  Heightfield out((l.width - 1) / step + 1, (l.height - 1) / step + 1, 1.0);
  out.cell_x = l.cell_x * step;
  out.cell_y = l.cell_y * step;
  out.source = path_ + " at step " + std::to_string(step);
  for (int ty = 0; ty < l.tilesY(); ++ty)
    for (int tx = 0; tx < l.tilesX(); ++tx) {
      const TileGrid g = readPlanes(tx, ty, step, 1);  // the heights alone
      const int per_block = l.block / step;
      // The tile's own blocks, edges included (neighbours write the same heights on shared edges).
      for (int j = g.blocks.y0 * per_block; j <= g.blocks.y1 * per_block; ++j)
        for (int i = g.blocks.x0 * per_block; i <= g.blocks.x1 * per_block; ++i)
          out.at(g.origin.x / step + i, g.origin.y / step + j) = g.hf.at(i, j);
    }
  return out;
}

TileGrid TileCache::read(int tx, int ty, int step) const { return readPlanes(tx, ty, step, 3); }

TileGrid TileCache::readPlanes(int tx, int ty, int step, int planes_wanted) const {
  const TileLayout& l = layout_;
  FF_CHECK(tx >= 0 && ty >= 0 && tx < l.tilesX() && ty < l.tilesY());
  FF_CHECK(step >= 1 && step <= l.block / 2 && (step & (step - 1)) == 0);
  const BlockRect s = l.storedBlocks(tx, ty), own = l.tileBlocks(tx, ty);
  const int w = storedWidth(s, l.block), h = storedHeight(s, l.block);
  const int ws = (w - 1) / step + 1, hs = (h - 1) / step + 1;
  TileGrid g;
  g.step = step;
  g.origin = IVec2(s.x0 * l.block, s.y0 * l.block);
  g.blocks = {own.x0 - s.x0, own.y0 - s.y0, own.x1 - s.x0, own.y1 - s.y0};
  g.hf = Heightfield(ws, hs, 1.0);
  g.hf.cell_x = l.cell_x * step;
  g.hf.cell_y = l.cell_y * step;
  g.hf.source = path_ + " tile (" + std::to_string(tx) + ", " + std::to_string(ty) + ")";
  if (planes_wanted == 3) {
    g.error.resize(g.hf.size());
    g.radius.resize(g.hf.size());
  }

  const int fd = ::open(path_.c_str(), O_RDONLY);
  if (fd < 0) throw Error(path_, "cannot open the tile cache");
  std::vector<float> row(static_cast<size_t>(w));
  float* planes[3] = {g.hf.heights.data(), g.error.data(), g.radius.data()};
  const uint64_t plane_bytes = uint64_t(w) * uint64_t(h) * sizeof(float);
  for (int p = 0; p < planes_wanted; ++p)
    for (int j = 0; j < hs; ++j) {
      const uint64_t at = info(tx, ty).offset + uint64_t(p) * plane_bytes + uint64_t(j) * step * w * sizeof(float);
      const size_t want = row.size() * sizeof(float);
      const uint64_t sum_at = info(tx, ty).offset + 3 * plane_bytes + (uint64_t(p) * uint64_t(h) + uint64_t(j) * step) * 8;
      uint64_t sum = 0;
      if (::pread(fd, row.data(), want, off_t(at)) != ssize_t(want) ||
          ::pread(fd, &sum, sizeof sum, off_t(sum_at)) != ssize_t(sizeof sum)) {
        ::close(fd);
        throw Error(path_, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + "): cannot read its data");
      }
      if (sum != rowChecksum(row.data(), row.size())) {
        ::close(fd);
        throw Error(path_, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + "): row " +
                               std::to_string(j * step) + " of its " + kPlaneNames[p] + " fails its checksum");
      }
      float* dst = planes[p] + size_t(j) * size_t(ws);
      for (int i = 0; i < ws; ++i) dst[i] = row[size_t(i) * size_t(step)];
    }
  ::close(fd);
  return g;
}

size_t TileCache::residentBytes(int tx, int ty, int step) const {
  const BlockRect s = layout_.storedBlocks(tx, ty);
  const size_t ws = size_t((storedWidth(s, layout_.block) - 1) / step + 1);
  const size_t hs = size_t((storedHeight(s, layout_.block) - 1) / step + 1);
  return ws * hs * (sizeof(float) * 3 + sizeof(Vec3));
}

}  // namespace farfield::terrain
