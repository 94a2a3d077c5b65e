#include "farfield/impostor/discrepancy.h"

#include <gtest/gtest.h>

#include <cmath>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

using Mask = image::Image<uint8_t>;

// Linear depth (metres) with a step along the line x = x0 + slope * (y + 0.5): near on the left, far on the right.
image::DepthImage stepImage(int w, int h, double x0, double slope, float near_m, float far_m) {
  image::DepthImage d(w, h, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d.at(x, y) = (x + 0.5 < x0 + slope * (y + 0.5)) ? near_m : far_m;
  return d;
}

double distanceToLine(const DVec2& p, double x0, double slope) {
  // Line x - slope * y - x0 = 0.
  return std::abs(p.x - slope * p.y - x0) / std::sqrt(1.0 + slope * slope);
}

TEST(DiscrepancyTest, VerticalStepGivesOneStraightChainOnEachSide) {
  const image::DepthImage depth = stepImage(64, 48, 32.0, 0.0, 10.0f, 20.0f);
  const Mask mask(64, 48, 1);
  const DiscrepancyLines lines = extractDiscrepancyLines(depth, mask);
  // Hand-computed: |20 - 10| / 10 = 1 on both columns next to the step, 0 elsewhere.
  EXPECT_FLOAT_EQ(lines.discrepancy.at(31, 20), 1.0f);
  EXPECT_FLOAT_EQ(lines.discrepancy.at(32, 20), 1.0f);
  EXPECT_FLOAT_EQ(lines.discrepancy.at(30, 20), 0.0f);
  EXPECT_FLOAT_EQ(lines.discrepancy.at(33, 20), 0.0f);
  EXPECT_EQ(lines.pixels_above, 2u * 48u);
  ASSERT_EQ(lines.chains.size(), 2u);
  EXPECT_EQ(lines.short_chains, 0u);
  std::set<double> columns;
  for (const DiscrepancyChain& chain : lines.chains) {
    EXPECT_EQ(chain.pixels.size(), 48u);
    ASSERT_EQ(chain.polyline.size(), 2u);
    EXPECT_EQ(chain.polyline[0].x, chain.polyline[1].x);
    EXPECT_DOUBLE_EQ(std::abs(chain.polyline[1].y - chain.polyline[0].y), 47.0);  // centre of row 0 to row 47
    columns.insert(chain.polyline[0].x);
  }
  EXPECT_EQ(columns, (std::set<double>{31.5, 32.5}));
  EXPECT_EQ(lines.segmentCount(), 2u);
}

TEST(DiscrepancyTest, SlantedStepChainsFollowTheStepLine) {
  const double x0 = 10.0, slope = 0.6;
  const image::DepthImage depth = stepImage(80, 64, x0, slope, 50.0f, 90.0f);
  const Mask mask(80, 64, 1);
  DiscrepancyOptions options;
  options.tolerance_px = 1.0;
  const DiscrepancyLines lines = extractDiscrepancyLines(depth, mask, options);
  ASSERT_GE(lines.chains.size(), 2u);
  double covered_rows = 0.0;
  for (const DiscrepancyChain& chain : lines.chains) {
    // Every chain pixel touches the step: its centre within 1.5 px of the line.
    for (const IVec2& p : chain.pixels) EXPECT_LE(distanceToLine(DVec2(p) + 0.5, x0, slope), 1.5);
    for (const DVec2& v : chain.polyline) EXPECT_LE(distanceToLine(v, x0, slope), 1.5 + options.tolerance_px);
    if (chain.polyline.size() >= 2) covered_rows += std::abs(chain.polyline.back().y - chain.polyline.front().y);
  }
  // The long chains run (nearly) the whole height, once per side.
  EXPECT_GE(covered_rows, 2.0 * 60.0);
  // Each polyline is short: the step is straight.
  for (const DiscrepancyChain& chain : lines.chains)
    if (chain.pixels.size() > 30) {
      EXPECT_LE(chain.polyline.size(), 4u);
    }
}

TEST(DiscrepancyTest, ChainsStopAtTheContour) {
  const image::DepthImage depth = stepImage(40, 40, 20.0, 0.0, 10.0f, 30.0f);
  Mask mask(40, 40, 1);
  for (int y = 18; y < 22; ++y)
    for (int x = 0; x < 40; ++x) mask.at(x, y) = 0;  // a band of sky across the step
  const DiscrepancyLines lines = extractDiscrepancyLines(depth, mask);
  ASSERT_EQ(lines.chains.size(), 4u);
  for (const DiscrepancyChain& chain : lines.chains) {
    const bool above = chain.pixels.front().y < 18;
    for (const IVec2& p : chain.pixels) {
      EXPECT_TRUE(mask.at(p.x, p.y));
      EXPECT_EQ(p.y < 18, above);  // never crosses the background band
    }
    EXPECT_EQ(chain.pixels.size(), 18u);
  }
}

TEST(DiscrepancyTest, StepBelowThresholdAndBackgroundGiveNoChains) {
  const image::DepthImage depth = stepImage(30, 30, 15.0, 0.0, 100.0f, 105.0f);  // 5 %
  const DiscrepancyLines lines = extractDiscrepancyLines(depth, Mask(30, 30, 1));
  EXPECT_EQ(lines.pixels_above, 0u);
  EXPECT_TRUE(lines.chains.empty());
  // Data against background is the contour's job, not a discrepancy.
  image::DepthImage island(30, 30, 0.0f);
  Mask mask(30, 30, 0);
  for (int y = 10; y < 20; ++y)
    for (int x = 10; x < 20; ++x) {
      island.at(x, y) = 40.0f;
      mask.at(x, y) = 1;
    }
  EXPECT_EQ(extractDiscrepancyLines(island, mask).pixels_above, 0u);
}

TEST(DiscrepancyTest, AbsoluteMetricUsesMetres) {
  const image::DepthImage depth = stepImage(30, 30, 15.0, 0.0, 1000.0f, 1040.0f);  // 4 %, 40 m
  DiscrepancyOptions options;
  options.metric = DiscrepancyMetric::Absolute;
  options.threshold = 30.0f;
  EXPECT_EQ(extractDiscrepancyLines(depth, Mask(30, 30, 1), options).chains.size(), 2u);
  options.threshold = 50.0f;
  EXPECT_EQ(extractDiscrepancyLines(depth, Mask(30, 30, 1), options).chains.size(), 0u);
  EXPECT_FLOAT_EQ(pairDiscrepancy(10.0f, 15.0f, DiscrepancyMetric::Relative), 0.5f);
  EXPECT_FLOAT_EQ(pairDiscrepancy(10.0f, 15.0f, DiscrepancyMetric::Absolute), 5.0f);
}

TEST(DiscrepancyTest, LinearizeDepthMatchesTheCameraAndRejectsBadInput) {
  Camera camera;
  camera.width = 4;
  camera.height = 2;
  camera.near_plane = 1.0f;
  camera.far_plane = 1001.0f;
  image::DepthImage window(4, 2, 0.0f);
  Mask mask(4, 2, 0);
  window.at(1, 1) = 1.0f;   // near plane
  mask.at(1, 1) = 1;
  window.at(2, 0) = 0.5f;
  mask.at(2, 0) = 1;
  const image::DepthImage linear = linearizeDepth(window, mask, camera);
  EXPECT_NEAR(linear.at(1, 1), 1.0f, 1e-5f);
  // n f / (z (f - n) + n) = 1001 / 501 at z = 0.5, by hand.
  EXPECT_NEAR(linear.at(2, 0), 1001.0f / 501.0f, 1e-4f);
  EXPECT_EQ(linear.at(0, 0), 0.0f);
  window.at(2, 0) = std::nanf("");
  EXPECT_THROW(linearizeDepth(window, mask, camera), Error);
  camera.width = 5;
  EXPECT_THROW(linearizeDepth(image::DepthImage(4, 2, 0.5f), Mask(4, 2, 1), camera), Error);
}

}  // namespace
}  // namespace farfield::impostor
