// The skinned triangles' measured cost: a moving average of frames' time per triangle, turned into a triangle budget
// for a time budget divided by the recent frames' largest measured / predicted ratio; frames with too few triangles
// or no time are left out.
#include "farfield/runtime/triangle_rate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "farfield/core/error.h"

using namespace farfield;
using runtime::TriangleRate;

TEST(TriangleRate, FirstBudgetThenTheMeasuredCostsMovingAverage) {
  TriangleRate rate(0.5, 1000, 12345);
  EXPECT_FALSE(rate.known());
  EXPECT_EQ(rate.trianglesFor(5.0), 12345u);
  rate.observe(10.0, 100000);  // 0.1 us a triangle
  EXPECT_TRUE(rate.known());
  EXPECT_DOUBLE_EQ(rate.msPerTriangle(), 1e-4);
  EXPECT_DOUBLE_EQ(rate.safetyFactor(), 1.0);
  EXPECT_EQ(rate.trianglesFor(5.0), 50000u);
  rate.observe(20.0, 100000);  // 0.2 us: the average moves halfway, and this frame took 2x its prediction
  EXPECT_NEAR(rate.msPerTriangle(), 1.5e-4, 1e-12);
  EXPECT_NEAR(rate.safetyFactor(), 2.0, 1e-12);
  EXPECT_NEAR(double(rate.trianglesFor(3.0)), 3.0 / (1.5e-4 * 2.0), 1.0);
  EXPECT_EQ(rate.trianglesFor(0.0), 0u);
}

TEST(TriangleRate, TheSafetyFactorIsTheLargestRatioOfTheWindow) {
  TriangleRate rate(1.0, 1, 0, 3);  // the newest frame alone is the average
  rate.observe(1.0, 1000);
  rate.observe(1.5, 1000);  // predicted 1.0: ratio 1.5
  rate.observe(1.5, 1000);  // 1.0
  rate.observe(1.2, 1000);  // 0.8
  EXPECT_NEAR(rate.safetyFactor(), 1.5, 1e-12);
  rate.observe(1.2, 1000);  // 1.0: the 1.5 leaves the window of 3
  EXPECT_NEAR(rate.safetyFactor(), 1.0, 1e-12);
  // A budget that the window's worst frame would have kept: 1.2 ms per 1,000 triangles.
  EXPECT_NEAR(double(rate.trianglesFor(6.0)), 5000.0, 1.0);
}

TEST(TriangleRate, FramesThatSayNothingAreLeftOut) {
  TriangleRate rate(0.3, 1000, 10000);
  rate.observe(5.0, 999);  // too few triangles
  rate.observe(std::nan(""), 50000);
  rate.observe(-1.0, 50000);
  EXPECT_FALSE(rate.known());
  EXPECT_EQ(rate.trianglesFor(4.0), 10000u);
  rate.observe(2.0, 20000);
  rate.observe(9.0, 500);  // left out: the average stays
  EXPECT_DOUBLE_EQ(rate.msPerTriangle(), 1e-4);
  EXPECT_THROW(TriangleRate(0.0), Error);
  EXPECT_THROW(TriangleRate(1.5), Error);
  EXPECT_THROW(TriangleRate(0.3, 1000, 10000, 0), Error);
}
