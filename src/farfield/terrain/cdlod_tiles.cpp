#include "farfield/terrain/cdlod_tiles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::terrain {
namespace {

// The largest vertical distance between the grid points h(i, j) of [x0, x1] x [y0, y1] and the level mesh of spacing
// s over them (cells split along their (0,0)-(1,1) diagonal), as CdlodTerrain computes it; h clamps to the grid.
template <class Height>
double meshError(const Height& h, int x0, int y0, int x1, int y1, int s) {
  const double inv = 1.0 / s;
  double worst = 0.0;
  for (int j = y0; j <= y1; ++j) {
    const int cy = j / s * s;
    const double v = (j - cy) * inv;
    for (int i = x0; i <= x1; ++i) {
      const int cx = i / s * s;
      if (i == cx && j == cy) continue;
      const double u = (i - cx) * inv;
      const double h00 = h(cx, cy), h10 = h(cx + s, cy), h01 = h(cx, cy + s), h11 = h(cx + s, cy + s);
      const double mesh = u >= v ? h00 + u * (h10 - h00) + v * (h11 - h10) : h00 + v * (h01 - h00) + u * (h11 - h01);
      worst = std::max(worst, std::abs(mesh - double(h(i, j))));
    }
  }
  return worst;
}

}  // namespace

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
  auto nodes = [&](int l, bool x) {
    const int64_t cells = int64_t(p) << l;
    return int((int64_t((x ? grid.width : grid.height) - 1) + cells - 1) / cells);
  };
  std::vector<size_t> offset(size_t(top) + 1, 0);
  size_t total = 0;
  for (int l = 0; l <= top; ++l) {
    offset[size_t(l)] = total;
    total += size_t(nodes(l, true)) * size_t(nodes(l, false));
  }
  auto index = [&](int l, int x, int y) { return offset[size_t(l)] + size_t(x) + size_t(y) * size_t(nodes(l, true)); };
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::vector<Vec2> heights(total, Vec2(kInf, -kInf));
  std::vector<float> errors(total, 0.0f);

  // Levels 0..Lt, tile by tile: a node lies in exactly one tile (its border points in the tile's own area too).
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
        for (int y = ty * per_tile; y < std::min((ty + 1) * per_tile, nodes(l, false)); ++y)
          for (int x = tx * per_tile; x < std::min((tx + 1) * per_tile, nodes(l, true)); ++x) {
            const int x0 = x * cells, y0 = y * cells;
            const int x1 = std::min(x0 + cells, grid.width - 1), y1 = std::min(y0 + cells, grid.height - 1);
            Vec2& range = heights[index(l, x, y)];
            for (int j = y0; j <= y1; ++j)
              for (int i = x0; i <= x1; ++i) {
                const float v = h(i, j);
                range = Vec2(std::min(range.x, v), std::max(range.y, v));
              }
            if (l > 0) errors[index(l, x, y)] = float(meshError(h, x0, y0, x1, y1, 1 << l));
          }
      }
    }

  // Coarser levels: height ranges from the children, errors bounded on the overview's level-Lt vertices.
  if (tile_level < top) {
    const int lt_spacing = 1 << tile_level;
    int step = 1;
    while (step * 2 <= std::min(lt_spacing, layout.block / 2)) step *= 2;
    const Heightfield overview = cache.overview(step);
    auto h = [&](int i, int j) {  // grid point (i, j), a multiple of step, clamped to the grid
      i = std::clamp(i, 0, grid.width - 1);
      j = std::clamp(j, 0, grid.height - 1);
      return overview.at(i / step, j / step);
    };
    std::vector<float> descendants(total, 0.0f);  // max E over the level-Lt nodes below
    for (int y = 0; y < nodes(tile_level, false); ++y)
      for (int x = 0; x < nodes(tile_level, true); ++x) descendants[index(tile_level, x, y)] = errors[index(tile_level, x, y)];
    for (int l = tile_level + 1; l <= top; ++l) {
      const int cells = p << l, s = 1 << l;
      for (int y = 0; y < nodes(l, false); ++y)
        for (int x = 0; x < nodes(l, true); ++x) {
          Vec2& range = heights[index(l, x, y)];
          float below = 0.0f;
          for (int c = 0; c < 4; ++c) {
            const int cx = 2 * x + (c & 1), cy = 2 * y + (c >> 1);
            if (cx >= nodes(l - 1, true) || cy >= nodes(l - 1, false)) continue;
            const Vec2 r = heights[index(l - 1, cx, cy)];
            range = Vec2(std::min(range.x, r.x), std::max(range.y, r.y));
            below = std::max(below, descendants[index(l - 1, cx, cy)]);
          }
          descendants[index(l, x, y)] = below;
          // max |h - m_L| over the level-Lt vertices of the node's area.
          const int x0 = x * cells, y0 = y * cells;
          const int x1 = std::min(x0 + cells, grid.width - 1), y1 = std::min(y0 + cells, grid.height - 1);
          double worst = 0.0;
          for (int j = y0; j <= y1; j += lt_spacing) {
            const int cy = j / s * s;
            const double v = double(j - cy) / s;
            for (int i = x0; i <= x1; i += lt_spacing) {
              const int cx = i / s * s;
              const double u = double(i - cx) / s;
              const double h00 = h(cx, cy), h10 = h(cx + s, cy), h01 = h(cx, cy + s), h11 = h(cx + s, cy + s);
              const double mesh =
                  u >= v ? h00 + u * (h10 - h00) + v * (h11 - h10) : h00 + v * (h01 - h00) + u * (h11 - h01);
              worst = std::max(worst, std::abs(mesh - double(h(i, j))));
            }
          }
          errors[index(l, x, y)] = below + float(worst);
        }
    }
  }
  return CdlodTerrain(grid, options, std::move(heights), std::move(errors));
}

}  // namespace farfield::terrain
