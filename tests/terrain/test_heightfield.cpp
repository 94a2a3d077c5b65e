// Heightfields: DEM loading through GDAL (checked against GDAL's own raw read), nodata filling, bad files, the
// fractal generator and cropping.
#include <gtest/gtest.h>

#include <cpl_conv.h>
#include <gdal.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/heightfield.h"
#include "farfield/terrain/terrain_data.h"
#include "support/test_support.h"
#include "terrain/test_raster.h"

namespace farfield::terrain {
namespace {

using test::writeRaster;

TEST(Dem, BigTujungaLoadsWithSizeRangeAndNodataOfTheFile) {
  FF_SHARED_FILE_OR_SKIP(tif, "terrain/bigtujunga_srtm30m_utm11.tif");
  const std::string path = tif.string();
  const Heightfield hf = loadDem(path);
  EXPECT_EQ(hf.width, 1197);
  EXPECT_EQ(hf.height, 643);
  EXPECT_NEAR(hf.cell_x, 30.0, 0.5);
  EXPECT_NEAR(hf.cell_y, 30.0, 0.5);

  // Independent: GDAL's raw 16-bit read of the same file (row 0 = north), nodata value 32767.
  GDALAllRegister();
  GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
  ASSERT_NE(ds, nullptr);
  const int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
  ASSERT_EQ(w, 1197);
  ASSERT_EQ(h, 643);
  int has_nodata = 0;
  EXPECT_EQ(GDALGetRasterNoDataValue(GDALGetRasterBand(ds, 1), &has_nodata), 32767.0);
  EXPECT_TRUE(has_nodata);
  std::vector<int16_t> raw(size_t(w) * size_t(h));
  ASSERT_EQ(GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, w, h, raw.data(), w, h, GDT_Int16, 0, 0), CE_None);
  GDALClose(ds);
  size_t nodata = 0;
  int lo = 1 << 30, hi = -(1 << 30);
  size_t mismatched = 0;
  for (int r = 0; r < h; ++r)
    for (int i = 0; i < w; ++i) {
      const int v = raw[size_t(r) * size_t(w) + size_t(i)];
      const int j = h - 1 - r;  // our row 0 is the south edge
      if (v == 32767) {
        ++nodata;
        if (!hf.nodata[hf.index(i, j)]) ++mismatched;
        continue;
      }
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      if (hf.nodata[hf.index(i, j)] || hf.at(i, j) != float(v)) ++mismatched;
    }
  EXPECT_EQ(mismatched, 0u);
  // The file declares nodata 32767; the count is whatever the raw read finds (this SRTM tile has no voids).
  EXPECT_EQ(hf.nodata_count, nodata);
  EXPECT_EQ(lo, 315);
  EXPECT_EQ(hi, 2295);
  // Filled heights stay inside the range of the data they were filled from.
  EXPECT_GE(hf.minHeight(), 315.0f);
  EXPECT_LE(hf.maxHeight(), 2295.0f);
}

TEST(Dem, MissingFileIsAClearError) {
  try {
    loadDem("/nonexistent/dem.tif");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dem.tif"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

TEST(Dem, WrongFormatIsAClearError) {
  const auto dir = farfield::test::scratchDir("terrain_wrong_format");
  const std::string path = (dir / "not_a_dem.tif").string();
  std::ofstream(path) << "this is not a raster\n";
  try {
    loadDem(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not a raster"), std::string::npos) << e.what();
  }
}

TEST(Dem, AllNodataIsAClearError) {
  const auto dir = farfield::test::scratchDir("terrain_all_nodata");
  const std::string path = (dir / "empty.tif").string();
  const double nodata = -9999.0;
  const double gt[6] = {1000.0, 10.0, 0.0, 2000.0, 0.0, -10.0};
  writeRaster(path, "GTiff", GDT_Float32, 8, 6, std::vector<double>(48, nodata), &nodata, gt);
  try {
    loadDem(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("nodata"), std::string::npos) << e.what();
  }
}

TEST(Dem, GeoTiffCellSizeOrientationAndNodataFill) {
  const auto dir = farfield::test::scratchDir("terrain_small_tif");
  const std::string path = (dir / "small.tif").string();
  const int w = 5, h = 4;
  std::vector<double> values(size_t(w * h));
  for (int r = 0; r < h; ++r)
    for (int i = 0; i < w; ++i) values[size_t(r * w + i)] = 100.0 * r + i;  // row 0 (north) = 0..4
  const double nodata = -1.0;
  values[size_t(2 * w + 2)] = nodata;  // one hole at raster row 2, column 2
  const double gt[6] = {500000.0, 25.0, 0.0, 4000000.0, 0.0, -25.0};
  writeRaster(path, "GTiff", GDT_Float32, w, h, values, &nodata, gt);
  const Heightfield hf = loadDem(path);
  ASSERT_EQ(hf.width, w);
  ASSERT_EQ(hf.height, h);
  EXPECT_DOUBLE_EQ(hf.cell_x, 25.0);
  EXPECT_DOUBLE_EQ(hf.cell_y, 25.0);
  // Our row 0 is the south edge = raster row h - 1.
  EXPECT_FLOAT_EQ(hf.at(0, 0), 300.0f);
  EXPECT_FLOAT_EQ(hf.at(4, 3), 4.0f);
  // South-west grid point centre: x = 500000 + 12.5, y = 4000000 - 4 * 25 + 12.5.
  EXPECT_DOUBLE_EQ(hf.geo_origin.x, 500012.5);
  EXPECT_DOUBLE_EQ(hf.geo_origin.y, 3999912.5);
  EXPECT_EQ(hf.nodata_count, 1u);
  // The hole (raster row 2 -> our row 1) is filled with the mean of its 8 neighbours (a plane: exact).
  EXPECT_TRUE(hf.nodata[hf.index(2, 1)]);
  EXPECT_NEAR(hf.at(2, 1), 202.0f, 1e-3f);
}

TEST(Dem, SixteenBitPngWithoutGeoreferencing) {
  const auto dir = farfield::test::scratchDir("terrain_png16");
  const std::string path = (dir / "dem16.png").string();
  const int w = 6, h = 3;
  std::vector<double> values(size_t(w * h));
  for (int k = 0; k < w * h; ++k) values[size_t(k)] = 1000.0 + 2000.0 * k;  // needs 16 bits
  writeRaster(path, "PNG", GDT_UInt16, w, h, values, nullptr, nullptr);
  const Heightfield hf = loadDem(path);
  ASSERT_EQ(hf.width, w);
  ASSERT_EQ(hf.height, h);
  EXPECT_DOUBLE_EQ(hf.cell_x, 1.0);
  ASSERT_FALSE(hf.notes.empty());
  EXPECT_NE(hf.notes[0].find("no georeferencing"), std::string::npos);
  EXPECT_FLOAT_EQ(hf.at(0, h - 1), 1000.0f);               // raster row 0, column 0
  EXPECT_FLOAT_EQ(hf.at(5, 0), float(1000.0 + 2000.0 * 17));  // raster row 2, column 5
  DemLoadOptions o;
  o.cell_size = 30.0;
  EXPECT_DOUBLE_EQ(loadDem(path, o).cell_x, 30.0);
}

TEST(Dem, NetCdfLoads) {
  GDALAllRegister();
  if (!GDALGetDriverByName("netCDF")) GTEST_SKIP() << "GDAL built without netCDF";
  const auto dir = farfield::test::scratchDir("terrain_netcdf");
  const std::string path = (dir / "dem.nc").string();
  const int w = 4, h = 3;
  std::vector<double> values(size_t(w * h));
  for (int k = 0; k < w * h; ++k) values[size_t(k)] = 50.0 * k;
  const double gt[6] = {0.0, 90.0, 0.0, 270.0, 0.0, -90.0};
  writeRaster(path, "netCDF", GDT_Float32, w, h, values, nullptr, gt);
  const Heightfield hf = loadDem(path);
  ASSERT_EQ(hf.width, w);
  ASSERT_EQ(hf.height, h);
  EXPECT_NEAR(hf.cell_x, 90.0, 1e-9);
  // Same orientation rule as GeoTIFF: north row last.
  EXPECT_FLOAT_EQ(hf.at(0, h - 1), 0.0f);
  EXPECT_FLOAT_EQ(hf.at(3, 0), 550.0f);
}

// A header may claim any size: an ASCII grid of 100000 x 100000 points holding eight values was read into a raster
// of 10^10 doubles (std::bad_alloc, "internal error"). The size is refused from the header.
TEST(Dem, AbsurdHeaderSizeIsAClearError) {
  const std::string path = (farfield::test::testDataDir() / "terrain" / "fuzz" / "huge_header.asc").string();
  try {
    loadDem(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("100000x100000"), std::string::npos) << msg;
    EXPECT_NE(msg.find("exceeds the limit of 268435456"), std::string::npos) << msg;
  }
  // The limit is an option: a real file over a lower limit is refused the same way.
  const auto dir = farfield::test::scratchDir("terrain_cap");
  const std::string small = (dir / "small.tif").string();
  writeRaster(small, "GTiff", GDT_Float32, 8, 6, std::vector<double>(48, 5.0), nullptr, nullptr);
  DemLoadOptions o;
  o.max_grid_points = 47;
  EXPECT_THROW(loadDem(small, o), Error);
  o.max_grid_points = 48;
  EXPECT_EQ(loadDem(small, o).size(), 48u);
}

// A geographic raster whose centre lies past a pole gave a negative cell size (cos of the latitude), and a cell size
// option of infinity was taken as given: both are refused.
TEST(Dem, UnusableCellSizesAreClearErrors) {
  GDALAllRegister();
  const auto dir = farfield::test::scratchDir("terrain_bad_cells");
  const std::string path = (dir / "past_the_pole.tif").string();
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 8, 6, 1, GDT_Float32, nullptr);
  ASSERT_NE(ds, nullptr);
  double gt[6] = {7.0, 0.001, 0.0, 100.0, 0.0, -0.001};
  GDALSetGeoTransform(ds, gt);
  GDALSetProjection(ds, "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],"
                        "PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]]");
  std::vector<float> v(48, 3.0f);
  ASSERT_EQ(GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Write, 0, 0, 8, 6, v.data(), 8, 6, GDT_Float32, 0, 0),
            CE_None);
  GDALClose(ds);
  try {
    loadDem(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("expected positive finite sizes"), std::string::npos) << e.what();
  }
  DemLoadOptions o;
  o.cell_size = std::numeric_limits<double>::infinity();
  EXPECT_THROW(loadDem(path, o), Error);
  o.cell_size = 2.0;
  EXPECT_EQ(loadDem(path, o).cell_x, 2.0);
}

TEST(TerrainSpec, FractalSpecsAreWholeNumbersOnly) {
  const FractalOptions f = parseFractalSpec("fractal:33:18446744073709551615");
  EXPECT_EQ(f.size, 33);
  EXPECT_EQ(f.seed, 18446744073709551615ull);
  EXPECT_EQ(parseFractalSpec("fractal:65").seed, FractalOptions{}.seed);
  // sscanf("%d") read 99999999999 as some int (undefined), "33x" as 33 and "-1" as seed 2^64 - 1.
  for (const char* bad : {"fractal:99999999999", "fractal:33x", "fractal:33:-1", "fractal:-33", "fractal: 33",
                          "fractal:33:1:2", "fractal:", "fractal:33:18446744073709551616", "fractal:1e3"}) {
    try {
      parseFractalSpec(bad);
      ADD_FAILURE() << bad << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(std::string(bad) + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_THROW(TerrainData::load("fractal:99999999999"), Error);
  EXPECT_EQ(TerrainData::load("fractal:33:7")->source.width, 33);
}

TEST(TerrainSpec, FractalSpecsTakeReliefRoughnessAndCell) {
  const FractalOptions f = parseFractalSpec("fractal:8193:23:relief=3000:roughness=0.75:cell=10");
  EXPECT_EQ(f.size, 8193);
  EXPECT_EQ(f.seed, 23u);
  EXPECT_EQ(f.relief, 3000.0);
  EXPECT_EQ(f.roughness, 0.75);
  EXPECT_EQ(f.cell_size, 10.0);
  EXPECT_EQ(parseFractalSpec("fractal:65:1:relief=10").roughness, FractalOptions{}.roughness);
  for (const char* bad : {"fractal:33:1:relief", "fractal:33:1:relief=", "fractal:33:1:relief=-5",
                          "fractal:33:1:relief=1e999", "fractal:33:1:relief=5x", "fractal:33:1:height=5",
                          "fractal:33:1:cell=0", "fractal:33:relief=5"}) {
    try {
      parseFractalSpec(bad);
      ADD_FAILURE() << bad << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(std::string(bad) + ": ", 0), 0u) << e.what();
    }
  }
  const auto data = TerrainData::load("fractal:33:7:relief=100:cell=5");
  EXPECT_EQ(data->source.cell_x, 5.0);
  EXPECT_NEAR(data->source.maxHeight() - data->source.minHeight(), 100.0, 1e-3);
}

TEST(Heightfield, FillNodataFillsHolesAndCounts) {
  Heightfield hf(9, 7, 1.0);
  hf.source = "plane";
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 9; ++i) hf.at(i, j) = float(2 * i + 3 * j);
  std::vector<uint8_t> mask(hf.size(), 0);
  // A 3x3 hole: filled rim-inwards from means of known neighbours; on a plane every such mean is bounded by the
  // plane's values around the hole.
  for (int j = 2; j <= 4; ++j)
    for (int i = 3; i <= 5; ++i) mask[hf.index(i, j)] = 1, hf.at(i, j) = -1000.0f;
  fillNodata(hf, mask);
  EXPECT_EQ(hf.nodata_count, 9u);
  for (int j = 2; j <= 4; ++j)
    for (int i = 3; i <= 5; ++i) {
      EXPECT_GE(hf.at(i, j), float(2 * 2 + 3 * 1));
      EXPECT_LE(hf.at(i, j), float(2 * 6 + 3 * 5));
    }
  // The centre is the mean of its 8 rim neighbours, each the mean of known points around it; symmetric, so the
  // plane's value at the centre.
  EXPECT_NEAR(hf.at(4, 3), float(2 * 4 + 3 * 3), 1e-4f);
  std::vector<uint8_t> all(hf.size(), 1);
  EXPECT_THROW(fillNodata(hf, all), Error);
}

TEST(Fractal, SizeRangeAndDeterminism) {
  FractalOptions o;
  o.size = 65;
  o.seed = 3;
  const Heightfield a = fractalTerrain(o);
  const Heightfield b = fractalTerrain(o);
  o.seed = 4;
  const Heightfield c = fractalTerrain(o);
  EXPECT_EQ(a.width, 65);
  EXPECT_EQ(a.heights, b.heights);
  EXPECT_NE(a.heights, c.heights);
  EXPECT_NEAR(a.minHeight(), 200.0f, 1e-3f);
  EXPECT_NEAR(a.maxHeight(), 1700.0f, 1e-2f);
  o.size = 64;
  EXPECT_THROW(fractalTerrain(o), Error);
  o.size = 2;
  EXPECT_THROW(fractalTerrain(o), Error);
}

TEST(Heightfield, CropForBlocksIsCentredAndWhole) {
  Heightfield hf(1197, 643, 30.0);
  for (size_t k = 0; k < hf.size(); ++k) hf.heights[k] = float(k);
  const Heightfield c = cropForBlocks(hf, 128);
  EXPECT_EQ(c.width, 9 * 128 + 1);
  EXPECT_EQ(c.height, 5 * 128 + 1);
  const int i0 = (1197 - c.width) / 2, j0 = (643 - c.height) / 2;
  EXPECT_EQ(c.at(0, 0), hf.at(i0, j0));
  EXPECT_EQ(c.at(c.width - 1, c.height - 1), hf.at(i0 + c.width - 1, j0 + c.height - 1));
  EXPECT_DOUBLE_EQ(c.geo_origin.x, i0 * 30.0);
  EXPECT_THROW(cropForBlocks(Heightfield(100, 100), 128), Error);
}

}  // namespace
}  // namespace farfield::terrain
