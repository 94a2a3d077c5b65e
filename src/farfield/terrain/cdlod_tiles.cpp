#include "farfield/terrain/cdlod_tiles.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/log.h"

// xxHash inlined from its header (libxxhash-dev): no library to link.
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace farfield::terrain {
int cdlodTileLevel(const TileLayout& layout, const CdlodOptions& options) {
  const int64_t tile = int64_t(layout.tile_blocks) * layout.block;
  int level = -1;
  for (int l = 0; l <= 24 && (int64_t(options.patch_cells) << l) <= tile; ++l)
    if (tile % (int64_t(options.patch_cells) << l) == 0) level = l;
  return level;
}

CdlodTerrain cdlodFromTileCache(const TileCache& cache, const CdlodOptions& options) {
  const TileLayout& layout = cache.layout();
  const CdlodGrid grid{layout.width, layout.height, layout.cell_x, layout.cell_y};
  const int top = CdlodTerrain::topLevelFor(grid, options, cache.path());
  const int p = options.patch_cells;
  const int tile_level = std::min(cdlodTileLevel(layout, options), top);
  if (tile_level < 0)
    throw Error(cache.path(), "a CDLOD patch of " + std::to_string(p) + " cells does not fit in its tiles of " +
                                  std::to_string(layout.tile_blocks * layout.block) + " cells");
  // The terrain's node layout, its data filled below.
  const size_t total = CdlodTerrain::nodeCountFor(grid, options);
  const CdlodTerrain shape(grid, options, std::vector<Vec2>(total, Vec2(0.0f)), std::vector<float>(total, 0.0f));
  auto index = [&](int l, int x, int y) { return shape.nodeIndex({l, x, y}); };
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::vector<Vec2> heights(total, Vec2(kInf, -kInf));
  std::vector<float> errors(total, 0.0f);

  // Levels 0..Lt, tile by tile: a node lies in exactly one tile (its border points in the tile's own area too).
  // Level 0's height ranges from the points; the errors of levels 1..Lt from the points against each level's mesh.
  const int tile_cells = layout.tile_blocks * layout.block;
  for (int ty = 0; ty < layout.tilesY(); ++ty)
    for (int tx = 0; tx < layout.tilesX(); ++tx) {
      const TileGrid g = cache.readHeights(tx, ty, 1);
      auto h = [&](int i, int j) {
        i = std::clamp(i, 0, grid.width - 1);
        j = std::clamp(j, 0, grid.height - 1);
        return g.hf.at(i - g.origin.x, j - g.origin.y);
      };
      for (int l = 0; l <= tile_level; ++l) {
        const int cells = p << l, per_tile = tile_cells / cells;
        for (int y = ty * per_tile; y < std::min((ty + 1) * per_tile, shape.nodesY(l)); ++y)
          for (int x = tx * per_tile; x < std::min((tx + 1) * per_tile, shape.nodesX(l)); ++x) {
            const int x0 = x * cells, y0 = y * cells;
            const int x1 = std::min(x0 + cells, grid.width - 1), y1 = std::min(y0 + cells, grid.height - 1);
            if (l > 0) {
              errors[index(l, x, y)] = float(levelMeshError(h, x0, y0, x1, y1, 1 << l));
              continue;
            }
            Vec2& range = heights[index(0, x, y)];
            for (int j = y0; j <= y1; ++j)
              for (int i = x0; i <= x1; ++i) range = Vec2(std::min(range.x, h(i, j)), std::max(range.y, h(i, j)));
          }
      }
    }

  // Coarser levels' height ranges from their children; above Lt, their errors bounded on the overview's level-Lt
  // vertices (max E of the level-Lt descendants + the level mesh's distance at those vertices).
  const int lt_spacing = 1 << tile_level;
  int step = 1;
  while (step * 2 <= std::min(lt_spacing, layout.block / 2)) step *= 2;
  const Heightfield overview = tile_level < top ? cache.overview(step) : Heightfield();
  auto h = [&](int i, int j) {  // grid point (i, j), a multiple of step, clamped to the grid
    i = std::clamp(i, 0, grid.width - 1);
    j = std::clamp(j, 0, grid.height - 1);
    return overview.at(i / step, j / step);
  };
  std::vector<float> descendants = errors;  // above Lt: max E over the level-Lt nodes below
  for (int l = 1; l <= top; ++l) {
    const int cells = p << l;
    for (int y = 0; y < shape.nodesY(l); ++y)
      for (int x = 0; x < shape.nodesX(l); ++x) {
        Vec2& range = heights[index(l, x, y)];
        float below = 0.0f;
        for (int c = 0; c < 4; ++c) {
          const int cx = 2 * x + (c & 1), cy = 2 * y + (c >> 1);
          if (cx >= shape.nodesX(l - 1) || cy >= shape.nodesY(l - 1)) continue;
          const Vec2 r = heights[index(l - 1, cx, cy)];
          range = Vec2(std::min(range.x, r.x), std::max(range.y, r.y));
          below = std::max(below, descendants[index(l - 1, cx, cy)]);
        }
        if (l <= tile_level) continue;
        descendants[index(l, x, y)] = below;
        const int x0 = x * cells, y0 = y * cells;
        const int x1 = std::min(x0 + cells, grid.width - 1), y1 = std::min(y0 + cells, grid.height - 1);
        errors[index(l, x, y)] = below + float(levelMeshError(h, x0, y0, x1, y1, 1 << l, lt_spacing));
      }
  }
  return CdlodTerrain(grid, options, std::move(heights), std::move(errors));
}

namespace {

constexpr char kKeptMagic[8] = {'F', 'F', 'C', 'D', 'L', 'O', 'D', '1'};

// The header of a kept file: what it was made for.
struct KeptHeader {
  char magic[8];
  uint32_t version;
  int32_t width, height, patch_cells, max_level, top;
  uint64_t cache_bytes;
  int64_t cache_time;
  uint64_t nodes;
};

KeptHeader keptHeaderFor(const TileCache& cache, const CdlodOptions& options, int top, uint64_t nodes) {
  KeptHeader h{};
  std::memcpy(h.magic, kKeptMagic, 8);
  h.version = 1;
  h.width = cache.layout().width;
  h.height = cache.layout().height;
  h.patch_cells = options.patch_cells;
  h.max_level = options.max_level;
  h.top = top;
  std::error_code ec;
  h.cache_bytes = std::filesystem::file_size(cache.path(), ec);
  h.cache_time = int64_t(std::filesystem::last_write_time(cache.path(), ec).time_since_epoch().count());
  h.nodes = nodes;
  return h;
}

}  // namespace

CdlodTerrain cdlodFromTileCacheKept(const TileCache& cache, const CdlodOptions& options, bool* reused) {
  if (reused) *reused = false;
  const std::string kept = cache.path() + ".cdlod";
  const TileLayout& layout = cache.layout();
  const CdlodGrid grid{layout.width, layout.height, layout.cell_x, layout.cell_y};
  const int top = CdlodTerrain::topLevelFor(grid, options, cache.path());
  const uint64_t nodes = CdlodTerrain::nodeCountFor(grid, options);
  const KeptHeader want = keptHeaderFor(cache, options, top, nodes);
  const size_t body = size_t(nodes) * (sizeof(Vec2) + sizeof(float));
  if (std::filesystem::exists(kept)) {
    std::ifstream in(kept, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    KeptHeader have{};
    if (bytes.size() >= sizeof(KeptHeader)) std::memcpy(&have, bytes.data(), sizeof(KeptHeader));
    const bool matches = bytes.size() == sizeof(KeptHeader) + body + sizeof(uint64_t) &&
                         std::memcmp(&have, &want, sizeof(KeptHeader)) == 0;
    uint64_t sum = 0;
    if (matches) std::memcpy(&sum, bytes.data() + sizeof(KeptHeader) + body, sizeof(sum));
    if (matches && sum == XXH3_64bits(bytes.data(), sizeof(KeptHeader) + body)) {
      std::vector<Vec2> heights(nodes);
      std::vector<float> errors(nodes);
      std::memcpy(heights.data(), bytes.data() + sizeof(KeptHeader), nodes * sizeof(Vec2));
      std::memcpy(errors.data(), bytes.data() + sizeof(KeptHeader) + nodes * sizeof(Vec2), nodes * sizeof(float));
      if (reused) *reused = true;
      return CdlodTerrain(grid, options, std::move(heights), std::move(errors));
    }
    if (std::memcmp(have.magic, kKeptMagic, 8) == 0 && std::memcmp(&have, &want, sizeof(KeptHeader)) == 0)
      FF_WARN(kept << ": damaged (its checksum does not hold); made again from the tile cache");
  }
  CdlodTerrain lod = cdlodFromTileCache(cache, options);
  std::string out(sizeof(KeptHeader), '\0');
  std::memcpy(out.data(), &want, sizeof(KeptHeader));
  for (int l = 0; l <= lod.topLevel(); ++l)
    for (int y = 0; y < lod.nodesY(l); ++y)
      for (int x = 0; x < lod.nodesX(l); ++x) {
        const Vec2 h = lod.nodeHeights({l, x, y});
        out.append(reinterpret_cast<const char*>(&h), sizeof(h));
      }
  for (int l = 0; l <= lod.topLevel(); ++l)
    for (int y = 0; y < lod.nodesY(l); ++y)
      for (int x = 0; x < lod.nodesX(l); ++x) {
        const float e = lod.nodeError({l, x, y});
        out.append(reinterpret_cast<const char*>(&e), sizeof(e));
      }
  const uint64_t sum = XXH3_64bits(out.data(), out.size());
  out.append(reinterpret_cast<const char*>(&sum), sizeof(sum));
  const std::string tmp = kept + ".tmp";
  {
    std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
    file.write(out.data(), std::streamsize(out.size()));
    file.flush();
    if (!file) {
      FF_WARN(kept << ": cannot be written; the node data will be made again next time");
      return lod;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, kept, ec);
  if (ec) FF_WARN(kept << ": cannot be moved into place (" << ec.message() << ")");
  return lod;
}

}  // namespace farfield::terrain
