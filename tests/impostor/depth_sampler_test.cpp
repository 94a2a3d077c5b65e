#include "farfield/impostor/depth_sampler.h"

#include <gtest/gtest.h>

namespace farfield::impostor {
namespace {

using Mask = image::Image<uint8_t>;

struct Images {
  image::DepthImage window;
  Mask mask;
  image::DepthImage linear;
};

// Window depth given per pixel centre by fn(x + 0.5, y + 0.5); linear depth 1 / window depth (any monotone map
// will do for the continuity test).
template <class Fn>
Images makeImages(int w, int h, Fn&& fn) {
  Images im{image::DepthImage(w, h, 0.0f), Mask(w, h, 0), image::DepthImage(w, h, 0.0f)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float z = fn(x + 0.5, y + 0.5);
      im.window.at(x, y) = z;
      im.mask.at(x, y) = z > 0.0f ? 1 : 0;
      im.linear.at(x, y) = z > 0.0f ? 1.0f / z : 0.0f;
    }
  return im;
}

TEST(DepthSamplerTest, PlanesAreExtrapolatedExactlyToCornersAndEdges) {
  // An affine window depth (a plane seen in perspective) on the left half, background on the right.
  auto plane = [](double x, double y) { return 0.2 + 0.004 * x + 0.002 * y; };
  const Images im = makeImages(16, 16, [&](double x, double y) { return x < 8 ? float(plane(x, y)) : 0.0f; });
  const DepthSampler sampler(im.window, im.mask, im.linear, DiscrepancyOptions{});
  for (const DVec2 p : {DVec2(0, 0), DVec2(3, 5), DVec2(8, 8), DVec2(8, 16), DVec2(2.5, 7.25), DVec2(7.9, 0.1)}) {
    const auto s = sampler.sample(p);
    ASSERT_TRUE(s) << p.x << ", " << p.y;
    EXPECT_NEAR(s->window_depth, plane(p.x, p.y), 1e-6) << p.x << ", " << p.y;
    EXPECT_LT(s->pixel.x, 8);  // never a background pixel
  }
  // Off the data: the nearest data pixel within the search distance, else nothing.
  EXPECT_TRUE(sampler.sample(DVec2(9.5, 4.5), 2));
  EXPECT_EQ(sampler.sample(DVec2(9.5, 4.5), 2)->pixel, IVec2(7, 4));
  EXPECT_FALSE(sampler.sample(DVec2(13.5, 4.5), 2));
  EXPECT_TRUE(sampler.sample(DVec2(13.5, 4.5), -1));
}

TEST(DepthSamplerTest, OnAStepTheNearerSideWinsAndKeepsItsOwnGradient) {
  // Near plane (large window depth, reversed Z) left of x = 8, far plane right of it, each with its own slope.
  auto near_plane = [](double x, double y) { return 0.5 + 0.01 * x + 0.001 * y; };
  auto far_plane = [](double x, double y) { return 0.05 + 0.0005 * x - 0.0002 * y; };
  const Images im = makeImages(16, 16, [&](double x, double y) {
    return float(x < 8 ? near_plane(x, y) : far_plane(x, y));
  });
  const DepthSampler sampler(im.window, im.mask, im.linear, DiscrepancyOptions{});
  // On the step line (pixel edges and corners between the two sides): the near side, its own plane.
  for (const DVec2 p : {DVec2(8, 3), DVec2(8, 7.5), DVec2(8, 0)}) {
    const auto s = sampler.sample(p);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->pixel.x, 7);
    EXPECT_NEAR(s->window_depth, near_plane(p.x, p.y), 1e-6);
  }
  // Inside the far side's pixels: the far plane, extrapolated with the far side's gradient only.
  const auto far = sampler.sample(DVec2(8.25, 3.5));
  ASSERT_TRUE(far);
  EXPECT_EQ(far->pixel, IVec2(8, 3));
  EXPECT_NEAR(far->window_depth, far_plane(8.25, 3.5), 1e-6);
}

}  // namespace
}  // namespace farfield::impostor
