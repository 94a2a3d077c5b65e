// DEM input through GDAL: GeoTIFF, netCDF (the first subdataset when the file has several), 16-bit PNG and any
// other single-band raster GDAL reads.
//
// - Heights: band 1 (or the chosen band) with the band's scale and offset applied, converted to metres when the
//   band's unit is feet. Grid points equal to the band's nodata value, or not finite, are nodata: they are filled
//   (fillNodata) and counted in Heightfield::nodata_count.
// - Cell size from the geotransform: projected rasters in their linear unit converted to metres; geographic rasters
//   (degrees) at the latitude of the raster's centre (WGS84 mean radius; a note says so). Rasters without
//   georeferencing (a plain PNG) get DemLoadOptions::cell_size, or 1 m with a note. Rotated grids are refused.
// - Rows are flipped so that row 0 is the south edge (see heightfield.h).
// Errors (farfield::Error naming the file): missing file, a file GDAL cannot read as a raster, no raster bands,
// every grid point nodata, a rotated or degenerate geotransform, a grid smaller than 2x2, a grid of more than
// DemLoadOptions::max_grid_points points (checked from the header, before anything is allocated).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

struct DemLoadOptions {
  int band = 1;                // 1-based raster band
  double cell_size = 0.0;      // metres; > 0 overrides the georeferencing (and is required to be exact for PNG)
  double height_scale = 1.0;   // applied after the band's own scale/offset and unit conversion
  // Larger grids are refused (a damaged or hostile header may claim any size): 2^28 points (16384 x 16384) hold 1 GiB
  // of heights, the largest terrain the quadtree LOD's 32-bit vertex ids and one GPU buffer serve comfortably.
  uint64_t max_grid_points = uint64_t(1) << 28;
};

// The whole raster (checked against max_grid_points before anything is read).
Heightfield loadDem(const std::string& path, const DemLoadOptions& options = {});

// Writes hf as a single-band Float32 GeoTIFF (BigTIFF when large), row 0 north: its cell size, georeferencing
// (geo_origin and crs, when set) and no nodata. loadDem reads the same heights back. Throws farfield::Error naming
// path when GDAL cannot write it.
void writeDem(const Heightfield& hf, const std::string& path);

// A DEM raster read by windows, for rasters larger than memory (a tile cache is written from one: tile_cache.h).
// Opening reads the header only (the same checks and notes as loadDem). A window holds exactly the heights loadDem
// would give its points: nodata is filled from a margin of 3 * kNodataFillRings points around the window, beyond
// the fill's reach at the whole raster's lowest height (found by one pass over the raster, on the first window
// with nodata in it).
class DemReader {
 public:
  explicit DemReader(const std::string& path, const DemLoadOptions& options = {});
  ~DemReader();
  DemReader(const DemReader&) = delete;
  DemReader& operator=(const DemReader&) = delete;

  // Size, cell size, georeferencing, source and notes; no heights.
  const Heightfield& header() const { return header_; }
  int width() const { return header_.width; }
  int height() const { return header_.height; }
  // Grid points [i0, i0 + w) x [j0, j0 + h) (row 0 south, as in heightfield.h), with nodata flagged in the
  // window's mask and filled. Throws farfield::Error naming the file for a window outside the raster, a window of
  // more than max_grid_points points, a read error, or a raster without a valid point.
  Heightfield read(int i0, int j0, int w, int h) const;
  // Nodata grid points in the whole raster (one pass over it, once).
  size_t nodataCount() const;

 private:
  struct Impl;
  Heightfield readRaw(int i0, int j0, int w, int h, std::vector<uint8_t>& mask) const;
  void scan() const;

  std::unique_ptr<Impl> impl_;
  DemLoadOptions options_;
  Heightfield header_;
};

}  // namespace farfield::terrain
