// The governor's loop against a synthetic machine whose frame cost is known: base + per million triangles + per
// million pixels. The calibration and the measured frames must give that model back, and with it the loop keeps
// t_max once it has measured the load.
#include "farfield/runtime/governor_loop.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <tuple>
#include <vector>

#include "farfield/core/error.h"

using namespace farfield;
using runtime::GovernorLoop;
using runtime::GovernorLoopOptions;
using runtime::LoopLevel;

namespace {

constexpr double kBase = 2.0, kPerMTriangle = 30.0, kPerMPixel = 40.0;
const std::vector<double> kPixels{640.0 * 360.0, 640.0 * 360.0, 538.0 * 302.0, 320.0 * 180.0};
const std::vector<double> kShare{1.0, 0.6, 0.6, 0.6};  // level 1 on: simplified geometry, 60 % of the triangles

double cost(double triangles, size_t level) { return kBase + kPerMTriangle * triangles * 1e-6 + kPerMPixel * kPixels[level] * 1e-6; }

std::vector<LoopLevel> levels() {
  std::vector<LoopLevel> out;
  for (size_t i = 0; i < kPixels.size(); ++i) out.push_back({{"level " + std::to_string(i), 1.0 + double(i)}, kPixels[i]});
  return out;
}

// One view's calibration: every level drawn three times, its triangles the view's full count times its share.
void calibrate(GovernorLoop& loop, double view_triangles) {
  for (int round = 0; round < 3; ++round)
    for (size_t level = 0; level < kPixels.size(); ++level)
      loop.calibrationSample(level, view_triangles * kShare[level], cost(view_triangles * kShare[level], level));
  loop.finishCalibration();
}

struct LoopRun {
  std::vector<std::tuple<size_t, double, double>> frames;  // level, true cost, full-detail triangles
  size_t first_over_measured = SIZE_MAX;
};

// Frames whose full-detail triangles follow `load`; each frame's triangles and time come back `lag` frames later.
// hint: the host tells the loop each frame's load before drawing it (decide's workload).
LoopRun run(GovernorLoop& loop, size_t frames, double t_max, double (*load)(size_t), size_t lag = 2,
            bool hint = false) {
  LoopRun r;
  std::deque<std::tuple<uint64_t, double, double>> pending;  // frame, triangles, ms
  for (size_t f = 0; f < frames; ++f) {
    while (!pending.empty() && std::get<0>(pending.front()) + lag <= f) {
      const auto [frame, triangles, ms] = pending.front();
      if (ms > t_max && r.first_over_measured == SIZE_MAX) r.first_over_measured = f;
      loop.frameTriangles(frame, triangles);
      loop.frameMeasured(frame, ms);
      pending.pop_front();
    }
    const runtime::GovernorDecision d = loop.decide(f, hint ? load(f) : 0.0);
    const double triangles = load(f) * kShare[d.level];
    const double ms = cost(triangles, d.level);
    r.frames.emplace_back(d.level, ms, load(f));
    pending.emplace_back(f, triangles, ms);
  }
  return r;
}

double wander(size_t f) { return 150000.0 + 100000.0 * std::sin(double(f) * 0.05) + 30000.0 * std::sin(double(f) * 0.31); }
double ramp(size_t f) { return 50000.0 + 1200.0 * double(f); }
double step(size_t f) { return f < 100 ? 50000.0 : 300000.0; }  // a new plan: a region's visible set 6x larger

}  // namespace

TEST(GovernorLoop, CalibrationAndMeasuredFramesRecoverKnownSyntheticCosts) {
  GovernorLoopOptions options;
  options.governor.t_max_ms = 1000.0;  // never coarsened: the frames are the full level's
  GovernorLoop loop(levels(), options);
  calibrate(loop, 120000.0);
  for (size_t level = 0; level < kPixels.size(); ++level) EXPECT_NEAR(loop.triangleShare(level), kShare[level], 1e-9);
  // The calibration's own samples (exact here) are predicted.
  EXPECT_NEAR(loop.model().predict(120000.0, 0.0, kPixels[0]), cost(120000.0, 0), 0.05);
  run(loop, 200, 1000.0, wander);
  EXPECT_NEAR(loop.model().base_ms, kBase, 0.02 * kBase);
  EXPECT_NEAR(loop.model().ms_per_mtriangle, kPerMTriangle, 0.01 * kPerMTriangle);
  EXPECT_NEAR(loop.model().ms_per_mpixel, kPerMPixel, 0.02 * kPerMPixel);
  // The last frames' predictions, from the previous frame's triangles: within the frame-to-frame change of the load.
  const std::vector<double>& ratio = loop.measuredOverPredicted();
  ASSERT_GT(ratio.size(), 150u);
  for (size_t i = ratio.size() - 50; i < ratio.size(); ++i) EXPECT_NEAR(ratio[i], 1.0, 0.1) << i;
}

TEST(GovernorLoop, ARampIsKeptUnderTmaxOnceTheLoadIsMeasured) {
  GovernorLoopOptions options;
  options.governor.t_max_ms = 12.0;
  GovernorLoop loop(levels(), options);
  calibrate(loop, 50000.0);
  const LoopRun r = run(loop, 250, 12.0, ramp);
  // The ramp takes the full level past t_max (50 k to 350 k triangles: 12.7 to 21.7 ms at full detail and size);
  // the coarsest level keeps it (10.6 ms at the end).
  EXPECT_GT(cost(ramp(249), 0), 12.0);
  size_t over = 0, coarsened = 0;
  for (size_t f = 0; f < r.frames.size(); ++f) {
    over += std::get<1>(r.frames[f]) > 12.0;
    coarsened += std::get<0>(r.frames[f]) > 0;
  }
  EXPECT_EQ(over, 0u);  // the model sees the load rise through the frames' triangles, before any frame breaks t_max
  EXPECT_GT(coarsened, 100u);
  EXPECT_EQ(std::get<0>(r.frames.back()), kPixels.size() - 1);
}

// A step of the load (a new region's plan): told the frame's workload before drawing it, the loop coarsens in the
// step's first frame and no frame breaks t_max; without it, the frames decided before the step's triangles come back
// break it.
TEST(GovernorLoop, AStepOfThePlansWorkloadIsSeenInItsFirstFrame) {
  size_t over_told = 0, over_blind = 0;
  for (const bool hint : {true, false}) {
    GovernorLoopOptions options;
    options.governor.t_max_ms = 14.0;
    GovernorLoop loop(levels(), options);
    calibrate(loop, 50000.0);
    const LoopRun r = run(loop, 160, 14.0, step, 2, hint);
    size_t& over = hint ? over_told : over_blind;
    for (const auto& [level, ms, load] : r.frames) over += ms > 14.0;
    if (hint) {
      EXPECT_EQ(std::get<0>(r.frames[100]), kPixels.size() - 1);  // the coarsest, at once
    }
  }
  EXPECT_EQ(over_told, 0u);
  EXPECT_GE(over_blind, 1u);
}

TEST(GovernorLoop, BadUseIsAClearError) {
  GovernorLoopOptions options;
  options.governor.t_max_ms = 10.0;
  GovernorLoop loop(levels(), options);
  EXPECT_THROW(loop.decide(0), Error);         // before the calibration
  EXPECT_THROW(loop.finishCalibration(), Error);  // no sample
  EXPECT_THROW(loop.calibrationSample(9, 1.0, 1.0), Error);
  EXPECT_THROW(loop.calibrationSample(0, 1.0, -1.0), Error);
  std::vector<LoopLevel> no_pixels = levels();
  no_pixels[1].pixels = 0.0;
  EXPECT_THROW(GovernorLoop(no_pixels, options), Error);
  GovernorLoopOptions bad = options;
  bad.lag = 0;
  EXPECT_THROW(GovernorLoop(levels(), bad), Error);
  calibrate(loop, 1000.0);
  loop.decide(0);
  loop.frameMeasured(7, 1.0);  // never decided: ignored
  loop.frameTriangles(7, 1.0);
  EXPECT_EQ(loop.governor().statistics().frames, 1u);
}
