#include "farfield/eval/frame_stats.h"

#include <gtest/gtest.h>

#include <vector>

namespace farfield::eval {
namespace {

// Hand-computed with the documented rule: rank r = p/100 * (n-1), linear interpolation between v[floor r] and the
// next value.
TEST(FrameStats, PercentilesOfOneToTen) {
  const std::vector<double> v{7, 3, 10, 1, 5, 9, 2, 8, 4, 6};  // 1..10, shuffled
  EXPECT_NEAR(percentile(v, 50), 5.5, 1e-9);   // r = 4.5 -> 5 + 0.5
  EXPECT_NEAR(percentile(v, 95), 9.55, 1e-9);  // r = 8.55 -> 9 + 0.55
  EXPECT_NEAR(percentile(v, 99), 9.91, 1e-9);  // r = 8.91 -> 9 + 0.91
  EXPECT_NEAR(percentile(v, 0), 1.0, 1e-9);
  EXPECT_NEAR(percentile(v, 100), 10.0, 1e-9);
  EXPECT_NEAR(percentile(v, 10), 1.9, 1e-9);   // r = 0.9
  EXPECT_NEAR(percentile(v, 150), 10.0, 1e-9);  // clamped
  EXPECT_NEAR(percentile(v, -5), 1.0, 1e-9);

  const FrameSummary s = summarize(v);
  EXPECT_EQ(s.count, 10u);
  EXPECT_NEAR(s.median, 5.5, 1e-9);
  EXPECT_NEAR(s.p95, 9.55, 1e-9);
  EXPECT_NEAR(s.p99, 9.91, 1e-9);
  EXPECT_NEAR(s.min, 1.0, 1e-9);
  EXPECT_NEAR(s.max, 10.0, 1e-9);
  EXPECT_NEAR(s.mean, 5.5, 1e-9);
}

TEST(FrameStats, OddCountAndOutlier) {
  // 16.7 ms frames with one 100 ms hitch: the median ignores it, p99 feels it, max is it.
  const std::vector<double> v{16, 17, 100, 16, 18};
  const FrameSummary s = summarize(v);
  EXPECT_NEAR(s.median, 17.0, 1e-9);        // sorted 16 16 17 18 100, r = 2
  EXPECT_NEAR(s.p95, 18.0 + 0.8 * 82.0, 1e-9);  // r = 3.8
  EXPECT_NEAR(s.p99, 18.0 + 0.96 * 82.0, 1e-9);  // r = 3.96
  EXPECT_NEAR(s.max, 100.0, 1e-9);
  EXPECT_NEAR(s.min, 16.0, 1e-9);
  EXPECT_NEAR(s.mean, 167.0 / 5.0, 1e-9);
}

TEST(FrameStats, SingleValueAndEmpty) {
  const std::vector<double> one{4.25};
  const FrameSummary s = summarize(one);
  EXPECT_EQ(s.count, 1u);
  EXPECT_NEAR(s.median, 4.25, 1e-9);
  EXPECT_NEAR(s.p99, 4.25, 1e-9);
  EXPECT_NEAR(s.max, 4.25, 1e-9);

  const std::vector<double> none;
  const FrameSummary e = summarize(none);
  EXPECT_EQ(e.count, 0u);
  EXPECT_NEAR(e.median, 0.0, 1e-9);
  EXPECT_NEAR(e.max, 0.0, 1e-9);
  EXPECT_NEAR(percentile(none, 50), 0.0, 1e-9);
}

TEST(FrameStats, EvenCountMedianIsMeanOfMiddlePair) {
  const std::vector<double> v{4, 1, 3, 2};
  EXPECT_NEAR(percentile(v, 50), 2.5, 1e-9);
  EXPECT_NEAR(percentile(v, 25), 1.75, 1e-9);  // r = 0.75
  EXPECT_NEAR(percentile(v, 75), 3.25, 1e-9);  // r = 2.25
}

}  // namespace
}  // namespace farfield::eval
