// Heightfield: a regular grid of heights in metres with its cell size, georeferencing and nodata mask.
//
// Grid and world frame: grid point (i, j), column i = 0..width-1 going east, row j = 0..height-1 going north (row 0
// is the SOUTH edge, unlike image files, whose row 0 is the north edge; loaders flip). The terrain's local world
// frame puts grid point (0, 0) at the origin: world position (i * cell_x, j * cell_y, height(i, j)). Georeferenced
// coordinates of grid point (i, j) are geo_origin + (i * cell_x, j * cell_y) in the source's horizontal units
// (projected metres for UTM; for geographic rasters cell_x/cell_y are converted to metres, see dem_io.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield::terrain {

struct Heightfield {
  int width = 0;   // grid points per row (east-west)
  int height = 0;  // rows (south-north)
  double cell_x = 1.0;  // metres between neighbouring columns
  double cell_y = 1.0;  // metres between neighbouring rows
  DVec2 geo_origin{0.0};  // georeferenced coordinates of grid point (0, 0) (its centre), source units
  std::string crs;        // the source's coordinate reference system (WKT), "" when unknown
  std::string source;     // file name or a description ("fractal 513x513 seed 7")
  std::vector<float> heights;   // width * height, row-major, index i + j * width; metres
  std::vector<uint8_t> nodata;  // empty, or one flag per grid point: 1 where the source had no data (now filled)
  size_t nodata_count = 0;      // number of grid points flagged in `nodata`
  std::vector<std::string> notes;  // what the loader assumed or converted ("no georeferencing: 1 m cells")

  Heightfield() = default;
  Heightfield(int w, int h, double cell = 1.0, float fill = 0.0f);

  size_t size() const { return heights.size(); }
  size_t index(int i, int j) const { return size_t(i) + size_t(j) * size_t(width); }
  float at(int i, int j) const { return heights[index(i, j)]; }
  float& at(int i, int j) { return heights[index(i, j)]; }
  // Height at grid point (i, j) with i, j clamped into the grid.
  float clampedAt(int i, int j) const;
  // World position of grid point (i, j) (local frame, see the file comment).
  Vec3 position(int i, int j) const { return Vec3(float(i * cell_x), float(j * cell_y), at(i, j)); }
  Vec3 position(size_t index) const {
    return position(int(index % size_t(width)), int(index / size_t(width)));
  }
  // Bilinear height at a world (x, y) in the local frame, clamped to the grid.
  float sample(double x, double y) const;
  // Unit surface normal at grid point (i, j) from central differences (one-sided at the border).
  Vec3 normal(int i, int j) const;
  // Slope at grid point (i, j), radians from horizontal.
  float slope(int i, int j) const { return std::acos(std::clamp(normal(i, j).z, -1.0f, 1.0f)); }
  float minHeight() const;
  float maxHeight() const;
  // World extent (x, y, z) of the grid in the local frame.
  Box3 bounds() const;
  double extentX() const { return (width - 1) * cell_x; }
  double extentY() const { return (height - 1) * cell_y; }

  // Sub-grid of w x h points starting at grid point (i0, j0); throws farfield::Error when it does not fit.
  Heightfield crop(int i0, int j0, int w, int h) const;
};

// Fills the grid points flagged in `mask` (1 = no data) from their valid neighbours: grid points are filled in
// order of their distance (in grid steps, 8-neighbourhood) to the nearest valid point, each with the mean of its
// already known 8-neighbours, so holes fill inwards from their rims with a smooth blend. Points farther than
// kNodataFillRings steps from any valid point take far_height (NaN: the lowest valid height of hf), so that what a
// point gets depends only on the grid within 3 * kNodataFillRings steps of it (a window read of a large raster
// fills as the whole raster would). Sets hf.nodata = mask and hf.nodata_count. Throws farfield::Error (naming
// hf.source) when every grid point is flagged and far_height is NaN.
inline constexpr int kNodataFillRings = 64;
void fillNodata(Heightfield& hf, const std::vector<uint8_t>& mask,
                float far_height = std::numeric_limits<float>::quiet_NaN());

// The largest centred sub-grid whose size is (a * block + 1) x (b * block + 1) with a, b >= 1 (block a power of
// two), which is what the quadtree LOD needs. Throws farfield::Error when the grid is smaller than block + 1.
Heightfield cropForBlocks(const Heightfield& hf, int block);

}  // namespace farfield::terrain
