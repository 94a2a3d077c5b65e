// The CDLOD terrain paged from a tile cache (terrain/paged_gpu_lod.h): its frames do not depend on the GPU budget
// (what was evicted and read again gives the same pixels), stay close to the whole grid's CDLOD frames, and pages
// are read ahead on the worker. Needs a GL context (llvmpipe is enough).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/paged_gpu_lod.h"
#include "farfield/terrain/terrain_texture.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

const Vec4 kSky(0.62f, 0.74f, 0.88f, 1.0f);
constexpr float kTau = 6.0f;  // pixels: the flight then draws nodes of every kind

// A low flight across the test fractal (4 x 4 tiles of 64 cells), 40 frames.
std::vector<Camera> flight(const Heightfield& hf) {
  std::vector<Camera> cameras;
  for (int f = 0; f < 40; ++f) {
    const float x = 300.0f + 100.0f * float(f);
    Camera c = test::tiledTestCamera(Vec3(x, 300.0f, hf.maxHeight() + 250.0f),
                                     Vec3(x + 800.0f, 3500.0f, hf.minHeight()));
    c.width = c.height = 160;
    cameras.push_back(c);
  }
  return cameras;
}

image::ColorImage drawPaged(PagedGpuLodTerrain& t, const Camera& c, float tau, PagedGpuLodFrame* out = nullptr) {
  gpu::RenderTarget target(c.width, c.height);
  target.clear(kSky);
  const PagedGpuLodFrame f = t.drawFrame(c, tau, target);
  if (out) *out = f;
  return target.readColor();
}

TEST(PagedGpuLodGL, FramesDoNotDependOnTheBudget) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "paged_gpu_lod"));
  PagedGpuLodOptions all;
  all.lod = CdlodOptions{8, 16, 0.2f};
  all.prefetch_frames = 0;
  PagedGpuLodTerrain roomy(cache, all);
  ASSERT_GE(roomy.pageLayers(), 16);
  EXPECT_EQ(roomy.overviewStep(), 8);
  EXPECT_EQ(roomy.fineLevels(), 3);
  const std::vector<Camera> cameras = flight(hf);
  size_t most = 0, nodes = 0, paged_nodes = 0;
  std::vector<image::ColorImage> expected;
  for (const Camera& c : cameras) {
    PagedGpuLodFrame f;
    expected.push_back(drawPaged(roomy, c, kTau, &f));
    EXPECT_GT(f.paged_nodes, 0u);
    nodes += f.nodes;
    paged_nodes += f.paged_nodes;
    most = std::max(most, f.pages_needed);
  }
  EXPECT_LT(paged_nodes, nodes);  // far nodes read the overview
  ASSERT_LT(most, 16u);
  PagedGpuLodOptions tight = all;
  tight.gpu_budget_bytes = (most + 1) * gpu::CdlodPages(64, 1).layerBytes();
  tight.prefetch_frames = 6;
  PagedGpuLodTerrain small(cache, tight);
  ASSERT_EQ(size_t(small.pageLayers()), most + 1);
  for (size_t f = 0; f < cameras.size(); ++f)
    EXPECT_EQ(drawPaged(small, cameras[f], kTau).pixels(), expected[f].pixels()) << "frame " << f;
  EXPECT_GT(small.stats().evictions, 0u);
  EXPECT_LE(small.stats().peak_pages, most + 1);
  EXPECT_GT(small.stats().prefetched, 0u);  // the worker read pages ahead
  EXPECT_EQ(roomy.stats().prefetched, 0u);
  std::printf("pages: %zu held at most, %zu evictions, %zu read in frames, %zu read ahead (%zu used)\n",
              small.stats().peak_pages, small.stats().evictions, small.stats().page_loads, small.stats().prefetched,
              small.stats().prefetch_hits);

  // A budget below one page, and a view needing more pages than held, are errors.
  PagedGpuLodOptions none = all;
  none.gpu_budget_bytes = 1000;
  EXPECT_THROW(PagedGpuLodTerrain(cache, none), Error);
  PagedGpuLodOptions one = all;
  one.gpu_budget_bytes = gpu::CdlodPages(64, 1).layerBytes();
  PagedGpuLodTerrain single(cache, one);
  EXPECT_THROW(drawPaged(single, cameras[0], 1.0f), Error);
}

TEST(PagedGpuLodGL, CloseToTheWholeGridFrame) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "paged_gpu_lod_whole"));
  PagedGpuLodOptions o;
  o.lod = CdlodOptions{8, 16, 0.2f};
  PagedGpuLodTerrain paged(cache, o);
  TextureOptions to;
  GpuLodTerrain whole(hf, terrainTexture(hf), o.lod);
  double worst = 1e9;
  for (const Camera& c : flight(hf)) {
    gpu::RenderTarget target(c.width, c.height);
    target.clear(kSky);
    whole.draw(c, 1.0f, target);
    worst = std::min(worst, image::psnr(drawPaged(paged, c, 1.0f), target.readColor()));
  }
  std::printf("paged against whole: PSNR at least %.1f dB\n", worst);
  EXPECT_GT(worst, 30.0);
}

}  // namespace
}  // namespace farfield::terrain
