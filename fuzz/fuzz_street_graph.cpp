// Street graphs (urban/street_graph.h: the city.streets.json next to a city, and the copy in an impostor store).
#include <nlohmann/json.hpp>

#include "farfield/urban/street_graph.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const std::string path = fuzz::writeInput("city.streets.json", data, size);
  fuzz::expectFarfieldErrors([&] {
    const urban::StreetGraph g = urban::StreetGraph::load(path);
    // The graph's derived parts as a reader sees them: written back, it loads again.
    const urban::StreetGraph again = urban::StreetGraph::fromJson(g.toJson(), path + " (written back)");
    (void)again;
  });
  return 0;
}
