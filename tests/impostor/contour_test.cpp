#include "farfield/impostor/contour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

using Mask = image::Image<uint8_t>;

size_t countData(const Mask& mask) {
  size_t n = 0;
  for (uint8_t v : mask.pixels()) n += v ? 1 : 0;
  return n;
}

bool dataAt(const Mask& mask, int x, int y) {
  return x >= 0 && y >= 0 && x < mask.width() && y < mask.height() && mask.at(x, y) != 0;
}

// A pixel corner with both a data pixel and a background pixel (or the outside of the image) among the four
// pixels around it: a point of the silhouette's boundary.
bool onSilhouetteBoundary(const Mask& mask, const DVec2& p) {
  if (p.x != std::floor(p.x) || p.y != std::floor(p.y)) return false;
  const int x = int(p.x), y = int(p.y);
  int data = 0;
  for (int dy = -1; dy <= 0; ++dy)
    for (int dx = -1; dx <= 0; ++dx) data += dataAt(mask, x + dx, y + dy) ? 1 : 0;
  return data > 0 && data < 4;
}

Mask disc(int size, double cx, double cy, double r) {
  Mask mask(size, size, 0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= r) mask.at(x, y) = 1;
  return mask;
}

double distanceToPolygon(const DVec2& p, const std::vector<DVec2>& polygon) {
  double best = 1e300;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const DVec2 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    const DVec2 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    best = std::min(best, glm::length(p - (a + t * ab)));
  }
  return best;
}

TEST(ContourTest, DiscTracedExactlyAndSimplifiedWithinAFewPercent) {
  const Mask mask = disc(128, 64.3, 60.7, 40.0);
  const double pixels = double(countData(mask));
  const auto traced = traceBoundaries(mask);
  ASSERT_EQ(traced.size(), 1u);
  EXPECT_DOUBLE_EQ(signedArea(traced[0]), pixels);  // pixel-edge polygon: exactly the pixel count
  for (const DVec2& p : traced[0]) EXPECT_TRUE(onSilhouetteBoundary(mask, p)) << p.x << ", " << p.y;

  ContourOptions options;
  options.tolerance_px = 1.0;
  const Contours contours = extractContours(mask, options);
  ASSERT_EQ(contours.loops.size(), 1u);
  const ContourLoop& loop = contours.loops[0];
  EXPECT_FALSE(loop.hole());
  EXPECT_LT(loop.points.size(), traced[0].size() / 2);  // simplification did something
  EXPECT_NEAR(signedArea(loop.points), pixels, 0.03 * pixels);
  for (const DVec2& p : loop.points) EXPECT_TRUE(onSilhouetteBoundary(mask, p)) << p.x << ", " << p.y;
  // Every traced corner stays within the tolerance of the simplified boundary.
  for (const DVec2& p : traced[0]) EXPECT_LE(distanceToPolygon(p, loop.points), options.tolerance_px + 1e-9);
}

TEST(ContourTest, RectangleGivesItsFourCorners) {
  Mask mask(40, 30, 0);
  for (int y = 5; y < 21; ++y)
    for (int x = 3; x < 33; ++x) mask.at(x, y) = 1;
  const Contours contours = extractContours(mask);
  ASSERT_EQ(contours.loops.size(), 1u);
  const std::vector<DVec2>& pts = contours.loops[0].points;
  ASSERT_EQ(pts.size(), 4u);
  const std::set<std::pair<double, double>> got = {{pts[0].x, pts[0].y}, {pts[1].x, pts[1].y},
                                                   {pts[2].x, pts[2].y}, {pts[3].x, pts[3].y}};
  const std::set<std::pair<double, double>> want = {{3, 5}, {33, 5}, {33, 21}, {3, 21}};
  EXPECT_EQ(got, want);
  EXPECT_DOUBLE_EQ(signedArea(pts), 30.0 * 16.0);
}

TEST(ContourTest, RingGivesAnOuterLoopAndAHole) {
  Mask mask = disc(100, 50, 50, 30);
  const Mask inner = disc(100, 50, 50, 12);
  for (size_t i = 0; i < mask.pixelCount(); ++i)
    if (inner.pixels()[i]) mask.pixels()[i] = 0;
  const Contours contours = extractContours(mask, {0.0, 0.0});
  ASSERT_EQ(contours.loops.size(), 2u);
  int holes = 0;
  double total = 0.0;
  for (const ContourLoop& loop : contours.loops) {
    holes += loop.hole() ? 1 : 0;
    total += signedArea(loop.points);
  }
  EXPECT_EQ(holes, 1);
  EXPECT_DOUBLE_EQ(total, double(countData(mask)));
}

TEST(ContourTest, DiagonalNeighboursAreSeparateLoopsAndTheImageBorderCloses) {
  Mask mask(4, 4, 0);
  mask.at(1, 1) = 1;
  mask.at(2, 2) = 1;
  const auto loops = traceBoundaries(mask);
  ASSERT_EQ(loops.size(), 2u);
  for (const auto& loop : loops) {
    EXPECT_EQ(loop.size(), 4u);
    EXPECT_DOUBLE_EQ(signedArea(loop), 1.0);
  }
  const Mask full(5, 3, 1);
  const auto border = traceBoundaries(full);
  ASSERT_EQ(border.size(), 1u);
  EXPECT_DOUBLE_EQ(signedArea(border[0]), 15.0);
  EXPECT_TRUE(traceBoundaries(Mask(6, 6, 0)).empty());
}

// Random masks against an independent check: every unit step of every loop is a pixel edge with a data pixel on
// its right (on screen, y down) and background on its left, every such edge of the mask is used exactly once, and
// the signed areas add up to the pixel count.
TEST(ContourTest, RandomMasksBoundaryEdgesMatchBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    const int w = 5 + int(rng() % 20), h = 5 + int(rng() % 20);
    Mask mask(w, h, 0);
    const unsigned density = 2 + rng() % 5;
    for (uint8_t& v : mask.pixels()) v = (rng() % density) == 0 ? 0 : 1;
    std::multiset<std::tuple<int, int, int, int>> from_loops;
    double total = 0.0;
    for (const auto& loop : traceBoundaries(mask)) {
      total += signedArea(loop);
      for (size_t i = 0; i < loop.size(); ++i) {
        const DVec2 a = loop[i], b = loop[(i + 1) % loop.size()];
        ASSERT_TRUE(a.x == b.x || a.y == b.y);
        const int steps = int(std::abs(b.x - a.x) + std::abs(b.y - a.y));
        const int dx = int(glm::sign(b.x - a.x)), dy = int(glm::sign(b.y - a.y));
        for (int s = 0; s < steps; ++s) {
          const int x = int(a.x) + s * dx, y = int(a.y) + s * dy;
          from_loops.insert({x, y, dx, dy});
        }
      }
    }
    EXPECT_DOUBLE_EQ(total, double(countData(mask)));
    std::multiset<std::tuple<int, int, int, int>> brute;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!dataAt(mask, x, y)) continue;
        if (!dataAt(mask, x, y - 1)) brute.insert({x, y, 1, 0});
        if (!dataAt(mask, x + 1, y)) brute.insert({x + 1, y, 0, 1});
        if (!dataAt(mask, x, y + 1)) brute.insert({x + 1, y + 1, -1, 0});
        if (!dataAt(mask, x - 1, y)) brute.insert({x, y + 1, 0, -1});
      }
    EXPECT_EQ(from_loops, brute) << "trial " << trial;
  }
}

TEST(ContourTest, SmallLoopsAreDroppedAndCounted) {
  Mask mask(30, 30, 0);
  for (int y = 2; y < 20; ++y)
    for (int x = 2; x < 20; ++x) mask.at(x, y) = 1;
  mask.at(25, 25) = 1;  // a one-pixel island
  mask.at(10, 10) = 0;  // a one-pixel hole
  ContourOptions options;
  options.min_area_px = 2.0;
  const Contours contours = extractContours(mask, options);
  EXPECT_EQ(contours.loops.size(), 1u);
  EXPECT_EQ(contours.dropped_loops, 2u);
  EXPECT_DOUBLE_EQ(contours.dropped_area, 2.0);
}

TEST(ContourTest, DataMaskRule) {
  image::ColorImage color(3, 1, image::Rgba8(10, 20, 30, 255));
  image::DepthImage depth(3, 1, 0.5f);
  depth.at(0, 0) = 0.0f;                  // sky
  color.at(1, 0) = kSeenFromBelowColor;   // bottom face seen from below
  const Mask mask = dataMask(color, depth);
  EXPECT_EQ(mask.at(0, 0), 0);
  EXPECT_EQ(mask.at(1, 0), 0);
  EXPECT_EQ(mask.at(2, 0), 1);
  EXPECT_THROW(dataMask(color, image::DepthImage(2, 2, 0.5f)), Error);
}

}  // namespace
}  // namespace farfield::impostor
