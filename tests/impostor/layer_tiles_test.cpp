// Layers drawn as their tiles (impostor::layerTiles): every texel near data is in exactly one rectangle and nothing
// else is, the tiles draw the whole quad's image, and the cover planned from the cluster's parts bounds the captured one.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "farfield/impostor/layered.h"
#include "farfield/impostor/layered_fill.h"
#include "impostor/impostor_fixture.h"
#include "impostor/layered_cluster.h"

namespace farfield::impostor {
namespace {

using test::Cluster;
using test::ImpostorGpuTest;
using test::testBound;
using test::viewFrom;

// Brute force: does the tile of texel (x, y) (the grid's origin at (-origin.x, -origin.y)) hold a texel, or touch one
// within a texel, with alpha > 0?
bool inDrawnTile(const image::ColorImage& c, IVec2 origin, int x, int y) {
  const int t = kLayerTile;
  const int gx0 = (x + origin.x) / t * t, gy0 = (y + origin.y) / t * t;  // the tile's first grid texel
  for (int b = 0; b < c.height(); ++b)
    for (int a = 0; a < c.width(); ++a) {
      if (c.at(a, b).a == 0) continue;
      const int gx = a + origin.x, gy = b + origin.y;
      if (gx >= gx0 - 1 && gx <= gx0 + t && gy >= gy0 - 1 && gy <= gy0 + t) return true;
    }
  return false;
}

TEST(LayerTilesTest, EveryTexelNearDataIsInOneRectangleAndNoOtherTexelIs) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> size(1, 48), offset(0, 3 * kLayerTile), coin(0, 99);
  size_t drawn_total = 0, texels_total = 0;
  for (int trial = 0; trial < 60; ++trial) {
    image::ColorImage color(size(rng), size(rng), image::Rgba8(0, 0, 0, 0));
    const IVec2 origin(offset(rng), offset(rng));
    // A few blobs of data and scattered texels; colour without alpha (a dilated fringe) is not data.
    const int density = trial % 4 == 0 ? 0 : 1 + trial % 7;
    for (int y = 0; y < color.height(); ++y)
      for (int x = 0; x < color.width(); ++x) {
        if (coin(rng) < density) color.at(x, y) = image::Rgba8(200, 10, 10, 255);
        else if (coin(rng) < 20) color.at(x, y) = image::Rgba8(40, 40, 40, 0);
      }
    const std::vector<LayerCrop> rects = layerTiles(color, origin);
    std::vector<int> count(color.pixelCount(), 0);
    for (const LayerCrop& r : rects) {
      ASSERT_GE(r.x, 0);
      ASSERT_GE(r.y, 0);
      ASSERT_LE(r.x + r.width, color.width());
      ASSERT_LE(r.y + r.height, color.height());
      ASSERT_GT(r.width, 0);
      ASSERT_GT(r.height, 0);
      for (int y = r.y; y < r.y + r.height; ++y)
        for (int x = r.x; x < r.x + r.width; ++x) ++count[size_t(y) * size_t(color.width()) + size_t(x)];
    }
    for (int y = 0; y < color.height(); ++y)
      for (int x = 0; x < color.width(); ++x) {
        const int want = inDrawnTile(color, origin, x, y) ? 1 : 0;
        ASSERT_EQ(count[size_t(y) * size_t(color.width()) + size_t(x)], want)
            << "trial " << trial << " texel (" << x << ", " << y << ") origin (" << origin.x << ", " << origin.y << ")";
        drawn_total += size_t(want);
      }
    texels_total += color.pixelCount();
    if (density == 0) {
      EXPECT_TRUE(rects.empty());
    }
  }
  // Sparse data leaves most tiles out (the point of drawing tiles).
  EXPECT_LT(drawn_total, texels_total);
  EXPECT_GT(drawn_total, 0u);
}

TEST_F(ImpostorGpuTest, TiledLayersDrawTheWholeQuadsImageOverLessOfThem) {
  const Cluster c;
  const gpu::GpuScene scene(c.s.scene);
  const ErrorBound bound = testBound();
  for (const bool crop : {false, true}) {
    LayeredImpostor impostor = captureLayered(*renderer_, scene, c.ids, planLayered(c.box, c.shaft, bound));
    if (crop) impostor = cropLayered(impostor);
    else measureLayerCover(impostor);
    const GpuLayeredImpostor tiles(impostor), whole(impostor, LayerDraw::WholeQuads);
    EXPECT_EQ(tiles.gpuBytes(), impostor.plan.bytes());  // the tiles' rectangles counted
    EXPECT_GT(tiles.rectangles(), tiles.quads());
    EXPECT_EQ(whole.rectangles(), whole.quads());
    double drawn = 0.0, texels = 0.0;
    for (const LayerPlan& lp : impostor.plan.layers) {
      EXPECT_GT(lp.cover, 0.0f);
      EXPECT_LE(lp.cover, 1.0f);
      drawn += double(lp.cover) * lp.width * lp.height;
      texels += double(lp.width) * lp.height;
    }
    std::printf("%s: %u layers as %u rectangles cover %.1f %% of their quads\n", crop ? "cropped" : "whole",
                tiles.quads(), tiles.rectangles(), 100.0 * drawn / texels);
    EXPECT_LT(drawn, (crop ? 0.95 : 0.6) * texels);
    std::vector<gpu::DrawItem> a_items, b_items;
    tiles.appendDrawItems(a_items);
    whole.appendDrawItems(b_items);
    test::expectSameImage(*renderer_, c, bound, a_items, b_items);
  }
}

TEST_F(ImpostorGpuTest, TheCoverPlannedFromThePartsBoundsTheCapturedTiles) {
  const Cluster c;
  const gpu::GpuScene scene(c.s.scene);
  const ErrorBound bound = testBound();
  const std::vector<Box3> parts(c.s.boxes.begin(), c.s.boxes.end());
  double planned_sum = 0.0, texel_sum = 0.0;
  int shafts = 0;
  for (const Vec3& axis : {Vec3(0.0f, -1.0f, 0.3f), Vec3(1.0f, 0.2f, 0.1f), Vec3(-0.6f, 0.7f, 0.4f)})
    for (const double apex_deg : {11.25, 45.0})
      for (const float distance : {45.0f, 120.0f}) {
        const Shaft shaft = Shaft::make(c.box.center(), axis, float(degToRad(apex_deg)), distance);
        const LayeredPlan plan = planLayered(c.box, shaft, bound, {}, parts);
        const LayeredPlan plain = planLayered(c.box, shaft, bound);
        ASSERT_EQ(plan.layers.size(), plain.layers.size());
        LayeredImpostor captured = captureLayered(*renderer_, scene, c.ids, plan);
        const LayeredImpostor cropped = cropLayered(captured);
        measureLayerCover(captured);
        for (size_t i = 0; i < plan.layers.size(); ++i) {
          const LayerPlan& p = plan.layers[i];
          const double texels = double(p.width) * p.height;
          const double planned = double(p.cover) * texels;
          const LayerPlan& m = captured.plan.layers[i];
          const LayerPlan& k = cropped.plan.layers[i];
          EXPECT_EQ(plain.layers[i].cover, 1.0f);
          EXPECT_GE(planned, double(m.cover) * texels - 1e-3) << "shaft " << shafts << " layer " << i;
          EXPECT_GE(planned, double(k.cover) * k.width * k.height - 1e-3) << "shaft " << shafts << " layer " << i;
          planned_sum += planned;
          texel_sum += texels;
        }
        // The fill estimate follows: the plan's bounds what the cropped tiles fill, and is below the whole quads'.
        const double d = 1.3 * distance;
        EXPECT_LE(layeredFillPixels(cropped.plan, d, bound), layeredFillPixels(plan, d, bound) * (1.0 + 1e-6));
        EXPECT_LE(layeredFillPixels(plan, d, bound), layeredFillPixels(plain, d, bound) * (1.0 + 1e-6));
        ++shafts;
      }
  std::printf("planned cover %.1f %% of the quads over %d shafts\n", 100.0 * planned_sum / texel_sum, shafts);
  EXPECT_LT(planned_sum, 0.9 * texel_sum);  // the parts leave gaps the whole quads would shade

  std::vector<Box3> bad = parts;
  bad[2].hi.x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THAT([&] { planLayered(c.box, c.shaft, bound, {}, bad); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("layered impostor part 2")));
}

}  // namespace
}  // namespace farfield::impostor
