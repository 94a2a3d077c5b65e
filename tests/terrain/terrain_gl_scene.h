// A small terrain on the GPU for the LOD-sprite tests: its LOD, texture and renderer, and cameras over it.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_cost.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain::test {

inline const Vec4 kSky(0.62f, 0.74f, 0.88f, 1.0f);

struct Scene {
  Heightfield hf;
  std::unique_ptr<QuadtreeLod> lod;
  image::ColorImage texture;
  std::unique_ptr<gpu::TerrainRenderer> renderer;

  explicit Scene(Heightfield h) : hf(std::move(h)) {
    gpu::sharedHeadlessContext().makeCurrent();
    lod = std::make_unique<QuadtreeLod>(hf);
    texture = terrainTexture(hf);
    Vec2 scale, offset;
    texCoordTransform(hf, scale, offset);
    renderer = std::make_unique<gpu::TerrainRenderer>(lod->positions(), texture, scale, offset);
  }
  image::ColorImage renderLod(const Camera& camera, float pixel_error) {
    gpu::RenderTarget target(camera.width, camera.height);
    target.clear(kSky);
    LodMesh mesh;
    renderLodFrame(*lod, *renderer, camera, LodSettings{pixel_error, true, false}, target, mesh);
    return target.readColor();
  }
};

inline Camera makeCamera(Vec3 eye, Vec3 at, int size = 128) {
  Camera c;
  c.eye = eye;
  c.at = at;
  c.width = c.height = size;
  c.fov_y = float(degToRad(60.0));
  c.near_plane = 1.0f;
  c.far_plane = 50000.0f;
  return c;
}

// Motion over the test fractal: forwards and a little sideways, 40 m a frame.
inline std::vector<Camera> choicePath(const Heightfield& hf, int frames) {
  const float top = hf.maxHeight();
  std::vector<Camera> cameras;
  for (int f = 0; f < frames; ++f)
    cameras.push_back(makeCamera(Vec3(600.0f + 40.0f * f, 300.0f + 10.0f * f, top + 700.0f),
                                 Vec3(900.0f + 40.0f * f, 1600.0f + 10.0f * f, 0.0f)));
  return cameras;
}

// 129 x 129 points, 20 m cells, 500 m of relief.
inline Heightfield testFractal() {
  FractalOptions o;
  o.size = 129;
  o.seed = 9;
  o.cell_size = 20.0;
  o.relief = 500.0;
  return fractalTerrain(o);
}

// A cost model where CDLOD high frames (and keyframes) are expensive and sprite frames cheap: 50 against 0.25 ms.
inline TerrainCost spritesPay() {
  TerrainCost cost;
  cost.gpu_high = gpu::CostModel{};
  cost.gpu_high->base_ms = 50.0;
  cost.gpu_sprite = gpu::CostModel{};
  cost.gpu_sprite->base_ms = 0.25;
  return cost;
}

}  // namespace farfield::terrain::test
