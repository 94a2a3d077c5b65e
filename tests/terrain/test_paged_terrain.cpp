// A terrain drawn from paged tiles, each from its own GPU patch: the frame the whole grid's LOD draws with the
// whole texture (the same pixels covered, the same colours up to the far tiles' coarser texels), within the GPU
// budget with evictions, and a budget below one tile refused.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/image/metrics.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/paged_terrain.h"
#include "farfield/terrain/terrain_texture.h"
#include "support/expect_error.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

const Vec4 kSky(0.62f, 0.74f, 0.88f, 1.0f);

struct Frame {
  image::ColorImage color;
  image::IdImage ids;
};

// The whole grid: its LOD, its texture, every grid point on the GPU.
struct WholeTerrain {
  const Heightfield& hf;
  QuadtreeLod lod;
  image::ColorImage texture;
  std::unique_ptr<gpu::TerrainRenderer> renderer;
  explicit WholeTerrain(const Heightfield& h) : hf(h), lod(h, 16), texture(terrainTexture(h)) {
    Vec2 scale, offset;
    texCoordTransform(hf, scale, offset);
    renderer = std::make_unique<gpu::TerrainRenderer>(lod.positions(), texture, scale, offset);
  }
  Frame draw(const Camera& camera) {
    gpu::RenderTarget target(camera.width, camera.height);
    target.clear(kSky);
    LodMesh mesh;
    renderLodFrame(lod, *renderer, camera, LodSettings{1.0f, true, false}, target, mesh);
    return {target.readColor(), target.readIds()};
  }
};

Frame drawPaged(PagedTerrainRenderer& paged, const Camera& camera, PagedTerrainFrame* info = nullptr) {
  gpu::RenderTarget target(camera.width, camera.height);
  target.clear(kSky);
  const PagedTerrainFrame f = paged.draw(camera, LodSettings{1.0f, true, false}, target);
  if (info) *info = f;
  return {target.readColor(), target.readIds()};
}

size_t differentIds(const image::IdImage& a, const image::IdImage& b) {
  size_t n = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) n += a.at(x, y) != b.at(x, y) ? 1 : 0;
  return n;
}

TEST(PagedTerrainGL, DrawsTheFrameOfTheWholeGrid) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  WholeTerrain whole(hf);
  const TileCache cache(test::writeTestCache(hf, "paged_terrain_whole"));
  TilePager pager(cache, size_t(64) << 20);
  PagedTerrainRenderer paged(pager, size_t(64) << 20);
  size_t coarse_frames = 0;
  for (const Camera& camera : test::tiledTestCameras(hf)) {
    const Frame a = whole.draw(camera);
    PagedTerrainFrame info;
    const Frame b = drawPaged(paged, camera, &info);
    // The same mesh: the same pixels covered (a pixel on a triangle edge may go either way).
    EXPECT_LE(differentIds(a.ids, b.ids), size_t(a.ids.width() * a.ids.height()) / 1000) << camera.eye.x;
    EXPECT_GT(info.draw.triangles, 0u);
    EXPECT_EQ(info.draw.draw_calls, info.tiles.tiles_in_view);
    // The colours: tiles at step 1 carry the whole texture's texels, coarser tiles a coarser texture, as a mipmap
    // level would (measured 47.8-62.5 dB here; a patch's texture shifted by one texel gives 30-41 dB).
    EXPECT_GT(image::psnr(a.color, b.color), 45.0) << camera.eye.x;
    coarse_frames += info.tiles.coarsest_step > 1 ? 1 : 0;
  }
  EXPECT_GT(coarse_frames, 0u);  // the far views read coarse steps
  EXPECT_LE(paged.stats().peak_gpu_bytes, paged.budget());
}

TEST(PagedTerrainGL, PatchesStayWithinTheBudgetAndEvictionsChangeNoPixel) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal(11);
  const TileCache cache(test::writeTestCache(hf, "paged_terrain_budget"));
  TilePager pager(cache, size_t(64) << 20);
  PagedTerrainRenderer roomy(pager, size_t(64) << 20);
  TilePager pager2(cache, size_t(64) << 20);
  PagedTerrainRenderer probe(pager2, size_t(64) << 20);
  const size_t tile = probe.patchBytes(1, 1, 1);
  PagedTerrainRenderer tight(pager2, 3 * tile);
  const std::vector<Camera> cameras = test::tiledTestCameras(hf);
  for (int pass = 0; pass < 2; ++pass)
    for (const Camera& camera : cameras) {
      const Frame a = drawPaged(roomy, camera), b = drawPaged(tight, camera);
      EXPECT_EQ(differentIds(a.ids, b.ids), 0u);
      EXPECT_TRUE(a.color.pixels() == b.color.pixels()) << "pass " << pass << ", camera at " << camera.eye.x;
      EXPECT_LE(tight.stats().gpu_bytes, 3 * tile);
    }
  EXPECT_LE(tight.stats().peak_gpu_bytes, 3 * tile);
  EXPECT_GT(tight.stats().evictions, 0u);
  EXPECT_GT(tight.stats().loads, roomy.stats().loads);
}

TEST(PagedTerrainGL, ABudgetBelowOneTileIsRefused) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "paged_terrain_refused"));
  TilePager pager(cache, size_t(64) << 20);
  farfield::test::expectErrorMentions([&] { PagedTerrainRenderer(pager, 1000); },
                                      {cache.path(), "GPU budget", "full resolution"});
}

}  // namespace
}  // namespace farfield::terrain
