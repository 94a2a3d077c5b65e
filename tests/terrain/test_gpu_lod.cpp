// The CDLOD terrain on the GPU (terrain/gpu_lod.h): its frame against the same surface drawn from the CPU
// reference of its vertex shader (CdlodTerrain::vertex) as a plain triangle list, and against the quadtree LOD's
// frame at the same bound and the full-resolution grid's. Needs a GL context (llvmpipe is enough).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/terrain/gpu_lod.h"
#include "terrain_gl_scene.h"

namespace farfield::terrain {
namespace {

using test::kSky;
using test::makeCamera;

image::ColorImage drawGpuLod(GpuLodTerrain& terrain, const Camera& camera, float tau, GpuLodFrame* out = nullptr) {
  gpu::RenderTarget target(camera.width, camera.height);
  target.clear(kSky);
  const GpuLodFrame frame = terrain.draw(camera, tau, target);
  if (out) *out = frame;
  return target.readColor();
}

// The selection's patches, their vertices computed on the CPU, drawn as one triangle list.
image::ColorImage drawCpuReference(const GpuLodTerrain& terrain, test::Scene& scene, const Camera& camera) {
  const CdlodTerrain& lod = terrain.lod();
  const CdlodSelection& sel = terrain.lastSelection();
  const int p = lod.patchCells();
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
  for (const CdlodNode& n : sel.nodes) {
    const uint32_t base = uint32_t(positions.size());
    for (int j = 0; j <= p; ++j)
      for (int i = 0; i <= p; ++i) positions.push_back(lod.vertex(n, i, j, sel.ranges, camera.eye));
    for (int j = 0; j < p; ++j)
      for (int i = 0; i < p; ++i) {
        const uint32_t c00 = base + uint32_t(i + j * (p + 1)), c10 = c00 + 1, c01 = c00 + uint32_t(p + 1),
                       c11 = c01 + 1;
        indices.insert(indices.end(), {c00, c10, c11, c00, c11, c01});
      }
  }
  Vec2 scale, offset;
  texCoordTransform(scene.hf, scale, offset);
  gpu::TerrainRenderer reference(positions, scene.texture, scale, offset);
  reference.setIndices(indices);
  gpu::RenderTarget target(camera.width, camera.height);
  target.clear(kSky);
  reference.drawTextured(camera, target, 0, indices.size() / 3);
  return target.readColor();
}

std::vector<Camera> views(const Heightfield& hf) {
  const float top = hf.maxHeight();
  return {makeCamera(Vec3(100, 150, top + 30), Vec3(2400, 2000, hf.minHeight()), 192),
          makeCamera(Vec3(1280, 1280, top + 1500), Vec3(1300, 1500, 0), 192),
          makeCamera(Vec3(2500, 300, hf.sample(2500, 300) + 15), Vec3(300, 2400, hf.minHeight()), 192)};
}

TEST(GpuLodGL, FrameEqualsTheCpuReferenceOfItsVertices) {
  test::Scene scene(test::testFractal());
  GpuLodTerrain terrain(scene.hf, scene.texture, CdlodOptions{8, 16, 0.3f});
  for (const Camera& camera : views(scene.hf))
    for (float tau : {1.0f, 4.0f}) {
      GpuLodFrame frame;
      const image::ColorImage gpu_frame = drawGpuLod(terrain, camera, tau, &frame);
      EXPECT_GT(frame.nodes, 0u);
      EXPECT_EQ(frame.draw.draw_calls, 1u);
      EXPECT_EQ(frame.draw.triangles, frame.nodes * 2 * 8 * 8);
      const image::ColorImage cpu_frame = drawCpuReference(terrain, scene, camera);
      EXPECT_GT(image::psnr(gpu_frame, cpu_frame), 50.0) << "eye " << camera.eye.x << " tau " << tau;
    }
}

TEST(GpuLodGL, CloseToTheQuadtreeLodAndTheFullGrid) {
  test::Scene scene(test::testFractal());
  GpuLodTerrain terrain(scene.hf, scene.texture, CdlodOptions{8, 16, 0.3f});
  for (const Camera& camera : views(scene.hf)) {
    const image::ColorImage cdlod = drawGpuLod(terrain, camera, 1.0f);
    const image::ColorImage quadtree = scene.renderLod(camera, 1.0f);
    const image::ColorImage full = scene.renderLod(camera, 1e-6f);
    const double vs_quadtree = image::psnr(cdlod, quadtree), vs_full = image::psnr(cdlod, full);
    std::printf("eye %.0f,%.0f: PSNR against the quadtree LOD %.1f dB, against full resolution %.1f dB\n",
                camera.eye.x, camera.eye.y, vs_quadtree, vs_full);
    EXPECT_GT(vs_full, 30.0);
    EXPECT_GT(vs_quadtree, 30.0);
    // A much larger bound changes the frame more (the comparison can fail).
    EXPECT_LT(image::psnr(drawGpuLod(terrain, camera, 64.0f), full), vs_full);
  }
}

TEST(GpuLodGL, BadInputIsAnError) {
  test::Scene scene(test::testFractal());
  EXPECT_THROW(GpuLodTerrain(scene.hf, image::ColorImage(), CdlodOptions{8, 16, 0.3f}), Error);
  EXPECT_THROW(GpuLodTerrain(scene.hf, scene.texture, CdlodOptions{6, 16, 0.3f}), Error);
  gpu::CdlodRenderer renderer(2, 2, std::vector<float>(4, 0.0f), Vec2(1.0f), 4, scene.texture, Vec2(1.0f), Vec2(0.0f));
  gpu::RenderTarget target(16, 16);
  const std::vector<gpu::CdlodInstance> nodes(1);
  EXPECT_THROW(renderer.draw(makeCamera(Vec3(0, 0, 5), Vec3(1, 1, 0), 16), target, nodes), Error);  // no levels
  EXPECT_THROW(renderer.setLevels(std::vector<int>(30, 0), std::vector<IVec2>(30, IVec2(1))), Error);
  EXPECT_THROW(gpu::CdlodRenderer(3, 3, std::vector<float>(4, 0.0f), Vec2(1.0f), 4, scene.texture, Vec2(1.0f),
                                  Vec2(0.0f)),
               Error);
}

}  // namespace
}  // namespace farfield::terrain
