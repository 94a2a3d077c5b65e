// Large terrains held in tiles on disk (issue 18: DEMs of 8,193 x 8,193 points and more, paged under a memory
// budget with the quadtree LOD built per tile; Chen et al. 1999 section 2.2's LOD, quadtree_lod.h).
//
// A tile cache file holds a grid of (a * block + 1) x (b * block + 1) points cut into tiles of tile_blocks x
// tile_blocks LOD blocks. Per tile it stores, for the tile's blocks plus one block of apron on each side where the
// map continues: the heights and the full-resolution LOD's saturated errors and sphere radii, computed once when the
// cache is written from the tile and its apron. The apron makes them exact: a vertex's error and sphere depend only
// on the grid points of its diamond, which reaches at most half a block past the tile. So a tile's LOD, built from
// the cache, activates exactly the vertices the whole grid's LOD activates (test_tiled_lod.cpp).
//
// Per tile and per level of the vertex hierarchy (scale 2, 4, ..., block) the cache also keeps the largest error and
// sphere radius over the tile's vertices of that level, so a reader can tell from the eye's distance to the tile's
// box which levels may be active, and read only every step-th grid point of a far tile (stepFor).
//
// File: "FFTILES1", version, grid and tiling sizes, cell sizes, one index record per tile (height range, the level
// maxima, the data offset), then per tile three planes of floats (heights, errors, radii), row-major, south row
// first, and a checksum (XXH3, 64 bits) per row of each plane. Written to a temporary file and renamed. A reader checks
// the header, the index, that every tile's data lie inside the file and every row it reads against its checksum,
// and names the file (and the tile, plane and row) in every error.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

// Blocks [x0, x1) x [y0, y1) of the LOD's block grid.
struct BlockRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

struct TileLayout {
  int width = 0, height = 0;  // grid points
  int block = 0;              // LOD block, cells (a power of two)
  int tile_blocks = 0;        // blocks per tile side (the last row / column of tiles may be narrower)
  double cell_x = 1.0, cell_y = 1.0;

  int blocksX() const { return (width - 1) / block; }
  int blocksY() const { return (height - 1) / block; }
  int tilesX() const { return (blocksX() + tile_blocks - 1) / tile_blocks; }
  int tilesY() const { return (blocksY() + tile_blocks - 1) / tile_blocks; }
  int levels() const;  // log2(block): scales 2, 4, ..., block
  BlockRect tileBlocks(int tx, int ty) const;
  // The tile's blocks and one block of apron on each side where the grid continues.
  BlockRect storedBlocks(int tx, int ty) const;
};

struct TileInfo {
  int tx = 0, ty = 0;
  float z_min = 0.0f, z_max = 0.0f;  // the tile's heights, metres
  std::vector<float> level_error;    // [l]: largest saturated error (metres) of the tile's vertices of scale 2^(l+1)
  std::vector<float> level_radius;   // [l]: largest sphere radius (metres) of those vertices
  uint64_t offset = 0;               // of the tile's data in the file
};

// A tile read at a step: every step-th point of its stored grid.
struct TileGrid {
  Heightfield hf;                   // cell = step * the grid's cell; source "<file> tile (tx, ty)"
  std::vector<float> error, radius; // the full grid's saturated errors and radii at hf's points
  IVec2 origin{0};                  // full-grid point of hf's (0, 0)
  int step = 1;
  BlockRect blocks;                 // the tile's own blocks, in hf's LOD blocks (block / step points)
};

class TileCache {
 public:
  // Writes hf (whole LOD blocks: cropForBlocks) as a tile cache. tile_blocks >= 1. Throws farfield::Error naming
  // path when it cannot be written, or hf when it is not made of whole blocks.
  static void write(const Heightfield& hf, int block, int tile_blocks, const std::string& path);
  // Writes the cache of a DEM raster cropped to whole blocks as cropForBlocks crops it, reading one tile and its
  // apron at a time: a raster larger than memory. The same file as writing loadDem's heightfield (cropped).
  static void write(const DemReader& dem, int block, int tile_blocks, const std::string& path);
  // Grid points [i0, i0 + w) x [j0, j0 + h) of the grid being written.
  using HeightWindow = std::function<Heightfield(int i0, int j0, int w, int h)>;
  // The general form: layout's size, block, tiling and cells; each tile's stored region read from `window`.
  // `source` names the grid in errors.
  static void write(const TileLayout& layout, const std::string& source, const HeightWindow& window,
                    const std::string& path);

  // Opens a cache and reads its index; throws farfield::Error naming path for a missing, short or damaged file.
  explicit TileCache(const std::string& path);

  const std::string& path() const { return path_; }
  const TileLayout& layout() const { return layout_; }
  const TileInfo& info(int tx, int ty) const { return tiles_[size_t(tx) + size_t(ty) * size_t(layout_.tilesX())]; }
  // The tile's own box in the local world frame (heightfield.h), x/y of its blocks, z its height range.
  Box3 tileBox(int tx, int ty) const;
  float minHeight() const;
  float maxHeight() const;

  // The coarsest step at which tile (tx, ty) gives the same LOD mesh and quadrants as the full grid for an eye at
  // `eye` (lambda pixels per radian, tau the pixel threshold): the finest level that may hold an active vertex,
  // from the level maxima and the eye's distance to the tile's box, and one level finer for the quadrants' central
  // vertices and the culling spheres of the finest triangles. A power of two, 1 .. block / 2.
  int stepFor(int tx, int ty, const Vec3& eye, double lambda, float tau) const;

  // Reads tile (tx, ty) at `step` (a power of two, 1 .. block / 2). Throws farfield::Error naming the file.
  TileGrid read(int tx, int ty, int step) const;
  // The same tile's heights alone (TileGrid::error and radius left empty): a third of the reading.
  TileGrid readHeights(int tx, int ty, int step) const { return readPlanes(tx, ty, step, 1); }
  // The whole grid at every step-th point (a power of two, 1 .. block / 2), read tile by tile: what a flythrough or
  // a map is planned on without holding the grid. cell = step * the grid's cell; source "<file> at step N".
  Heightfield overview(int step) const;
  // Bytes a tile read at step holds once it has its LOD (tile_pager.h): heights, errors, radii and positions.
  size_t residentBytes(int tx, int ty, int step) const;

 private:
  // The first planes_wanted planes of a tile (1: heights; 3: heights, errors, radii) at step.
  TileGrid readPlanes(int tx, int ty, int step, int planes_wanted) const;

  std::string path_;
  TileLayout layout_;
  std::vector<TileInfo> tiles_;
  uint64_t file_size_ = 0;
};

}  // namespace farfield::terrain
