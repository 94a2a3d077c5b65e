#include "farfield/placement/greedy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "farfield/core/error.h"

using namespace farfield;
using namespace farfield::placement;

namespace {

bool ancestorOf(const std::vector<int>& parent, int a, int b) {
  for (int at = parent[size_t(b)]; at >= 0; at = parent[size_t(at)])
    if (at == a) return true;
  return false;
}

// A random instance whose estimates are consistent: a node's time in a CPV is the sum of its own part and its
// children's times, and an impostor costs a fraction of the geometry it replaces.
GreedyProblem randomProblem(uint32_t seed, size_t n_cpvs = 30, size_t n_candidates = 80) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  GreedyProblem p;
  p.t_max = 1.0;
  const int n_nodes = 15;
  p.node_parent.push_back(-1);
  for (int n = 1; n < n_nodes; ++n) p.node_parent.push_back(int(rng() % uint32_t(n)));
  std::vector<std::vector<double>> own(static_cast<size_t>(n_nodes), std::vector<double>(n_cpvs));
  for (auto& row : own)
    for (double& t : row) t = 0.25 * uni(rng);
  std::vector<std::vector<double>> subtree = own;
  for (int n = n_nodes - 1; n > 0; --n)  // parents have lower indices
    for (size_t c = 0; c < n_cpvs; ++c) subtree[size_t(p.node_parent[size_t(n)])][c] += subtree[size_t(n)][c];
  for (size_t c = 0; c < n_cpvs; ++c) p.cpv_times.push_back(subtree[0][c] * (0.3 + 0.8 * uni(rng)) + 0.5);
  for (size_t i = 0; i < n_candidates; ++i) {
    GreedyCandidate cand;
    cand.node = int(rng() % uint32_t(n_nodes));
    cand.memory = 1.0 + 9.0 * uni(rng);
    for (uint32_t c = 0; c < n_cpvs; ++c)
      if (uni(rng) < 0.3) {
        const double t_o = subtree[size_t(cand.node)][c];
        cand.serves.push_back({c, t_o, t_o * 0.4 * uni(rng)});
      }
    p.candidates.push_back(cand);
  }
  return p;
}

// Score of a candidate against a final state, written from the paper's definitions independently of greedy.cpp.
double independentScore(const GreedyProblem& p, const GreedyResult& r, size_t i) {
  const GreedyCandidate& cand = p.candidates[i];
  double sum = 0.0;
  for (const GreedyServe& s : cand.serves) {
    double cost = s.t_object;
    bool blocked = false;
    for (uint32_t k : r.cpv_impostors[s.cpv]) {
      const GreedyCandidate& shown = p.candidates[r.impostors[k].candidate];
      if (shown.node == cand.node || ancestorOf(p.node_parent, shown.node, cand.node)) blocked = true;
      if (ancestorOf(p.node_parent, cand.node, shown.node))
        for (const GreedyServe& e : shown.serves)
          if (e.cpv == s.cpv) cost -= e.t_object - e.t_impostor;
    }
    if (blocked) continue;
    const double t_i = r.cpv_times[s.cpv] - (cost - s.t_impostor);
    sum += std::max(0.0, r.cpv_times[s.cpv] - std::max(t_i, p.t_max));
  }
  return sum / cand.memory;
}

}  // namespace

TEST(Greedy, HandInstanceReplacesChildByParent) {
  GreedyProblem p;
  p.t_max = 1.0;
  p.cpv_times = {10.0};
  p.node_parent = {-1, 0};
  // A (node 1): saves 2.9 for memory 1 -> score 2.9. B (root): saves 9 for memory 10 -> score 0.9.
  p.candidates.push_back({1, 1.0, {{0, 3.0, 0.1}}});
  p.candidates.push_back({0, 10.0, {{0, 9.5, 0.5}}});
  const GreedyResult r = placeGreedy(p, estimatesAsGenerated(p));
  // A first (t = 7.1); then B with A's saving counted: cost 9.5 - 2.9 = 6.6, saves 6.1 -> t = 1.0, solved.
  ASSERT_EQ(r.impostors.size(), 1u);
  EXPECT_EQ(r.impostors[0].candidate, 1u);
  EXPECT_DOUBLE_EQ(r.memory, 10.0);
  EXPECT_NEAR(r.cpv_times[0], 1.0, 1e-12);
  EXPECT_TRUE(r.unsolved.empty());
  EXPECT_EQ(r.counters.choices, 2u);
  EXPECT_EQ(r.counters.replacements, 1u);
  EXPECT_EQ(r.counters.freed, 1u);
  EXPECT_EQ(r.cpv_impostors[0], std::vector<uint32_t>{0});
}

TEST(Greedy, ReductionBelowTmaxIsWorthNothing) {
  // Both solve the CPV; the cheaper one (less saving, less memory) wins because savings are clipped at t_max.
  GreedyProblem p;
  p.t_max = 1.0;
  p.cpv_times = {2.0};
  p.node_parent = {-1, -1};
  p.candidates.push_back({0, 4.0, {{0, 1.9, 0.0}}});  // saves 1.9, clipped to 1.0 -> 0.25
  p.candidates.push_back({1, 2.0, {{0, 1.1, 0.0}}});  // saves 1.1, clipped to 1.0 -> 0.5
  const GreedyResult r = placeGreedy(p, estimatesAsGenerated(p));
  ASSERT_EQ(r.impostors.size(), 1u);
  EXPECT_EQ(r.impostors[0].candidate, 1u);
  EXPECT_EQ(r.counters.choices, 1u);
}

TEST(Greedy, ParentShownBlocksChildAndSlowImpostorIsFreed) {
  GreedyProblem p;
  p.t_max = 1.0;
  p.cpv_times = {5.0, 5.0};
  p.node_parent = {-1, 0, -1};
  p.candidates.push_back({0, 1.0, {{0, 4.5, 0.0}}});            // root, solves CPV 0
  p.candidates.push_back({1, 1.0, {{0, 2.0, 0.0}}});            // its child, same CPV: blocked after the root
  p.candidates.push_back({2, 0.5, {{1, 3.0, 0.5}}});            // generated slower than estimated: never shown
  const GenerateImpostor generate = [&](size_t i) {
    GeneratedImpostor g{p.candidates[i].memory, {}};
    if (i == 2) g.t_impostor = {3.5};
    return g;
  };
  const GreedyResult r = placeGreedy(p, generate);
  ASSERT_EQ(r.impostors.size(), 1u);
  EXPECT_EQ(r.impostors[0].candidate, 0u);
  EXPECT_EQ(r.counters.choices, 2u);  // candidate 2 was generated, candidate 1 never
  EXPECT_EQ(r.counters.freed, 1u);
  EXPECT_EQ(r.unsolved, std::vector<uint32_t>{1});
  EXPECT_DOUBLE_EQ(r.cpv_times[1], 5.0);
  EXPECT_DOUBLE_EQ(r.memory, 1.0);
}

TEST(Greedy, LazyAndFullRecalculationChooseTheSame) {
  size_t lazy_recalcs = 0, full_recalcs = 0, chosen = 0;
  for (uint32_t seed = 0; seed < 150; ++seed) {
    const GreedyProblem p = randomProblem(seed);
    std::vector<size_t> lazy_order, full_order;
    const GreedyResult lazy = placeGreedy(p, [&](size_t i) {
      lazy_order.push_back(i);
      return GeneratedImpostor{p.candidates[i].memory, {}};
    });
    const GreedyResult full = placeGreedy(
        p,
        [&](size_t i) {
          full_order.push_back(i);
          return GeneratedImpostor{p.candidates[i].memory, {}};
        },
        {.full_recalculation = true});
    ASSERT_EQ(lazy_order, full_order) << "seed " << seed;
    ASSERT_EQ(lazy.impostors.size(), full.impostors.size());
    for (size_t k = 0; k < lazy.impostors.size(); ++k) EXPECT_EQ(lazy.impostors[k].candidate, full.impostors[k].candidate);
    EXPECT_EQ(lazy.cpv_times, full.cpv_times);
    EXPECT_EQ(lazy.memory, full.memory);
    lazy_recalcs += lazy.counters.recalculations;
    full_recalcs += full.counters.recalculations;
    chosen += lazy_order.size();
  }
  EXPECT_GT(chosen, 300u);  // the instances make greedy work
  EXPECT_LT(lazy_recalcs * 3, full_recalcs);
}

// The final state checked from the definitions: no nested or repeated impostors in a CPV, times equal to the start
// time minus the savings of what is shown, memory the sum over kept impostors, each kept impostor shown somewhere,
// unsolved exactly the CPVs over t_max, and no candidate left that would still help (greedy ran to the end).
TEST(Greedy, FinalStateAgreesWithIndependentRecount) {
  for (uint32_t seed = 100; seed < 200; ++seed) {
    const GreedyProblem p = randomProblem(seed);
    const GreedyResult r = placeGreedy(p, estimatesAsGenerated(p));
    double memory = 0.0;
    std::set<size_t> kept;
    for (const ChosenImpostor& imp : r.impostors) {
      memory += imp.memory;
      EXPECT_FALSE(imp.cpvs.empty());
      EXPECT_TRUE(kept.insert(imp.candidate).second);
    }
    EXPECT_NEAR(r.memory, memory, 1e-9);
    for (uint32_t c = 0; c < p.cpv_times.size(); ++c) {
      double t = p.cpv_times[c];
      const auto& shown = r.cpv_impostors[c];
      for (size_t a = 0; a < shown.size(); ++a) {
        const GreedyCandidate& ca = p.candidates[r.impostors[shown[a]].candidate];
        for (size_t b = 0; b < shown.size(); ++b) {
          if (a == b) continue;
          const GreedyCandidate& cb = p.candidates[r.impostors[shown[b]].candidate];
          EXPECT_NE(ca.node, cb.node);
          EXPECT_FALSE(ancestorOf(p.node_parent, ca.node, cb.node)) << "seed " << seed << " cpv " << c;
        }
        for (const GreedyServe& s : ca.serves)
          if (s.cpv == c) t -= s.t_object - s.t_impostor;
      }
      EXPECT_NEAR(r.cpv_times[c], t, 1e-9) << "seed " << seed << " cpv " << c;
      const bool over = r.cpv_times[c] > p.t_max;
      EXPECT_EQ(over, std::find(r.unsolved.begin(), r.unsolved.end(), c) != r.unsolved.end());
    }
    for (size_t i = 0; i < p.candidates.size(); ++i)
      EXPECT_LE(independentScore(p, r, i), 1e-9) << "seed " << seed << " candidate " << i;
  }
}

namespace {

// Objects 1..8 under a root 0; every CPV sees all objects; for each object one candidate per pair of CPVs and one for
// all CPVs. Replacing all objects brings every CPV to 0.1 < t_max.
GreedyProblem constructedProblem(double t_max) {
  GreedyProblem p;
  p.t_max = t_max;
  const int n_objects = 8;
  p.node_parent.push_back(-1);
  for (int k = 0; k < n_objects; ++k) p.node_parent.push_back(0);
  const uint32_t n_cpvs = 20;
  for (uint32_t c = 0; c < n_cpvs; ++c) p.cpv_times.push_back(1.0 + 0.5 * c);
  const double t_imp = 0.1 / n_objects;
  for (int k = 1; k <= n_objects; ++k) {
    GreedyCandidate all{k, 50.0, {}};
    for (uint32_t c = 0; c < n_cpvs; ++c) {
      all.serves.push_back({c, p.cpv_times[c] / n_objects, t_imp});
      if (c % 2 == 0)
        p.candidates.push_back({k, 3.0, {{c, p.cpv_times[c] / n_objects, t_imp},
                                         {c + 1, (1.0 + 0.5 * (c + 1)) / n_objects, t_imp}}});
    }
    p.candidates.push_back(all);
  }
  return p;
}

}  // namespace

TEST(Greedy, EveryCpvOfAConstructedInstanceIsSolved) {
  for (double t_max : {0.5, 1.0, 3.0}) {
    const GreedyProblem p = constructedProblem(t_max);
    for (bool full : {false, true}) {
      const GreedyResult r = placeGreedy(p, estimatesAsGenerated(p), {.full_recalculation = full});
      EXPECT_TRUE(r.unsolved.empty()) << t_max;
      for (double t : r.cpv_times) EXPECT_LE(t, p.t_max);
      EXPECT_GT(r.memory, 0.0);
    }
  }
}

// Raising t_max should not need more memory. Greedy does not guarantee it: on the constructed instance it holds
// (checked strictly); on random instances memory sometimes rises by a step (a different early choice), so there only
// the overall trend is checked and the number of rises is printed.
TEST(Greedy, MemoryAgainstTmax) {
  double previous = -1.0;
  for (double t_max = 0.25; t_max <= 11.0; t_max += 0.25) {
    const GreedyProblem p = constructedProblem(t_max);
    const double memory = placeGreedy(p, estimatesAsGenerated(p)).memory;
    if (previous >= 0.0) {
      EXPECT_LE(memory, previous + 1e-9) << "t_max " << t_max;
    }
    previous = memory;
  }
  EXPECT_EQ(previous, 0.0);  // t_max above every CPV time: nothing to place

  int pairs = 0, rises = 0;
  double first_total = 0.0, last_total = 0.0;
  for (uint32_t seed = 300; seed < 340; ++seed) {
    GreedyProblem p = randomProblem(seed, 25, 60);
    double last = -1.0;
    for (double t_max = 0.6; t_max <= 2.6; t_max += 0.25) {
      p.t_max = t_max;
      const double memory = placeGreedy(p, estimatesAsGenerated(p)).memory;
      if (last >= 0.0) {
        ++pairs;
        if (memory > last + 1e-9) ++rises;
      } else {
        first_total += memory;
      }
      last = memory;
    }
    last_total += last;
  }
  std::printf("random instances: memory rose with t_max in %d of %d steps\n", rises, pairs);
  EXPECT_LT(last_total, 0.5 * first_total);
  EXPECT_LT(rises * 4, pairs);
}

TEST(Greedy, RejectsBadInput) {
  GreedyProblem good;
  good.t_max = 1.0;
  good.cpv_times = {2.0};
  good.node_parent = {-1};
  good.candidates.push_back({0, 1.0, {{0, 1.5, 0.1}}});
  EXPECT_NO_THROW(placeGreedy(good, estimatesAsGenerated(good)));
  auto bad = [&](auto edit) {
    GreedyProblem p = good;
    edit(p);
    EXPECT_THROW(placeGreedy(p, estimatesAsGenerated(p)), Error);
  };
  bad([](GreedyProblem& p) { p.t_max = 0.0; });
  bad([](GreedyProblem& p) { p.t_max = -1.0; });
  bad([](GreedyProblem& p) { p.cpv_times[0] = -1.0; });
  bad([](GreedyProblem& p) { p.candidates[0].memory = 0.0; });
  bad([](GreedyProblem& p) { p.candidates[0].node = 3; });
  bad([](GreedyProblem& p) { p.candidates[0].serves[0].cpv = 7; });
  bad([](GreedyProblem& p) { p.candidates[0].serves.push_back(p.candidates[0].serves[0]); });
  bad([](GreedyProblem& p) { p.candidates[0].serves[0].t_impostor = NAN; });
  bad([](GreedyProblem& p) { p.node_parent = {0}; });
  EXPECT_THROW(placeGreedy(good, GenerateImpostor{}), Error);
  EXPECT_THROW(placeGreedy(good, [](size_t) { return GeneratedImpostor{0.0, {}}; }), Error);
  EXPECT_THROW(placeGreedy(good, [](size_t) { return GeneratedImpostor{1.0, {0.1, 0.2}}; }), Error);
}
