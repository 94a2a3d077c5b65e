// runtime/regeneration_scheduler.h against an exhaustive check of its rule: the prediction is the sum of what was
// chosen, never above t_max when the all-geometry frame was not, and every skipped request that is more invalid
// than a chosen one did not fit when its turn came.
#include "farfield/runtime/regeneration_scheduler.h"

#include <algorithm>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace farfield::runtime {
namespace {

// Brute-force replay helpers: requests in decreasing error ratio (stable), and the pay-back rule written out.
std::vector<size_t> mostInvalidFirst(const std::vector<RegenerationRequest>& req) {
  std::vector<size_t> order(req.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return req[a].error_ratio > req[b].error_ratio; });
  return order;
}

bool paysBack(const RegenerationRequest& r) {
  return r.regenerate_ms + r.image_ms - r.geometry_ms <= r.expected_reuse * (r.geometry_ms - r.image_ms);
}

TEST(RegenerationScheduler, MostInvalidFirstUnderTheBudget) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<RegenerationRequest> req(1 + trial % 20);
    for (size_t i = 0; i < req.size(); ++i) {
      req[i].node = uint32_t(i);
      req[i].error_ratio = i % 7 == 3 ? std::numeric_limits<double>::infinity() : 1.0 + 5 * u(rng);
      req[i].geometry_ms = 3 * u(rng);
      req[i].regenerate_ms = req[i].geometry_ms + 0.2 + u(rng);
      req[i].image_ms = 0.05;
    }
    const double base = 2.0;
    double all_geometry = base;
    for (const auto& r : req) all_geometry += r.geometry_ms;
    const double t_max = all_geometry + 4 * u(rng);
    const int cap = trial % 3 == 0 ? 2 : 100;
    const RegenerationSchedule s = scheduleRegenerations(req, base, t_max, cap);
    EXPECT_EQ(s.regenerate.size() + s.geometry.size(), req.size());
    EXPECT_LE(int(s.regenerate.size()), cap);
    double predicted = all_geometry;
    for (const uint32_t n : s.regenerate) predicted += req[n].regenerate_ms + req[n].image_ms - req[n].geometry_ms;
    EXPECT_NEAR(s.predicted_ms, predicted, 1e-9);
    EXPECT_LE(s.predicted_ms, t_max + 1e-9);
    // Replay in priority order: a skipped request did not fit at its turn (or the cap was reached).
    const std::vector<size_t> order = mostInvalidFirst(req);
    double running = all_geometry;
    size_t next = 0;
    for (const size_t i : order) {
      const double delta = req[i].regenerate_ms + req[i].image_ms - req[i].geometry_ms;
      const bool taken = next < s.regenerate.size() && s.regenerate[next] == req[i].node;
      if (taken) {
        running += delta;
        ++next;
      } else {
        EXPECT_TRUE(running + delta > t_max || int(next) == cap) << "trial " << trial;
      }
    }
    EXPECT_EQ(next, s.regenerate.size());
  }
}

TEST(RegenerationScheduler, NoBudgetRegeneratesUpToTheCount) {
  std::vector<RegenerationRequest> req(5);
  for (size_t i = 0; i < req.size(); ++i) req[i] = {uint32_t(i), double(i) + 2, 10.0, 1.0, 0.0};
  const RegenerationSchedule s = scheduleRegenerations(req, 0.0, 0.0, 3);
  EXPECT_EQ(s.regenerate, (std::vector<uint32_t>{4, 3, 2}));
  EXPECT_EQ(s.geometry, (std::vector<uint32_t>{1, 0}));
}

// A lost frame (all geometry already over t_max): without an investment it regenerates nothing; with one it takes,
// most invalid first, exactly the requests that pay back over their expected reuse and fit the investment (replayed
// here by brute force), and never more than the all-geometry prediction + the investment.
TEST(RegenerationScheduler, ALostFrameInvestsInImagesThatPayBackOverTheirReuse) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  size_t invested = 0, refused_payback = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<RegenerationRequest> req(1 + trial % 15);
    for (size_t i = 0; i < req.size(); ++i) {
      req[i].node = uint32_t(i);
      req[i].error_ratio = 1.0 + 5 * u(rng);
      req[i].geometry_ms = 4 * u(rng);
      req[i].image_ms = 0.05;
      req[i].regenerate_ms = req[i].geometry_ms + 3 * u(rng);  // some pay back, some do not
      req[i].expected_reuse = i % 4 == 0 ? 0.0 : (i % 4 == 1 ? 1.0 : 2.5);
    }
    const double base = 10.0;
    double all_geometry = base;
    for (const auto& r : req) all_geometry += r.geometry_ms;
    const double t_max = all_geometry * (0.3 + 0.6 * u(rng));  // lost
    const RegenerationSchedule none = scheduleRegenerations(req, base, t_max, 100, 0.0);
    EXPECT_TRUE(none.lost);
    EXPECT_TRUE(none.regenerate.empty());
    EXPECT_NEAR(none.predicted_ms, all_geometry, 1e-9);

    const double invest = t_max * u(rng);
    const RegenerationSchedule s = scheduleRegenerations(req, base, t_max, 100, invest);
    EXPECT_TRUE(s.lost);
    EXPECT_LE(s.predicted_ms, all_geometry + invest + 1e-9);
    const std::vector<size_t> order = mostInvalidFirst(req);
    std::vector<uint32_t> want;
    double running = all_geometry;
    for (const size_t i : order) {
      const double delta = req[i].regenerate_ms + req[i].image_ms - req[i].geometry_ms;
      const bool pays = paysBack(req[i]);
      EXPECT_FALSE(req[i].expected_reuse == 0.0 && std::count(s.regenerate.begin(), s.regenerate.end(), req[i].node))
          << "an image that was not reused is no investment";
      refused_payback += !pays;
      if (!pays || running + delta > all_geometry + invest) continue;
      running += delta;
      want.push_back(req[i].node);
    }
    EXPECT_EQ(s.regenerate, want) << "trial " << trial;
    EXPECT_NEAR(s.predicted_ms, running, 1e-9);
    invested += s.regenerate.size();
  }
  EXPECT_GT(invested, 100u);  // not vacuous: both kinds of request occur
  EXPECT_GT(refused_payback, 100u);

  // A frame that is not lost keeps the plain rule, investment or not.
  std::vector<RegenerationRequest> req(3);
  for (size_t i = 0; i < req.size(); ++i) req[i] = {uint32_t(i), double(i) + 2, 2.0, 0.1, 1.0, 1.0};
  const RegenerationSchedule fits = scheduleRegenerations(req, 1.0, 6.0, 10, 100.0);
  EXPECT_FALSE(fits.lost);
  EXPECT_NEAR(fits.predicted_ms, 4.0 + 1.1, 1e-9);  // a second regeneration (+1.1) would pass 6
  EXPECT_EQ(fits.regenerate, (std::vector<uint32_t>{2}));
}

// With pay_back every frame takes, most invalid first, exactly the requests that pay for themselves over their
// expected reuse and fit t_max (a brute-force replay); without it the same frames take more, some of them images
// that cost more than the geometry they replace.
TEST(RegenerationScheduler, PayBackTakesOnlyImagesThatPayForThemselves) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  size_t taken = 0, refused = 0, taken_without = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<RegenerationRequest> req(1 + trial % 12);
    for (size_t i = 0; i < req.size(); ++i) {
      req[i].node = uint32_t(i);
      req[i].error_ratio = 1.0 + 5 * u(rng);
      req[i].geometry_ms = 4 * u(rng);
      req[i].image_ms = 0.05;
      req[i].regenerate_ms = req[i].geometry_ms + 3 * u(rng);
      req[i].expected_reuse = 3 * u(rng);
    }
    const double base = 2.0;
    double all_geometry = base;
    for (const auto& r : req) all_geometry += r.geometry_ms;
    const double t_max = all_geometry * (1.0 + 2 * u(rng));  // not lost
    const RegenerationSchedule s = scheduleRegenerations(req, base, t_max, 100, 1.0, true);
    EXPECT_FALSE(s.lost);
    const std::vector<size_t> order = mostInvalidFirst(req);
    std::vector<uint32_t> want;
    double running = all_geometry;
    for (const size_t i : order) {
      const double delta = req[i].regenerate_ms + req[i].image_ms - req[i].geometry_ms;
      if (!paysBack(req[i])) {
        ++refused;
        continue;
      }
      if (running + delta > t_max) continue;
      running += delta;
      want.push_back(req[i].node);
    }
    EXPECT_EQ(s.regenerate, want) << "trial " << trial;
    EXPECT_NEAR(s.predicted_ms, running, 1e-9);
    EXPECT_LE(s.predicted_ms, t_max + 1e-9);
    taken += s.regenerate.size();
    taken_without += scheduleRegenerations(req, base, t_max, 100, 1.0, false).regenerate.size();
  }
  EXPECT_GT(taken, 100u);  // not vacuous
  EXPECT_GT(refused, 100u);
  EXPECT_GT(taken_without, taken);
}

}  // namespace
}  // namespace farfield::runtime
