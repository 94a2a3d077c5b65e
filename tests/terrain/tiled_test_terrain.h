// A small fractal written as a tile cache, and cameras over it, for the tiled-terrain tests.
#pragma once

#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/tile_cache.h"
#include "support/test_support.h"

namespace farfield::terrain::test {

// 257 x 257 points, 20 m cells, block 16, tiles of 4 x 4 blocks: 4 x 4 tiles.
inline Heightfield tiledTestFractal(uint64_t seed = 5) {
  FractalOptions o;
  o.size = 257;
  o.seed = seed;
  o.cell_size = 20.0;
  o.relief = 800.0;
  o.roughness = 0.5;
  return fractalTerrain(o);
}

inline std::string writeTestCache(const Heightfield& hf, const std::string& name, int block = 16,
                                  int tile_blocks = 4) {
  const std::string path = (farfield::test::scratchDir(name) / "terrain.tiles").string();
  TileCache::write(hf, block, tile_blocks, path);
  return path;
}

inline Camera tiledTestCamera(Vec3 eye, Vec3 at) {
  Camera c;
  c.eye = eye;
  c.at = at;
  c.up = Vec3(0, 0, 1);
  c.width = c.height = 256;
  c.fov_y = float(degToRad(60.0));
  c.near_plane = 1.0f;
  c.far_plane = 100000.0f;
  return c;
}

// Low over one corner looking across, high overhead, from outside the map, a grazing view along an edge, and two
// from far away (where far tiles are read at coarse steps).
inline std::vector<Camera> tiledTestCameras(const Heightfield& hf) {
  const float ex = float(hf.extentX()), ey = float(hf.extentY()), top = hf.maxHeight();
  return {tiledTestCamera(Vec3(0.1f * ex, 0.1f * ey, top + 30.0f), Vec3(0.9f * ex, 0.8f * ey, 0.0f)),
          tiledTestCamera(Vec3(0.5f * ex, 0.45f * ey, top + 2500.0f), Vec3(0.5f * ex, 0.5f * ey, 0.0f)),
          tiledTestCamera(Vec3(-0.6f * ex, 0.3f * ey, top + 400.0f), Vec3(0.5f * ex, 0.5f * ey, 0.0f)),
          tiledTestCamera(Vec3(0.5f * ex, 0.02f * ey, top + 10.0f), Vec3(0.55f * ex, 0.98f * ey, top - 200.0f)),
          tiledTestCamera(Vec3(-4.0f * ex, 0.4f * ey, top + 3000.0f), Vec3(0.5f * ex, 0.5f * ey, 0.0f)),
          tiledTestCamera(Vec3(1.2f * ex, 3.0f * ey, top + 6000.0f), Vec3(0.5f * ex, 0.5f * ey, 0.0f))};
}

}  // namespace farfield::terrain::test
