// The closed loop of LOD-sprite's cost model (cost_correction.h) against known costs: what each kind of frame really
// costs is recovered from measured times delivered late and in any order, a keyframe's or a slice's part from what
// its frame measured beyond the corrected sprite frame, one slow frame does not move the median, and a kind that is no
// longer measured falls back to the model.
#include <gtest/gtest.h>

#include <random>

#include "farfield/core/error.h"
#include "farfield/terrain/cost_correction.h"

namespace farfield::terrain {
namespace {

using K = TerrainFrameKind;

// Frame f drawn as `kind` with the model's prediction (base, extra), and measured at `ms` at once.
void drawnAndMeasured(CostCorrection& c, uint64_t f, K kind, double base, double extra, double ms) {
  c.drawn(f, kind, base, extra);
  c.measured(f, ms);
}

TEST(CostCorrection, WithoutMeasurementsTheModelStands) {
  CostCorrection c;
  for (uint64_t f = 1; f <= 10; ++f) c.drawn(f, f % 2 ? K::Sprite : K::High, 4.0);
  for (size_t k = 0; k < kTerrainFrameKinds; ++k) EXPECT_DOUBLE_EQ(c.factor(TerrainFrameKind(k)), 1.0);
  EXPECT_EQ(c.measurementsUsed(), 0u);
  // Fewer than min_samples (3) of a kind: still the model's.
  CostCorrectionOptions o;
  o.lag = 0;
  CostCorrection few(o);
  for (uint64_t f = 1; f <= 3; ++f) {
    drawnAndMeasured(few, f, K::Sprite, 1.0, 0.0, 2.0);
    EXPECT_DOUBLE_EQ(few.factor(K::Sprite), f < 3 ? 1.0 : 2.0) << "frame " << f;
  }
}

// A slice's part is judged by the sprite frames' correction of now: slices measured while the sprite factor rested on
// slow first frames are not taken as nearly free.
TEST(CostCorrection, APartIsJudgedByTheSpriteFactorOfNow) {
  CostCorrectionOptions o;
  o.lag = 0;
  CostCorrection c(o);
  uint64_t f = 0;
  auto frame = [&](K kind, double base, double extra, double ms) { drawnAndMeasured(c, ++f, kind, base, extra, ms); };
  for (int i = 0; i < 3; ++i) frame(K::Sprite, 10.0, 0.0, 16.0);  // slow first sprite frames: 1.6x
  for (int i = 0; i < 3; ++i) frame(K::Slice, 10.0, 2.0, 14.0);   // sprite 10 ms + a 4 ms slice
  EXPECT_DOUBLE_EQ(c.factor(K::Slice), o.min_ratio) << "14 - 1.6 x 10 < 0";
  for (int i = 0; i < 9; ++i) frame(K::Sprite, 10.0, 0.0, 10.0);  // then they measure as predicted
  EXPECT_DOUBLE_EQ(c.factor(K::Sprite), 1.0);
  EXPECT_DOUBLE_EQ(c.factor(K::Slice), 2.0);
}

// Sprite frames that cost 1.8x their prediction and high frames 0.7x, keyframes whose part costs 2.5x and slices
// whose part costs 3x, each frame's time measured with noise and reported one to three frames late, out of order.
TEST(CostCorrection, RecoversKnownCostsFromLateMeasurements) {
  CostCorrectionOptions o;
  o.samples = 15;
  CostCorrection c(o);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(0.95, 1.05), prediction(2.0, 6.0);
  std::uniform_int_distribution<int> late(1, 3);
  struct Pending {
    uint64_t due, frame;
    double ms;
  };
  std::vector<Pending> pending;
  for (uint64_t f = 1; f <= 200; ++f) {
    const K kind = f % 10 == 0 ? K::Keyframe : f % 10 == 5 ? K::Slice : f % 3 == 0 ? K::High : K::Sprite;
    const double base = prediction(rng), extra = kind == K::Keyframe || kind == K::Slice ? prediction(rng) : 0.0;
    c.drawn(f, kind, base, extra);
    double ms = kind == K::High ? 0.7 * base : 1.8 * base;
    if (kind == K::Keyframe) ms += 2.5 * extra;
    if (kind == K::Slice) ms += 3.0 * extra;
    pending.push_back({f + uint64_t(late(rng)), f, ms * noise(rng)});
    // Delivered in reverse order of their frames when several come due together.
    for (auto it = pending.rbegin(); it != pending.rend(); ++it) {
      if (it->due == f) {
        EXPECT_TRUE(c.measured(it->frame, it->ms));
      }
    }
  }
  EXPECT_NEAR(c.factor(K::Sprite), 1.8, 0.08);
  EXPECT_NEAR(c.factor(K::High), 0.7, 0.04);
  EXPECT_NEAR(c.factor(K::Keyframe), 2.5, 0.3);
  EXPECT_NEAR(c.factor(K::Slice), 3.0, 0.3);
  EXPECT_FALSE(c.measured(3, 1.0)) << "measured twice";
  EXPECT_FALSE(c.measured(999, 1.0)) << "never drawn";
}

// A measurement counts only once `lag` frames have been drawn after its frame, as a timer query would come back.
TEST(CostCorrection, AMeasurementCountsOnlyLagFramesLater) {
  CostCorrectionOptions o;
  o.lag = 2;
  o.min_samples = 1;
  CostCorrection c(o);
  c.drawn(1, K::Sprite, 2.0);
  EXPECT_TRUE(c.measured(1, 6.0));
  EXPECT_DOUBLE_EQ(c.factor(K::Sprite), 1.0);
  c.drawn(2, K::Sprite, 2.0);
  EXPECT_DOUBLE_EQ(c.factor(K::Sprite), 1.0);
  c.drawn(3, K::Sprite, 2.0);
  EXPECT_DOUBLE_EQ(c.factor(K::Sprite), 3.0);
  // Measured after it was due: taken at once.
  c.drawn(4, K::High, 1.0);
  c.drawn(5, K::Sprite, 2.0);
  c.drawn(6, K::Sprite, 2.0);
  EXPECT_TRUE(c.measured(4, 0.5));
  EXPECT_DOUBLE_EQ(c.factor(K::High), 0.5);
}

// The median: one frame 40x slower than the others does not move it; the ratio is clamped at max_ratio.
TEST(CostCorrection, OneSlowFrameDoesNotMoveTheMedian) {
  CostCorrectionOptions o;
  o.lag = 0;
  o.min_samples = 1;
  CostCorrection c(o);
  for (uint64_t f = 1; f <= 9; ++f) drawnAndMeasured(c, f, K::Sprite, 1.0, 0.0, f == 5 ? 40.0 : 1.2);
  EXPECT_DOUBLE_EQ(c.factor(K::Sprite), 1.2);
  CostCorrection one(o);
  drawnAndMeasured(one, 1, K::Sprite, 1.0, 0.0, 40.0);
  EXPECT_DOUBLE_EQ(one.factor(K::Sprite), o.max_ratio);
}

// A kind no longer drawn (the high LOD while sprites win) forgets its measurements after forget_frames, so that the
// model's prediction of it comes back and the choice can try it again.
TEST(CostCorrection, AKindNoLongerMeasuredFallsBackToTheModel) {
  CostCorrectionOptions o;
  o.lag = 0;
  o.forget_frames = 30;
  CostCorrection c(o);
  for (uint64_t f = 1; f <= 5; ++f) drawnAndMeasured(c, f, K::High, 2.0, 0.0, 6.0);
  EXPECT_DOUBLE_EQ(c.factor(K::High), 3.0);
  for (uint64_t f = 6; f <= 33; ++f) c.drawn(f, K::Sprite, 1.0);
  EXPECT_DOUBLE_EQ(c.factor(K::High), 3.0) << "frames 3, 4 and 5 are at most 30 frames old";
  c.drawn(34, K::Sprite, 1.0);
  EXPECT_DOUBLE_EQ(c.factor(K::High), 1.0) << "two left: fewer than min_samples";
}

TEST(CostCorrection, RefusesBadInput) {
  CostCorrectionOptions o;
  o.samples = 0;
  EXPECT_THROW(CostCorrection{o}, Error);
  o = {};
  o.lag = 1000;
  EXPECT_THROW(CostCorrection{o}, Error);
  o = {};
  o.min_ratio = 0.0;
  EXPECT_THROW(CostCorrection{o}, Error);
  CostCorrection c;
  c.drawn(5, K::Sprite, 1.0);
  EXPECT_THROW(c.drawn(5, K::Sprite, 1.0), Error);
  EXPECT_THROW(c.drawn(6, K::Sprite, -1.0), Error);
  EXPECT_FALSE(c.measured(5, -1.0));
}

}  // namespace
}  // namespace farfield::terrain
