// The terrain's original texture (terrain_texture.h) per page: what a paged terrain's loading thread spends most of
// a page on (a 1,027^2-point part with its margin, about 60 % of the 90 ms a page took on the 16,385^2 flight,
// `perf` of `farfield terrain tiles --render --lod-sprite`), and what a frame waits for where a page is read at
// once. Fractal parts of the relief a 1,025-point tile of the 16,385^2 terrain has (400 m) and of a steep one
// (1,500 m: most slopes past the rock threshold). Counter: texels per second.
#include <benchmark/benchmark.h>

#include <map>

#include "farfield/terrain/fractal.h"
#include "farfield/terrain/terrain_texture.h"

namespace {

using namespace farfield;

// One fractal part per relief (metres), made once.
const terrain::Heightfield& part(int relief) {
  static std::map<int, terrain::Heightfield> parts;
  auto [it, made] = parts.try_emplace(relief);
  if (made) {
    terrain::FractalOptions f;
    f.size = 1025;
    f.seed = 7;
    f.cell_size = 30.0;
    f.relief = double(relief);
    f.roughness = 0.6;
    it->second = terrain::fractalTerrain(f);
  }
  return it->second;
}

void BM_TerrainTexture(benchmark::State& state) {
  const terrain::Heightfield& hf = part(int(state.range(0)));
  terrain::TextureOptions o;
  o.ramp_lo = 0.0f;
  o.ramp_hi = 3000.0f;
  for (auto _ : state) benchmark::DoNotOptimize(terrain::terrainTexture(hf, o));
  const double texels = double(hf.width) * double(hf.height);
  state.counters["texels/s"] = benchmark::Counter(texels * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TerrainTexture)->Arg(400)->Arg(1500)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
