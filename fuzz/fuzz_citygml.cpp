// CityGML 1.0 / 2.0 (geodata/citygml_import.h through libcitygml), read from memory with importCityGmlText: the
// whole input is the document (texture files it names are looked for in the scratch directory, where there are
// none). The input's length chooses between one object per block and one per building where the file has streets.
#include "farfield/geodata/citygml_import.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const std::string text(reinterpret_cast<const char*>(data), size);
  geodata::CityGmlImportOptions options;
  if (size % 2) options.objects = gen::ObjectGrouping::Buildings;
  fuzz::expectFarfieldErrors([&] {
    const geodata::CityGmlScene s =
        geodata::importCityGmlText(text, "fuzz.gml", fuzz::scratch().string(), options);
    (void)s;
  });
  return 0;
}
