// CityJSON 1.0 / 1.1 / 2.0 (geodata/cityjson_import.h). The last byte of the input chooses the import options (LoD
// limit, ground and other objects); the whole input is the file (a JSON parser ignores nothing after the document,
// so a trailing option byte is itself part of what is fuzzed).
#include "farfield/geodata/cityjson_import.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const std::string path = fuzz::writeInput("city.city.json", data, size);
  geodata::CityJsonImportOptions options;
  const uint8_t o = size > 0 ? data[size - 1] : 0;
  if (o & 1) options.max_lod = double((o >> 1) & 3);
  options.ground_objects = (o & 8) == 0;
  options.other_objects = (o & 16) == 0;
  fuzz::expectFarfieldErrors([&] {
    const geodata::CityJsonScene s = geodata::importCityJson(path, options);
    (void)s;
  });
  return 0;
}
