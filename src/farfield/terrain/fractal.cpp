#include "farfield/terrain/fractal.h"

#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::terrain {
namespace {

// SplitMix64: tiny, seedable and identical everywhere (std::uniform_real_distribution is not).
struct Random {
  uint64_t state;
  explicit Random(uint64_t seed) : state(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
  double symmetric() { return uniform() * 2.0 - 1.0; }                               // [-1, 1)
};

}  // namespace

Heightfield fractalTerrain(const FractalOptions& o) {
  const int n = o.size - 1;
  if (o.size < 3 || o.size > 16385 || (n & (n - 1)) != 0)
    throw Error("fractal terrain", "size " + std::to_string(o.size) + " is not 2^n + 1 (3, 5, 9, ..., 16385)");
  if (!(o.cell_size > 0.0) || !(o.relief > 0.0) || !(o.roughness > 0.0 && o.roughness < 1.0) ||
      !(o.ridge_bias >= 0.0 && o.ridge_bias <= 1.0))
    throw Error("fractal terrain", "need cell size > 0, relief > 0, 0 < roughness < 1, 0 <= ridge bias <= 1");

  Heightfield hf(o.size, o.size, o.cell_size);
  hf.source = "fractal " + std::to_string(o.size) + "x" + std::to_string(o.size) + " seed " + std::to_string(o.seed);
  Random rng(o.seed);
  std::vector<double> z(hf.size(), 0.0);
  auto at = [&](int i, int j) -> double& { return z[size_t(i) + size_t(j) * size_t(o.size)]; };

  double amplitude = 1.0;
  int level = 0;
  for (int step = n; step > 1; step /= 2, ++level) {
    const int half = step / 2;
    const double a = level >= o.octave_start ? amplitude : 0.0;
    // Diamond step: centres of squares from their four corners.
    for (int j = half; j < o.size; j += step)
      for (int i = half; i < o.size; i += step)
        at(i, j) = 0.25 * (at(i - half, j - half) + at(i + half, j - half) + at(i - half, j + half) +
                           at(i + half, j + half)) +
                   a * rng.symmetric();
    // Square step: edge midpoints from their (up to four) diamond neighbours.
    for (int j = 0; j < o.size; j += half)
      for (int i = ((j / half) % 2 == 0) ? half : 0; i < o.size; i += step) {
        double sum = 0.0;
        int count = 0;
        if (i - half >= 0) sum += at(i - half, j), ++count;
        if (i + half < o.size) sum += at(i + half, j), ++count;
        if (j - half >= 0) sum += at(i, j - half), ++count;
        if (j + half < o.size) sum += at(i, j + half), ++count;
        at(i, j) = sum / count + a * rng.symmetric();
      }
    amplitude *= o.roughness;
  }

  // A ridge across the map (a random direction through the middle third) makes a mountain range between plains,
  // the kind of terrain the LOD-sprite flythrough crosses.
  const double angle = rng.uniform() * kPi;
  const DVec2 dir(std::cos(angle), std::sin(angle));
  const DVec2 centre(n * (0.4 + 0.2 * rng.uniform()), n * (0.4 + 0.2 * rng.uniform()));
  double lo = 1e300, hi = -1e300;
  for (int j = 0; j < o.size; ++j)
    for (int i = 0; i < o.size; ++i) {
      const DVec2 p(i, j);
      const double across = std::abs(cross2(dir, p - centre)) / n;  // distance from the ridge line, in map sizes
      const double ridge = std::exp(-across * across / (2.0 * 0.12 * 0.12));
      // Plains: the fractal is flattened away from the ridge.
      double v = at(i, j) * (0.35 + 0.65 * ridge) + o.ridge_bias * 1.5 * ridge;
      at(i, j) = v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  const double span = hi > lo ? hi - lo : 1.0;
  for (size_t k = 0; k < hf.size(); ++k) hf.heights[k] = float(o.base + (z[k] - lo) / span * o.relief);
  return hf;
}

}  // namespace farfield::terrain
