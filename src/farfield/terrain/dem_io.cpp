#include "farfield/terrain/dem_io.h"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

struct DemReader::Impl {
  DatasetCloser ds;
  GDALRasterBandH band = nullptr;
  bool north_up = true;
  bool has_nodata = false;
  double nodata_value = 0.0;
  double scale = 1.0, offset = 0.0, to_metres = 1.0;
  // The whole raster's first pass (scan): the lowest valid height and the nodata count.
  bool scanned = false;
  float lowest = 0.0f;
  size_t nodata = 0;
};

DemReader::DemReader(const std::string& path, const DemLoadOptions& options)
    : impl_(std::make_unique<Impl>()), options_(options) {
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
  DatasetCloser& ds = impl_->ds;
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

  Heightfield& hf = header_;
  hf.width = w;
  hf.height = h;
  hf.source = path;
  impl_->band = GDALGetRasterBand(ds.handle, options.band);
  GDALRasterBandH band = impl_->band;
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
  impl_->north_up = north_up;

  // Vertical: raw values, nodata, scale/offset, unit.
  int has_nodata = 0;
  impl_->nodata_value = GDALGetRasterNoDataValue(band, &has_nodata);
  impl_->has_nodata = has_nodata != 0;
  int has_scale = 0, has_offset = 0;
  impl_->scale = GDALGetRasterScale(band, &has_scale);
  impl_->offset = GDALGetRasterOffset(band, &has_offset);
  if (!has_scale) impl_->scale = 1.0;
  if (!has_offset) impl_->offset = 0.0;
  const char* unit = GDALGetRasterUnitType(band);
  if (unit && isFeetUnit(unit)) {
    impl_->to_metres = 0.3048;
    hf.notes.push_back(std::string("heights converted from ") + unit + " to metres");
  }
}

DemReader::~DemReader() = default;

Heightfield DemReader::readRaw(int i0, int j0, int w, int h, std::vector<uint8_t>& mask) const {
  QuietGdalErrors quiet;
  Heightfield hf(w, h);
  hf.cell_x = header_.cell_x;
  hf.cell_y = header_.cell_y;
  hf.crs = header_.crs;
  hf.source = header_.source;
  hf.notes = header_.notes;
  hf.geo_origin = header_.geo_origin + DVec2(i0 * header_.cell_x, j0 * header_.cell_y);
  mask.assign(hf.size(), 0);
  const Impl& m = *impl_;
  // Row by row: a window of doubles would take twice the heights' memory again.
  std::vector<double> raw(static_cast<size_t>(w));
  for (int j = 0; j < h; ++j) {
    const int r = m.north_up ? header_.height - 1 - (j0 + j) : j0 + j;
    if (GDALRasterIO(m.band, GF_Read, i0, r, w, 1, raw.data(), w, 1, GDT_Float64, 0, 0) != CE_None)
      throw Error(header_.source, "cannot read band " + std::to_string(options_.band) + " (row " +
                                      std::to_string(r) + ")" + QuietGdalErrors::last());
    for (int i = 0; i < w; ++i) {
      const double v = raw[size_t(i)];
      const size_t k = hf.index(i, j);
      const bool missing = !std::isfinite(v) ||
                           (m.has_nodata && (v == m.nodata_value || float(v) == float(m.nodata_value)));
      if (missing) {
        mask[k] = 1;
        hf.heights[k] = 0.0f;
      } else {
        hf.heights[k] = float((v * m.scale + m.offset) * m.to_metres * options_.height_scale);
      }
    }
  }
  // GDAL keeps the raster's blocks it read in its process-wide cache (by default 5 % of the machine's memory, which
  // held the whole of a 1 GiB raster read by windows); drop them, the window is copied.
  GDALFlushRasterCache(m.band);
  return hf;
}

void DemReader::scan() const {
  Impl& m = *impl_;
  if (m.scanned) return;
  std::vector<uint8_t> mask;
  float lowest = std::numeric_limits<float>::max();
  size_t nodata = 0;
  // In bands of rows, each read once.
  const int rows = std::max(1, int((size_t(16) << 20) / (sizeof(float) * size_t(header_.width))));
  for (int j = 0; j < header_.height; j += rows) {
    const Heightfield band = readRaw(0, j, header_.width, std::min(rows, header_.height - j), mask);
    for (size_t k = 0; k < band.size(); ++k)
      if (mask[k]) ++nodata;
      else lowest = std::min(lowest, band.heights[k]);
  }
  if (nodata == size_t(header_.width) * size_t(header_.height))
    throw Error(header_.source, "every grid point is nodata (nothing to build a terrain from)");
  m.lowest = lowest;
  m.nodata = nodata;
  m.scanned = true;
}

size_t DemReader::nodataCount() const {
  scan();
  return impl_->nodata;
}

Heightfield DemReader::read(int i0, int j0, int w, int h) const {
  if (i0 < 0 || j0 < 0 || w < 1 || h < 1 || i0 + w > header_.width || j0 + h > header_.height)
    throw Error(header_.source, "window " + std::to_string(w) + "x" + std::to_string(h) + " at (" +
                                    std::to_string(i0) + ", " + std::to_string(j0) + ") lies outside the " +
                                    std::to_string(header_.width) + "x" + std::to_string(header_.height) + " raster");
  capSize(uint64_t(w) * uint64_t(h), options_.max_grid_points, header_.source,
          "window of " + std::to_string(w) + "x" + std::to_string(h) + " grid points:");
  std::vector<uint8_t> mask;
  Heightfield hf = readRaw(i0, j0, w, h, mask);
  const bool whole = i0 == 0 && j0 == 0 && w == header_.width && h == header_.height;
  if (whole || std::find(mask.begin(), mask.end(), uint8_t(1)) == mask.end()) {
    fillNodata(hf, mask);  // the whole raster: its own lowest height; no nodata: nothing to fill
    return hf;
  }
  // Fill from a margin wide enough that the window's points fill as in the whole raster (fillNodata), with the
  // whole raster's lowest height beyond the fill's reach.
  scan();
  const int margin = 3 * kNodataFillRings;
  const int a0 = std::max(0, i0 - margin), b0 = std::max(0, j0 - margin);
  const int a1 = std::min(header_.width, i0 + w + margin), b1 = std::min(header_.height, j0 + h + margin);
  Heightfield region = readRaw(a0, b0, a1 - a0, b1 - b0, mask);
  fillNodata(region, mask, impl_->lowest);
  Heightfield out = region.crop(i0 - a0, j0 - b0, w, h);
  out.notes = header_.notes;
  return out;
}

void writeDem(const Heightfield& hf, const std::string& path) {
  registerGdalOnce();
  QuietGdalErrors quiet;
  GDALDriverH driver = GDALGetDriverByName("GTiff");
  if (!driver) throw Error(path, "GDAL has no GeoTIFF driver");
  char** create = nullptr;
  create = CSLSetNameValue(create, "BIGTIFF", "IF_SAFER");
  create = CSLSetNameValue(create, "TILED", "YES");
  DatasetCloser ds;
  ds.handle = GDALCreate(driver, path.c_str(), hf.width, hf.height, 1, GDT_Float32, create);
  CSLDestroy(create);
  if (!ds.handle) throw Error(path, "cannot create the GeoTIFF" + QuietGdalErrors::last());
  // Grid point (0, 0) is the south-west point's centre: the raster's top-left corner lies half a cell beyond the
  // north-west point.
  double gt[6] = {hf.geo_origin.x - 0.5 * hf.cell_x, hf.cell_x, 0.0,
                  hf.geo_origin.y + (hf.height - 0.5) * hf.cell_y, 0.0, -hf.cell_y};
  GDALSetGeoTransform(ds.handle, gt);
  if (!hf.crs.empty()) GDALSetProjection(ds.handle, hf.crs.c_str());
  GDALRasterBandH band = GDALGetRasterBand(ds.handle, 1);
  for (int r = 0; r < hf.height; ++r) {
    const float* row = hf.heights.data() + hf.index(0, hf.height - 1 - r);
    if (GDALRasterIO(band, GF_Write, 0, r, hf.width, 1, const_cast<float*>(row), hf.width, 1, GDT_Float32, 0, 0) !=
        CE_None)
      throw Error(path, "cannot write row " + std::to_string(r) + QuietGdalErrors::last());
  }
  GDALClose(ds.handle);
  ds.handle = nullptr;
  if (CPLGetLastErrorType() == CE_Failure) throw Error(path, "writing the GeoTIFF failed" + QuietGdalErrors::last());
}

Heightfield loadDem(const std::string& path, const DemLoadOptions& options) {
  const DemReader reader(path, options);
  const Heightfield& h = reader.header();
  capSize(uint64_t(h.width) * uint64_t(h.height), options.max_grid_points, path,
          "raster of " + std::to_string(h.width) + "x" + std::to_string(h.height) + " grid points:");
  return reader.read(0, 0, h.width, h.height);
}

}  // namespace farfield::terrain
