// Rasters written with GDAL for the terrain tests (DEM loading, reading by windows, tile caches from a raster).
#pragma once

#include <gdal.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace farfield::terrain::test {

// Writes a single-band raster with GDAL: `driver` through an in-memory copy (PNG and netCDF only support copies).
inline void writeRaster(const std::string& path, const char* driver, GDALDataType type, int w, int h,
                        const std::vector<double>& values, const double* nodata, const double* geotransform) {
  GDALAllRegister();
  GDALDriverH mem = GDALGetDriverByName("MEM");
  ASSERT_NE(mem, nullptr);
  GDALDatasetH ds = GDALCreate(mem, "", w, h, 1, type, nullptr);
  ASSERT_NE(ds, nullptr);
  if (geotransform) GDALSetGeoTransform(ds, const_cast<double*>(geotransform));
  GDALRasterBandH band = GDALGetRasterBand(ds, 1);
  if (nodata) GDALSetRasterNoDataValue(band, *nodata);
  std::vector<double> copy = values;
  ASSERT_EQ(GDALRasterIO(band, GF_Write, 0, 0, w, h, copy.data(), w, h, GDT_Float64, 0, 0), CE_None);
  GDALDriverH out = GDALGetDriverByName(driver);
  ASSERT_NE(out, nullptr) << driver;
  GDALDatasetH written = GDALCreateCopy(out, path.c_str(), ds, FALSE, nullptr, nullptr, nullptr);
  ASSERT_NE(written, nullptr) << path;
  GDALClose(written);
  GDALClose(ds);
}

}  // namespace farfield::terrain::test
