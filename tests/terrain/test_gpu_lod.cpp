// The CDLOD terrain on the GPU (terrain/gpu_lod.h): its frame against the same surface drawn from the CPU
// reference of its vertex shader (CdlodTerrain::vertex) as a plain triangle list, and against the quadtree LOD's
// frame at the same bound and the full-resolution grid's. Needs a GL context (llvmpipe is enough).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/keyframe_visibility.h"
#include "farfield/terrain/terrain_texture.h"
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

// drawNodes: a selection kept by the caller, drawn in runs over several "frames" while the terrain makes selections
// for every other bound in between (each range slot remade), is the whole selection's frame pixel for pixel.
TEST(GpuLodGL, ASelectionDrawnInRunsIsTheWholeFrame) {
  test::Scene scene(test::testFractal());
  GpuLodTerrain terrain(scene.hf, scene.texture, CdlodOptions{8, 16, 0.3f});
  int differing = 0;
  for (const Camera& camera : views(scene.hf)) {
    const image::ColorImage whole = drawGpuLod(terrain, camera, 1.0f);
    const std::vector<CdlodNode> nodes = terrain.lastSelection().nodes;
    ASSERT_GT(nodes.size(), 3u);
    gpu::RenderTarget target(camera.width, camera.height);
    target.clear(kSky);
    const size_t runs = 3, per_run = (nodes.size() + runs - 1) / runs;
    size_t drawn = 0;
    for (size_t r = 0; r < runs; ++r) {
      for (float other : {2.0f, 3.0f, 5.0f, 7.0f}) terrain.select(views(scene.hf)[0], other);  // every slot remade
      const size_t first = std::min(nodes.size(), r * per_run);
      const std::span<const CdlodNode> run(nodes.data() + first, std::min(per_run, nodes.size() - first));
      const GpuLodFrame part = terrain.drawNodes(camera, 1.0f, run, target);
      EXPECT_EQ(part.nodes, run.size());
      drawn += part.nodes;
    }
    EXPECT_EQ(drawn, nodes.size());
    EXPECT_TRUE(target.readColor().pixels() == whole.pixels()) << "eye " << camera.eye.x;
    // The nodes drawn with another bound's ranges morph differently: the comparison can fail.
    target.clear(kSky);
    terrain.drawNodes(camera, 8.0f, nodes, target);
    if (target.readColor().pixels() != whole.pixels()) ++differing;
  }
  EXPECT_GT(differing, 0);
  EXPECT_THROW(terrain.drawNodes(views(scene.hf)[0], 0.0f, {}, *std::make_unique<gpu::RenderTarget>(8, 8)), Error);
}

// LOD-sprite's sprite frame on the GPU (CdlodRenderer::setSprite): against the CPU reference of the same selection,
// its vertices from CdlodTerrain::vertex, each tested by keyframe_visibility.h's vertexVisible against the keyframe's
// depth read back, the triangles whose three vertices pass drawn with the sprite, the others with the texture.
// Once with a plain magenta sprite (the frame shows which triangles took the sprite) and once with the keyframe's own
// colour (the projection).
TEST(GpuLodGL, SpriteFrameTakesTheSpriteWhereTheCpuVisibilityTestSays) {
  test::Scene scene(test::testFractal());
  GpuLodTerrain terrain(scene.hf, scene.texture, CdlodOptions{8, 16, 0.3f});
  const Heightfield& hf = scene.hf;
  const float top = hf.maxHeight();
  const Camera key = makeCamera(Vec3(100, 150, top + 80), Vec3(2400, 2000, hf.minHeight()), 160);
  gpu::RenderTarget keyframe(key.width, key.height), magenta(key.width, key.height);
  keyframe.clear(kSky);
  terrain.draw(key, 1.0f, keyframe);
  magenta.clear(Vec4(1.0f, 0.0f, 1.0f, 1.0f));
  const image::DepthImage key_depth = keyframe.readDepth();
  const VisibilityOptions visibility;
  Vec2 scale, offset;
  texCoordTransform(hf, scale, offset);
  // The frame moved away from the keyframe (sideways, lower, turned), so that part of its view is hidden there.
  for (const Camera& camera : {makeCamera(Vec3(400, 100, top + 20), Vec3(2200, 2400, hf.minHeight()), 128),
                               makeCamera(Vec3(160, 120, top + 60), Vec3(2300, 2100, hf.minHeight()), 128)}) {
    for (const gpu::RenderTarget* colour : {&magenta, &keyframe}) {
      gpu::CdlodSprite sprite;
      sprite.colour = &colour->colorTexture();
      sprite.depth = &keyframe.depthTexture();
      sprite.camera = key;
      const int handle = terrain.select(camera, 4.0f);
      terrain.renderer().setSprite(sprite);
      gpu::RenderTarget target(camera.width, camera.height);
      target.clear(kSky);
      const GpuLodFrame frame = terrain.drawSelection(camera, handle, target);
      terrain.renderer().clearSprite();
      EXPECT_EQ(frame.draw.draw_calls, 1u);
      const image::ColorImage gpu_frame = target.readColor();

      const CdlodTerrain& lod = terrain.lod();
      const CdlodSelection& sel = terrain.selection(handle);
      const int p = lod.patchCells();
      std::vector<Vec3> positions;
      std::vector<uint8_t> visible;
      std::vector<uint32_t> shown, textured;
      for (const CdlodNode& n : sel.nodes) {
        const uint32_t base = uint32_t(positions.size());
        for (int j = 0; j <= p; ++j)
          for (int i = 0; i <= p; ++i) {
            const Vec3 v = lod.vertex(n, i, j, sel.ranges, camera.eye);
            const int gi = std::min(int(std::floor(v.x / float(hf.cell_x) + 0.5f)), hf.width - 1);
            const int gj = std::min(int(std::floor(v.y / float(hf.cell_y) + 0.5f)), hf.height - 1);
            positions.push_back(v);
            visible.push_back(vertexVisible(key, key_depth, v, hf.normal(gi, gj), visibility) ? 1 : 0);
          }
        for (int j = 0; j < p; ++j)
          for (int i = 0; i < p; ++i) {
            const uint32_t c00 = base + uint32_t(i + j * (p + 1)), c10 = c00 + 1, c01 = c00 + uint32_t(p + 1),
                           c11 = c01 + 1;
            for (const std::array<uint32_t, 3>& t : {std::array<uint32_t, 3>{c00, c10, c11}, {c00, c11, c01}}) {
              std::vector<uint32_t>& list = visible[t[0]] && visible[t[1]] && visible[t[2]] ? shown : textured;
              list.insert(list.end(), t.begin(), t.end());
            }
          }
      }
      gpu::TerrainRenderer reference(positions, scene.texture, scale, offset);
      std::vector<uint32_t> indices = shown;
      indices.insert(indices.end(), textured.begin(), textured.end());
      reference.setIndices(indices);
      gpu::RenderTarget expected(camera.width, camera.height);
      expected.clear(kSky);
      reference.drawSprite(camera, expected, colour->colorTexture(), key.viewProjection(), 0, shown.size() / 3);
      reference.drawTextured(camera, expected, shown.size() / 3, textured.size() / 3);
      const image::ColorImage cpu_frame = expected.readColor();
      const double share = double(shown.size()) / double(indices.size());
      std::printf("eye %.0f,%.0f, %s sprite: %.0f %% of the triangles visible in the keyframe, PSNR %.1f dB\n",
                  camera.eye.x, camera.eye.y, colour == &magenta ? "magenta" : "keyframe", 100.0 * share,
                  image::psnr(gpu_frame, cpu_frame));
      EXPECT_GT(share, 0.1);
      EXPECT_LT(share, 0.98);
      EXPECT_GT(image::psnr(gpu_frame, cpu_frame), 40.0) << "eye " << camera.eye.x;
    }
  }
  gpu::CdlodSprite bad;
  EXPECT_THROW(terrain.renderer().setSprite(bad), Error);  // no textures
  bad.colour = bad.depth = &keyframe.depthTexture();
  bad.camera = makeCamera(Vec3(0, 0, 500), Vec3(100, 100, 0), 64);
  EXPECT_THROW(terrain.renderer().setSprite(bad), Error);  // another size than the camera's
  EXPECT_THROW(terrain.selection(-1), Error);
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
