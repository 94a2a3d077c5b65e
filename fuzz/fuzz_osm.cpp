// OpenStreetMap files (geodata/osm_reader.h, geodata/osm_import.h): the first byte of the input chooses the format
// (PBF or XML), whether the whole import runs (projection, extrusion, the street graph and blocks: `farfield import
// osm`) or only the reader, and a bounding box; the rest is the file.
#include "farfield/geodata/osm_import.h"
#include "farfield/geodata/osm_reader.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  if (size < 1) return 0;
  const uint8_t mode = data[0];
  const std::string path = fuzz::writeInput((mode & 1) ? "map.osm" : "map.osm.pbf", data + 1, size - 1);
  geodata::OsmImportOptions options;
  if (mode & 4) options.read.bbox = geodata::LonLatBox{7.40, 43.72, 7.44, 43.75};  // part of the seeds' area
  if (mode & 8) options.read.include_tunnels = true;
  if (mode & 16) options.objects = gen::ObjectGrouping::Buildings;
  fuzz::expectFarfieldErrors([&] {
    if (mode & 2) {
      const geodata::OsmCity city = geodata::importOsm(path, options);
      (void)city;
    } else {
      const geodata::OsmData osm = geodata::readOsm(path, options.read);
      (void)osm;
    }
  });
  return 0;
}
