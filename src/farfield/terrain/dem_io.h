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
#include <string>

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

Heightfield loadDem(const std::string& path, const DemLoadOptions& options = {});

}  // namespace farfield::terrain
