// The frame governor against simulated frame costs: a frame's true cost is a load times its level's cost factor,
// with noise; the model the governor is given predicts a biased load (too optimistic, or blind to a part of the
// load); measured times come back two frames late, as GPU timer queries do. The governor must keep every frame under
// t_max once it has measured one over it, and must not oscillate under a constant load.
#include "farfield/runtime/frame_governor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "farfield/core/error.h"

using namespace farfield;
using runtime::FrameGovernor;
using runtime::GovernorLevel;
using runtime::GovernorOptions;

namespace {

const std::vector<double> kFactors{1.0, 0.7, 0.5, 0.35, 0.25};

std::vector<GovernorLevel> levels() {
  std::vector<GovernorLevel> out;
  for (size_t i = 0; i < kFactors.size(); ++i) out.push_back({"level " + std::to_string(i), 1.0 + double(i)});
  return out;
}

struct SimFrame {
  size_t level = 0;
  double cost_ms = 0.0;
  bool relaxed = false;
};

struct Simulation {
  std::vector<SimFrame> frames;
  size_t first_over_measured = SIZE_MAX;  // the frame at which the first over-budget measurement arrived
  FrameGovernor::Statistics stats;

  // Frames after the first over-budget measurement arrived that were over t_max.
  size_t overAfterFirstMeasurement(double t_max) const {
    size_t n = 0;
    for (size_t f = first_over_measured == SIZE_MAX ? frames.size() : first_over_measured; f < frames.size(); ++f)
      n += frames[f].cost_ms > t_max;
    return n;
  }
  size_t levelChanges(size_t from) const {
    size_t n = 0;
    for (size_t f = from + 1; f < frames.size(); ++f) n += frames[f].level != frames[f - 1].level;
    return n;
  }
};

// true_load(f): the load of frame f at level 0 (ms); model_load(f): what the model predicts of it; noise: relative,
// uniform in [-noise, noise]; measurements arrive `lag` frames late.
Simulation simulate(size_t frames, double t_max, const std::function<double(size_t)>& true_load,
                    const std::function<double(size_t)>& model_load, double noise, size_t lag = 2,
                    GovernorOptions options = {}) {
  options.t_max_ms = t_max;
  FrameGovernor governor(levels(), options);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-noise, noise);
  Simulation sim;
  std::deque<std::pair<uint64_t, double>> in_flight;
  for (size_t f = 0; f < frames; ++f) {
    while (!in_flight.empty() && in_flight.front().first + lag <= f) {
      if (in_flight.front().second > t_max && sim.first_over_measured == SIZE_MAX) sim.first_over_measured = f;
      governor.measured(in_flight.front().first, in_flight.front().second);
      in_flight.pop_front();
    }
    std::vector<double> predicted;
    for (double factor : kFactors) predicted.push_back(model_load(f) * factor);
    const runtime::GovernorDecision d = governor.decide(f, predicted);
    EXPECT_EQ(d.relaxed, d.level > 0);
    EXPECT_DOUBLE_EQ(d.bound_scale, 1.0 + double(d.level));
    const double cost = true_load(f) * kFactors[d.level] * (1.0 + jitter(rng));
    sim.frames.push_back({d.level, cost, d.relaxed});
    in_flight.emplace_back(f, cost);
  }
  sim.stats = governor.statistics();
  return sim;
}

}  // namespace

TEST(FrameGovernor, AStepTheModelDoesNotSeeBreaksTmaxOnlyUntilItIsMeasured) {
  const double t_max = 10.0;
  // 8 ms, then 16 ms from frame 100 on; the model sees a constant 5 ms (blind to the step, and optimistic).
  const Simulation sim = simulate(
      300, t_max, [](size_t f) { return f < 100 ? 8.0 : 16.0; }, [](size_t) { return 5.0; }, 0.04);
  ASSERT_NE(sim.first_over_measured, SIZE_MAX);  // the step did break t_max once ...
  EXPECT_LE(sim.first_over_measured, 100u + 2u);
  EXPECT_EQ(sim.overAfterFirstMeasurement(t_max), 0u);  // ... and never again after it was measured
  for (size_t f = 0; f < 100; ++f) EXPECT_EQ(sim.frames[f].level, 0u) << f;  // 8 ms fits: the full level
  EXPECT_GT(sim.frames.back().level, 0u);
  EXPECT_GT(sim.stats.relaxed_frames, 0u);
  EXPECT_EQ(sim.stats.coarsenings, 1u);  // one move, straight to a level that fits
}

TEST(FrameGovernor, AStepTheModelSeesIsCoarsenedBeforeAnyFrameBreaksTmax) {
  const double t_max = 10.0;
  // The model is 40% optimistic but sees the step: after the first measurements the correction holds, and the
  // step's frames are coarsened before they are drawn.
  const Simulation sim = simulate(
      300, t_max, [](size_t f) { return f < 100 ? 8.0 : 16.0; },
      [](size_t f) { return (f < 100 ? 8.0 : 16.0) * 0.6; }, 0.04);
  for (size_t f = 10; f < sim.frames.size(); ++f) EXPECT_LE(sim.frames[f].cost_ms, t_max) << f;
  EXPECT_EQ(sim.frames[100].level, 2u);  // 16 x 0.5 = 8 ms <= 0.9 t_max, 16 x 0.7 over it
}

TEST(FrameGovernor, ARampIsFollowedWithoutAFrameOverBudget) {
  const double t_max = 10.0;
  auto load = [](size_t f) { return 6.0 + 24.0 * double(f) / 400.0; };  // 6 -> 30 ms
  const Simulation sim = simulate(400, t_max, load, [&](size_t f) { return load(f) * 0.7; }, 0.03);
  EXPECT_EQ(sim.overAfterFirstMeasurement(t_max), 0u);
  size_t over = 0;
  for (size_t f = 5; f < sim.frames.size(); ++f) over += sim.frames[f].cost_ms > t_max;
  EXPECT_EQ(over, 0u);
  for (size_t f = 1; f < sim.frames.size(); ++f) EXPECT_GE(sim.frames[f].level, sim.frames[f - 1].level) << f;
  EXPECT_EQ(sim.frames.back().level, kFactors.size() - 1);  // 30 x 0.25 = 7.5 ms: the coarsest fits
}

TEST(FrameGovernor, AConstantLoadNearTheThresholdDoesNotOscillate) {
  const double t_max = 10.0;
  // 9.3 ms with 5% noise: about the aim (0.9 t_max); the model is right on average.
  const Simulation sim = simulate(600, t_max, [](size_t) { return 9.3; }, [](size_t) { return 9.3; }, 0.05);
  EXPECT_LE(sim.levelChanges(50), 1u);
  EXPECT_EQ(sim.overAfterFirstMeasurement(t_max), 0u);
}

TEST(FrameGovernor, RefinesBackWhenTheLoadFallsAndOnlyThen) {
  const double t_max = 10.0;
  auto load = [](size_t f) { return f < 100 ? 20.0 : 5.0; };
  const Simulation sim = simulate(300, t_max, load, load, 0.02);
  EXPECT_GE(sim.frames[99].level, 2u);  // 20 ms needs 0.35 or 0.25
  EXPECT_EQ(sim.frames.back().level, 0u);  // 5 ms fits at the full level again ...
  EXPECT_GT(sim.stats.refinements, 0u);
  // ... one level at a time, each after refine_after (10) frames under refine_below.
  for (size_t f = 101; f < sim.frames.size(); ++f) {
    EXPECT_LE(sim.frames[f].level, sim.frames[f - 1].level) << f;
    EXPECT_LE(sim.frames[f - 1].level, sim.frames[f].level + 1) << f;
  }
  size_t first_full = 0;
  for (size_t f = 100; f < sim.frames.size() && !first_full; ++f)
    if (sim.frames[f].level == 0) first_full = f;
  EXPECT_GE(first_full, 99u + 10u * sim.frames[99].level);
  EXPECT_EQ(sim.overAfterFirstMeasurement(t_max), 0u);
}

TEST(FrameGovernor, ColdFramesExpectTheModelTimesTheColdRatioUntilAFrameIsMeasured) {
  const double t_max = 10.0;
  // A constant 11 ms that the model puts at 8 ms (1.375x optimistic): trusted, the model puts the first frames
  // (before the first measurement, two frames late) at the full level and they break t_max; with a cold ratio of 1.5
  // they are coarsened before they are drawn, and no frame breaks it.
  const auto load = [](size_t) { return 11.0; };
  const auto model = [](size_t) { return 8.0; };
  const Simulation trusted = simulate(40, t_max, load, model, 0.0);
  EXPECT_EQ(trusted.frames[0].level, 0u);
  EXPECT_GT(trusted.frames[0].cost_ms, t_max);
  GovernorOptions cold;
  cold.cold_ratio = 1.5;
  const Simulation sim = simulate(40, t_max, load, model, 0.0, 2, cold);
  EXPECT_EQ(sim.frames[0].level, 1u);  // 8 x 1.5 = 12 > 9; 8 x 0.7 x 1.5 = 8.4 fits
  for (const SimFrame& f : sim.frames) EXPECT_LE(f.cost_ms, t_max);
  EXPECT_EQ(sim.frames.back().level, 1u);  // measured: 11 ms at the full level stays over the aim
  FrameGovernor governor({{"full", 1.0}}, [&] {
    GovernorOptions o = cold;
    o.t_max_ms = t_max;
    return o;
  }());
  EXPECT_DOUBLE_EQ(governor.corrected(4.0), 6.0);
  const double p[1] = {4.0};
  governor.decide(0, p);
  governor.measured(0, 5.0);
  EXPECT_DOUBLE_EQ(governor.corrected(4.0), 5.0);  // the measured ratio 1.25, no longer the cold 1.5
  GovernorOptions bad = cold;
  bad.t_max_ms = t_max;
  bad.cold_ratio = 0.5;
  EXPECT_THROW(FrameGovernor({{"full", 1.0}}, bad), Error);
}

TEST(FrameGovernor, TheCorrectionIsTheSmallerOfTheWorstRatioAndTheWorstDifference) {
  GovernorOptions options;
  options.t_max_ms = 100.0;
  FrameGovernor governor({{"full", 1.0}}, options);
  EXPECT_DOUBLE_EQ(governor.corrected(4.0), 4.0);  // no measurement: the model
  const double p[1] = {2.0};
  governor.decide(0, p);
  governor.measured(0, 4.0);  // ratio 2, difference 2
  const double q[1] = {10.0};
  governor.decide(1, q);
  governor.measured(1, 13.0);  // ratio 1.3, difference 3
  EXPECT_DOUBLE_EQ(governor.corrected(1.0), 2.0);    // min(1 x 2, 1 + 3)
  EXPECT_DOUBLE_EQ(governor.corrected(10.0), 13.0);  // min(10 x 2, 10 + 3)
  governor.measured(1, 50.0);  // already measured: ignored
  governor.measured(7, 50.0);  // never decided: ignored
  EXPECT_EQ(governor.statistics().ignored_measurements, 2u);
  EXPECT_EQ(governor.statistics().measurements, 2u);
}

TEST(FrameGovernor, BadInputIsAClearError) {
  GovernorOptions options;
  EXPECT_THROW(FrameGovernor({{"full", 1.0}}, options), Error);  // no t_max
  options.t_max_ms = 10.0;
  EXPECT_THROW(FrameGovernor({}, options), Error);
  EXPECT_THROW(FrameGovernor({{"finer than promised", 0.5}}, options), Error);
  GovernorOptions bad = options;
  bad.refine_below = 0.95;  // above aim
  EXPECT_THROW(FrameGovernor({{"full", 1.0}}, bad), Error);
  FrameGovernor governor({{"full", 1.0}, {"half", 2.0}}, options);
  const double one[1] = {1.0};
  EXPECT_THROW(governor.decide(0, one), Error);
  const double nan[2] = {1.0, std::nan("")};
  EXPECT_THROW(governor.decide(0, nan), Error);
  const double ok[2] = {1.0, 0.5};
  governor.decide(3, ok);
  EXPECT_THROW(governor.decide(3, ok), Error);  // frames must increase
  EXPECT_THROW(governor.measured(3, -1.0), Error);
}
