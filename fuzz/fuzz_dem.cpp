// DEMs (terrain/dem_io.h through GDAL, and terrain/terrain_data.h: what `farfield terrain info` does with one). The
// first byte of the input chooses the file's extension (GeoTIFF, 16-bit PNG, netCDF, Esri ASCII grid, SRTM HGT),
// whether the LOD is built too, and load options; the rest is the file. Grids are capped at 2^18 points here (the
// reader's default cap is 2^28, more memory than a fuzzer's 2 GB allows), so the cap itself is fuzzed.
#include <array>
#include <string_view>

#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/terrain_data.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  if (size < 1) return 0;
  static constexpr std::array<const char*, 5> kExtensions = {".tif", ".png", ".nc", ".asc", ".hgt"};
  const uint8_t mode = data[0];
  // Known finding, not Farfield's code: libnetcdf allocates what a netCDF header claims (4 to 13 GB seen) inside
  // GDALOpen, and AddressSanitizer then fills the freed blocks for tens of seconds (fuzz/findings/README.md). netCDF
  // and HDF5 content is left out so the fuzzer explores the rest (tests/terrain reads a netCDF DEM).
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (bytes.substr(0, 3) == "CDF" || bytes.substr(0, 4) == "\x89HDF") return 0;
  const std::string path = fuzz::writeInput(std::string("dem") + kExtensions[mode % kExtensions.size()], data + 1,
                                            size - 1);
  terrain::TerrainLoadOptions options;
  options.block = 16;
  options.dem.max_grid_points = uint64_t(1) << 18;
  if (mode & 0x08) options.dem.band = 2;
  if (mode & 0x10) options.dem.cell_size = 2.5;
  if (mode & 0x20) options.dem.height_scale = 0.3048;
  fuzz::expectFarfieldErrors([&] {
    if (mode & 0x80) {
      const auto t = terrain::TerrainData::load(path, options);
      (void)t->describe();
    } else {
      const terrain::Heightfield hf = terrain::loadDem(path, options.dem);
      (void)hf;
    }
  });
  return 0;
}
