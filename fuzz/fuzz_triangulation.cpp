// The impostor triangulation (impostor/triangulation.h): contour loops, discrepancy polylines and grid points as a
// depth mesh gives them (half-pixel coordinates in a 512-pixel image, constraints that cross, overlap and double
// back), triangulated by CGAL. The bytes are read as 16-bit coordinates in half pixels: one byte says how many
// loops and polylines follow, each with a byte of point count. A crash here is one a bake would meet.
#include <cstdint>
#include <vector>

#include "farfield/impostor/triangulation.h"
#include "fuzz_support.h"

namespace {

struct Reader {
  const uint8_t* data;
  size_t size;
  size_t at = 0;
  bool more() const { return at < size; }
  uint8_t byte() { return at < size ? data[at++] : 0; }
  double coordinate() {
    const uint16_t v = uint16_t(byte() | (uint16_t(byte()) << 8));
    return double(v % 1025) * 0.5;  // 0 .. 512 in half pixels
  }
  std::vector<farfield::DVec2> points(size_t n) {
    std::vector<farfield::DVec2> out;
    for (size_t i = 0; i < n && more(); ++i) {
      const double x = coordinate();
      out.push_back({x, coordinate()});
    }
    return out;
  }
};

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  Reader in{data, size};
  impostor::TriangulationInput input;
  const uint8_t counts = in.byte();
  for (int k = 0; k < (counts & 3) && in.more(); ++k) {
    auto loop = in.points(size_t(3 + in.byte() % 62));
    if (loop.size() >= 3) input.loops.push_back(std::move(loop));
  }
  for (int k = 0; k < (counts >> 2) && in.more(); ++k) input.polylines.push_back(in.points(size_t(1 + in.byte() % 16)));
  input.points = in.points(size_t(in.byte()));
  fuzz::expectFarfieldErrors([&] { impostor::triangulate(input); });
  return 0;
}
