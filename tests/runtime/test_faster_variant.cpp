// The faster-variant chooser against a synthetic machine whose two variants' frame costs are known (with noise): it
// must keep the faster one, pay few frames of the slower one for its probes, follow a change of which is faster, keep
// what it has where the two are alike, and compare the two on the same stretch of a path whose frame time varies.
#include "farfield/runtime/faster_variant.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "farfield/core/error.h"

using namespace farfield;
using runtime::FasterVariant;
using runtime::FasterVariantOptions;

namespace {

// Frame costs: cost(frame, variant) in ms, times a uniform noise factor in [1 - noise, 1 + noise].
using Cost = std::function<double(uint64_t frame, int variant)>;

// Drives the chooser over `frames` frames, each measured `lag` frames after it is decided (0: at once); returns the
// variant of every frame. Frames in `unmeasured` are never measured. room(f): whether frame f has room for a probe
// (empty: every frame has).
std::vector<int> drive(FasterVariant& chooser, uint64_t frames, const Cost& cost, double noise, size_t lag = 0,
                       uint64_t unmeasured = 0, uint32_t seed = 7, const std::function<bool(uint64_t)>& room = {}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(1.0 - noise, 1.0 + noise);
  std::vector<int> variants;
  std::deque<std::pair<uint64_t, double>> pending;
  for (uint64_t f = 0; f < frames; ++f) {
    const int v = chooser.decide(f, !room || room(f));
    variants.push_back(v);
    if (f >= unmeasured) pending.push_back({f, cost(f, v) * jitter(rng)});
    while (pending.size() > lag) {
      chooser.measured(pending.front().first, pending.front().second);
      pending.pop_front();
    }
  }
  return variants;
}

size_t count(const std::vector<int>& variants, int v, size_t from = 0, size_t to = std::numeric_limits<size_t>::max()) {
  const auto end = variants.begin() + std::ptrdiff_t(std::min(to, variants.size()));
  const auto begin = variants.begin() + std::ptrdiff_t(std::min(from, variants.size()));
  return size_t(std::count(begin, end, v));
}

}  // namespace

TEST(FasterVariant, KeepsTheFasterVariantAfterOneProbe) {
  for (size_t lag : {0u, 3u}) {
    FasterVariant chooser(0);
    // Variant 1 is 35 % faster (occlusion culling off on llvmpipe over a region's visible set).
    const auto variants = drive(chooser, 2000, [](uint64_t, int v) { return v == 0 ? 10.0 : 6.5; }, 0.1, lag);
    EXPECT_EQ(chooser.kept(), 1) << "lag " << lag;
    EXPECT_EQ(chooser.switches(), 1u) << "lag " << lag;
    // The first probe: 4 measured frames of the first variant, then runs of two, the other's first.
    const std::vector<int> schedule{0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0, 1, 1};
    EXPECT_EQ(std::vector<int>(variants.begin() + std::ptrdiff_t(lag), variants.begin() + std::ptrdiff_t(lag + 20)),
              schedule)
        << "lag " << lag;
    // Then the faster one, the slower only in probes, which give up after two of its runs (plus the frames the lag
    // decided meanwhile), each probe after a doubled interval.
    EXPECT_EQ(std::count(variants.begin() + std::ptrdiff_t(20 + 2 * lag), variants.begin() + 120, 1),
              120 - std::ptrdiff_t(20 + 2 * lag))
        << "lag " << lag;
    EXPECT_LE(count(variants, 0, 20 + 2 * lag), (4 + lag) * (chooser.probes() - 1)) << "lag " << lag;
    EXPECT_LE(chooser.probes(), 6u) << "lag " << lag;
    EXPECT_EQ(chooser.probesGivenUp(), chooser.probes() - 1) << "lag " << lag;
  }
}

TEST(FasterVariant, KeepsTheFirstVariantWhenTheOtherIsNotFasterByTheMargin) {
  FasterVariant chooser(0);
  const auto variants = drive(chooser, 3000, [](uint64_t, int v) { return v == 0 ? 10.0 : 10.2; }, 0.03);
  EXPECT_EQ(chooser.kept(), 0);
  EXPECT_EQ(chooser.switches(), 0u);
  // Probes of the other variant, less and less often: 120, 240, 480, 960, 960 ... frames apart.
  EXPECT_GE(chooser.probes(), 4u);
  EXPECT_LE(chooser.probes(), 6u);
  EXPECT_EQ(chooser.probesGivenUp(), 0u);
  EXPECT_EQ(count(variants, 1), 8 * chooser.probes());
}

// Frame times that vary by 3x along the path (a view opening up, then closing), the same for both variants at each
// frame but for the other's 10 % advantage: the probe must see the variants, not the path. Its first probe starts at
// each phase of the path's swing in turn, rising and falling.
TEST(FasterVariant, ComparesLikeWithLikeWhereTheFrameTimeVariesAlongThePath) {
  size_t right = 0, phases = 0;
  for (double phase = 0.0; phase < 6.28; phase += 0.1, ++phases) {
    FasterVariant chooser(0);
    const Cost cost = [phase](uint64_t f, int v) {
      return (v == 1 ? 0.9 : 1.0) * (10.0 + 5.0 * std::sin(phase + double(f) * 0.06));
    };
    drive(chooser, 30, cost, 0.0);
    right += chooser.kept() == 1 ? 1 : 0;
  }
  EXPECT_EQ(right, phases);
}

TEST(FasterVariant, GivesUpAProbeOfAMuchSlowerVariantAfterTwoOfItsRuns) {
  FasterVariant chooser(0);
  const auto variants = drive(chooser, 2000, [](uint64_t, int v) { return v == 0 ? 5.0 : 15.0; }, 0.05);
  EXPECT_EQ(chooser.kept(), 0);
  EXPECT_EQ(chooser.probesGivenUp(), chooser.probes());
  EXPECT_EQ(count(variants, 1), 4 * chooser.probes());
}

TEST(FasterVariant, FollowsAChangeOfWhichVariantIsFaster) {
  FasterVariant chooser(0);
  // Variant 0 faster for 2000 frames, then variant 1 (the walk leaves the open streets for a dense old town).
  const Cost cost = [](uint64_t f, int v) { return (f < 2000) == (v == 0) ? 6.0 : 9.0; };
  const auto variants = drive(chooser, 4000, cost, 0.08);
  EXPECT_EQ(chooser.kept(), 1);
  EXPECT_EQ(chooser.switches(), 1u);
  // The kept variant's frames got 1.5x slower: a probe starts at once (after 4 of them) and switches.
  EXPECT_EQ(chooser.earlyProbes(), 1u);
  size_t switched = 2000;
  while (switched < variants.size() && variants[switched] == 0) ++switched;
  EXPECT_LE(switched, 2000u + 5u);
  EXPECT_EQ(count(variants, 0, 2000 + 30) % 4, 0u);  // then given-up probes of the slower, two runs each
  EXPECT_LE(count(variants, 0, 2000 + 30), 4u * 6u);
  EXPECT_EQ(count(variants, 1, switched + 20, switched + 120), 100u);  // the next probe is 120 frames later
}

// Both variants 1.5x slower from frame 1000 on (a heavier stretch of the path): one early probe, which keeps the
// choice, and no other (the level is taken again at its decision).
TEST(FasterVariant, AChangeOfTheWorkloadProbesOnceAndKeepsAChoiceThatStillHolds) {
  FasterVariant chooser(0);
  const Cost cost = [](uint64_t f, int v) { return (f < 1000 ? 6.0 : 9.0) * (v == 0 ? 1.0 : 1.4); };
  const auto variants = drive(chooser, 1500, cost, 0.05);
  EXPECT_EQ(chooser.earlyProbes(), 1u);
  EXPECT_EQ(chooser.switches(), 0u);
  EXPECT_EQ(chooser.kept(), 0);
  // The early probe: two runs of the other (1.4x slower: given up), within a few frames of the change.
  EXPECT_EQ(count(variants, 1, 1000, 1030), 4u);
  EXPECT_EQ(variants[1003], 1);
}

TEST(FasterVariant, ProbesNothingBeforeFramesOfTheFirstVariantAreMeasured) {
  FasterVariant chooser(1);
  // A host's untimed first draws (a governor's calibration): 50 frames never measured.
  const auto variants = drive(chooser, 80, [](uint64_t, int v) { return v == 1 ? 10.0 : 5.0; }, 0.0, 0, 50);
  EXPECT_EQ(count(variants, 1, 0, 54), 54u);
  EXPECT_EQ(chooser.kept(), 0);  // then measured: 4 frames of the first, and a probe finds the other faster
}

TEST(FasterVariant, GivesUpAProbeWhoseFramesAreNeverMeasured) {
  FasterVariantOptions options;
  options.max_in_flight = 16;
  FasterVariant chooser(0, options);
  for (uint64_t f = 0; f < 4; ++f) {
    EXPECT_EQ(chooser.decide(f), 0);
    chooser.measured(f, 5.0);
  }
  // A probe whose host stopped measuring: its schedule, then the kept variant.
  std::vector<int> variants;
  for (uint64_t f = 4; f < 44; ++f) variants.push_back(chooser.decide(f));
  EXPECT_EQ(std::vector<int>(variants.begin(), variants.begin() + 16),
            (std::vector<int>{1, 1, 0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0, 0, 1, 1}));
  EXPECT_EQ(std::count(variants.begin() + 16, variants.end(), 0), 24);
  EXPECT_EQ(chooser.probes(), 1u);
  EXPECT_EQ(chooser.probesGivenUp(), 1u);
  EXPECT_EQ(chooser.kept(), 0);
}

// A host's timing of both variants (a governor's calibration) starts the chooser: on the faster one where it is
// faster by the margin, with the next probe `reprobe_after` frames later.
TEST(FasterVariant, StartsFromAHostsTimingOfBothVariants) {
  FasterVariant faster(0);
  for (uint64_t f = 0; f < 8; ++f) EXPECT_EQ(faster.decide(f), 0);  // untimed draws
  faster.startFrom(10.0, 6.0);
  EXPECT_EQ(faster.kept(), 1);
  EXPECT_EQ(faster.starts(), 1u);
  // Measured frames twice as slow as the host's times (taken otherwise): no change of the workload is seen in that.
  std::vector<int> after;
  for (uint64_t f = 8; f < 7 + 120; ++f) {
    after.push_back(faster.decide(f));
    faster.measured(f, after.back() == 0 ? 20.0 : 12.0);
  }
  EXPECT_EQ(std::count(after.begin(), after.end(), 1), 119);  // no probe before 120 frames after the start
  EXPECT_EQ(faster.probes(), 0u);
  EXPECT_EQ(faster.decide(7 + 120), 0);  // then the first probe's run of the other

  FasterVariant alike(0);
  alike.startFrom(10.0, 9.8);  // within the margin: the first variant stays
  EXPECT_EQ(alike.kept(), 0);
  EXPECT_THROW(alike.startFrom(-1.0, 2.0), Error);
  EXPECT_THROW(alike.startFrom(1.0, std::nan("")), Error);
}

// A host without room for the other variant in a frame (a governor near its budget): no probe starts there, one due
// starts at the first frame with room, and one under way is given up at a frame without room.
TEST(FasterVariant, AFrameWithoutRoomDrawsNoProbe) {
  const Cost cost = [](uint64_t, int v) { return v == 0 ? 10.0 : 6.5; };
  {
    FasterVariant chooser(0);
    const auto variants = drive(chooser, 600, cost, 0.1, 0, 0, 7, [](uint64_t f) { return f >= 300; });
    EXPECT_EQ(count(variants, 1, 0, 300), 0u);
    EXPECT_EQ(variants[300], 1);  // the probe due since frame 4, at the first frame with room
    EXPECT_EQ(variants[301], 1);
    EXPECT_EQ(chooser.kept(), 1);
    EXPECT_EQ(chooser.probesHeld(), 0u);
  }
  {
    FasterVariant chooser(0);
    const auto variants = drive(chooser, 600, cost, 0.1, 0, 0, 7, [](uint64_t f) { return f != 6; });
    EXPECT_EQ(variants[4], 1);  // the first probe's first run
    EXPECT_EQ(variants[6], 0);  // given up at the frame without room
    EXPECT_EQ(chooser.probesHeld(), 1u);
    EXPECT_EQ(count(variants, 1, 6, 126), 0u);  // the next probe after the interval
    EXPECT_EQ(variants[126], 1);
    EXPECT_EQ(chooser.kept(), 1);
  }
}

TEST(FasterVariant, RejectsBadOptionsOrderAndTimes) {
  EXPECT_THROW(FasterVariant(2), Error);
  const std::vector<std::function<void(FasterVariantOptions&)>> spoil{
      [](FasterVariantOptions& o) { o.margin = 1.0; },
      [](FasterVariantOptions& o) { o.give_up_ratio = 1.0; },
      [](FasterVariantOptions& o) { o.reprobe_max = o.reprobe_after - 1; },
      [](FasterVariantOptions& o) { o.change_ratio = 1.0; },
      [](FasterVariantOptions& o) { o.min_kept = 9; },
      [](FasterVariantOptions& o) { o.max_in_flight = 4 * o.probe_runs - 1; },
  };
  for (size_t i = 0; i < spoil.size(); ++i) {
    FasterVariantOptions bad;
    spoil[i](bad);
    EXPECT_THROW(FasterVariant(0, bad), Error) << "bad option " << i;
  }
  FasterVariant chooser(0);
  chooser.decide(5);
  EXPECT_THROW(chooser.decide(5), Error);
  EXPECT_THROW(chooser.measured(5, std::nan("")), Error);
  EXPECT_THROW(chooser.measured(5, -1.0), Error);
  chooser.measured(99, 1.0);  // never decided: ignored
  EXPECT_EQ(chooser.probes(), 0u);
}
