#include "farfield/terrain/dem_io.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"

namespace farfield::terrain {
namespace {

void registerGdalOnce() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

// GDAL reports problems through its error handler (stderr by default); keep them quiet and put the last message
// into our own errors instead.
struct QuietGdalErrors {
  QuietGdalErrors() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdalErrors() { CPLPopErrorHandler(); }
  static std::string last() {
    const char* msg = CPLGetLastErrorMsg();
    return msg && *msg ? std::string(" (GDAL: ") + msg + ")" : std::string();
  }
};

struct DatasetCloser {
  GDALDatasetH handle = nullptr;
  ~DatasetCloser() {
    if (handle) GDALClose(handle);
  }
};

bool isFeetUnit(std::string unit) {
  for (char& c : unit) c = char(std::tolower(static_cast<unsigned char>(c)));
  return unit == "ft" || unit == "foot" || unit == "feet" || unit == "us survey foot" || unit == "ftus";
}

}  // namespace

Heightfield loadDem(const std::string& path, const DemLoadOptions& options) {
  registerGdalOnce();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(path, "DEM file not found");
  if (std::filesystem::is_directory(path, ec)) throw Error(path, "is a directory, expected a DEM raster file");
  if (options.band < 1) throw Error(path, "band must be 1 or more");
  if (!(options.height_scale > 0.0) || !std::isfinite(options.height_scale))
    throw Error(path, "height scale must be a positive number");
  if (!(options.cell_size >= 0.0) || !std::isfinite(options.cell_size))
    throw Error(path, "cell size must be a finite number of metres (0: from the georeferencing)");

  QuietGdalErrors quiet;
  DatasetCloser ds;
  ds.handle = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!ds.handle)
    throw Error(path, "not a raster GDAL can read (expected a GeoTIFF, netCDF or 16-bit PNG DEM)" +
                          QuietGdalErrors::last());
  std::string opened = path;
  if (GDALGetRasterCount(ds.handle) == 0) {
    // netCDF files with several variables open as a container of subdatasets: take the first.
    char** subdatasets = GDALGetMetadata(ds.handle, "SUBDATASETS");
    const char* first = subdatasets ? CSLFetchNameValue(subdatasets, "SUBDATASET_1_NAME") : nullptr;
    if (!first) throw Error(path, "has no raster bands (expected a DEM with at least one band)");
    opened = first;
    GDALClose(ds.handle);
    ds.handle = GDALOpen(opened.c_str(), GA_ReadOnly);
    if (!ds.handle) throw Error(path, "cannot open its first subdataset " + opened + QuietGdalErrors::last());
  }
  const int bands = GDALGetRasterCount(ds.handle);
  if (options.band > bands)
    throw Error(path, "band " + std::to_string(options.band) + " requested but the raster has " +
                          std::to_string(bands));
  const int w = GDALGetRasterXSize(ds.handle), h = GDALGetRasterYSize(ds.handle);
  if (w < 2 || h < 2)
    throw Error(path, "raster is " + std::to_string(w) + "x" + std::to_string(h) + ", need at least 2x2 cells");
  capSize(uint64_t(w) * uint64_t(h), options.max_grid_points, path,
          "raster of " + std::to_string(w) + "x" + std::to_string(h) + " grid points:");

  Heightfield hf(w, h);
  hf.source = path;
  GDALRasterBandH band = GDALGetRasterBand(ds.handle, options.band);
  const GDALDataType type = GDALGetRasterDataType(band);
  if (type == GDT_CInt16 || type == GDT_CInt32 || type == GDT_CFloat32 || type == GDT_CFloat64)
    throw Error(path, "band " + std::to_string(options.band) + " holds complex numbers, expected heights");

  // Horizontal: geotransform and coordinate system.
  double gt[6] = {0, 1, 0, 0, 0, 1};
  const bool georeferenced = GDALGetGeoTransform(ds.handle, gt) == CE_None;
  bool north_up = true;  // raster row 0 is the north edge
  if (options.cell_size > 0.0) {
    hf.cell_x = hf.cell_y = options.cell_size;
    if (georeferenced) north_up = gt[5] < 0.0;
    hf.notes.push_back("cell size " + std::to_string(options.cell_size) + " m given by the caller");
  } else if (!georeferenced) {
    hf.cell_x = hf.cell_y = 1.0;
    hf.notes.push_back("no georeferencing: 1 m cells assumed (give a cell size to override)");
  } else {
    if (gt[2] != 0.0 || gt[4] != 0.0)
      throw Error(path, "rotated geotransform (terms " + std::to_string(gt[2]) + ", " + std::to_string(gt[4]) +
                            ") is not supported, expected a north-up grid");
    if (!(gt[1] != 0.0 && gt[5] != 0.0 && std::isfinite(gt[1]) && std::isfinite(gt[5])))
      throw Error(path, "degenerate geotransform (zero or non-finite pixel size)");
    north_up = gt[5] < 0.0;
    double unit_x = std::abs(gt[1]), unit_y = std::abs(gt[5]);
    const char* wkt = GDALGetProjectionRef(ds.handle);
    hf.crs = wkt ? wkt : "";
    OGRSpatialReferenceH srs = hf.crs.empty() ? nullptr : OSRNewSpatialReference(hf.crs.c_str());
    if (srs && OSRIsGeographic(srs)) {
      // Degrees to metres at the centre latitude on a sphere of the WGS84 mean radius.
      const double lat = gt[3] + gt[5] * (h * 0.5);
      const double metres_per_degree = 6371008.8 * kPi / 180.0;
      hf.cell_x = unit_x * metres_per_degree * std::cos(degToRad(lat));
      hf.cell_y = unit_y * metres_per_degree;
      hf.notes.push_back("geographic raster: cell size converted from degrees at latitude " + std::to_string(lat));
    } else if (srs && OSRIsProjected(srs)) {
      const double metres = OSRGetLinearUnits(srs, nullptr);
      hf.cell_x = unit_x * metres;
      hf.cell_y = unit_y * metres;
      if (std::abs(metres - 1.0) > 1e-12)
        hf.notes.push_back("horizontal unit converted to metres (x " + std::to_string(metres) + ")");
    } else {
      hf.cell_x = unit_x;
      hf.cell_y = unit_y;
      hf.notes.push_back("no coordinate system: geotransform units taken as metres");
    }
    if (srs) OSRDestroySpatialReference(srs);
    // A geotransform of extreme numbers (or a latitude past a pole) gives no usable cell size.
    if (!(std::isfinite(hf.cell_x) && std::isfinite(hf.cell_y) && hf.cell_x > 0.0 && hf.cell_y > 0.0))
      throw Error(path, "geotransform gives cells of " + std::to_string(hf.cell_x) + " x " +
                            std::to_string(hf.cell_y) + " m, expected positive finite sizes");
    // Georeferenced position of the south-west grid point's centre.
    const int south_row = north_up ? h - 1 : 0;
    hf.geo_origin = DVec2(gt[0] + gt[1] * 0.5, gt[3] + gt[5] * (south_row + 0.5));
  }

  // Vertical: raw values, nodata, scale/offset, unit.
  int has_nodata = 0;
  const double nodata_value = GDALGetRasterNoDataValue(band, &has_nodata);
  int has_scale = 0, has_offset = 0;
  double scale = GDALGetRasterScale(band, &has_scale);
  double offset = GDALGetRasterOffset(band, &has_offset);
  if (!has_scale) scale = 1.0;
  if (!has_offset) offset = 0.0;
  const char* unit = GDALGetRasterUnitType(band);
  double to_metres = 1.0;
  if (unit && isFeetUnit(unit)) {
    to_metres = 0.3048;
    hf.notes.push_back(std::string("heights converted from ") + unit + " to metres");
  }
  std::vector<uint8_t> mask(hf.size(), 0);
  // Row by row: a whole raster of doubles would take twice the heights' memory again.
  std::vector<double> raw(static_cast<size_t>(w));
  for (int r = 0; r < h; ++r) {
    if (GDALRasterIO(band, GF_Read, 0, r, w, 1, raw.data(), w, 1, GDT_Float64, 0, 0) != CE_None)
      throw Error(path, "cannot read band " + std::to_string(options.band) + " (row " + std::to_string(r) + ")" +
                            QuietGdalErrors::last());
    const int j = north_up ? h - 1 - r : r;
    for (int i = 0; i < w; ++i) {
      const double v = raw[size_t(i)];
      const size_t k = hf.index(i, j);
      const bool missing = !std::isfinite(v) ||
                           (has_nodata && (v == nodata_value || float(v) == float(nodata_value)));
      if (missing) {
        mask[k] = 1;
        hf.heights[k] = 0.0f;
      } else {
        hf.heights[k] = float((v * scale + offset) * to_metres * options.height_scale);
      }
    }
  }
  fillNodata(hf, mask);
  return hf;
}

}  // namespace farfield::terrain
