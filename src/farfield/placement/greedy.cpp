// Greedy impostor selection with lazy recalculation (Jeschke et al. 2005, sections 5.1-5.5).
#include "farfield/placement/greedy.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <queue>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::placement {

namespace {

const char* const kWhat = "impostor placement";

void fail(const std::string& msg) { throw Error(kWhat, msg); }

bool goodTime(double t) { return std::isfinite(t) && t >= 0.0; }

void validate(const GreedyProblem& p) {
  if (!(p.t_max > 0.0) || !std::isfinite(p.t_max)) fail("t_max " + std::to_string(p.t_max) + " must be > 0");
  for (size_t c = 0; c < p.cpv_times.size(); ++c)
    if (!goodTime(p.cpv_times[c])) fail("CPV " + std::to_string(c) + ": time must be finite and >= 0");
  const size_t n_nodes = p.node_parent.size();
  for (size_t n = 0; n < n_nodes; ++n) {
    // Walking up from any node must reach a root within n_nodes steps.
    int at = int(n);
    for (size_t steps = 0; at >= 0; ++steps) {
      if (steps > n_nodes) fail("node_parent has a cycle through node " + std::to_string(n));
      const int parent = p.node_parent[size_t(at)];
      if (parent >= int(n_nodes) || parent < -1) fail("node " + std::to_string(at) + ": parent out of range");
      at = parent;
    }
  }
  std::vector<size_t> seen(p.cpv_times.size(), SIZE_MAX);
  for (size_t i = 0; i < p.candidates.size(); ++i) {
    const GreedyCandidate& cand = p.candidates[i];
    const std::string where = "candidate " + std::to_string(i);
    if (cand.node < 0 || size_t(cand.node) >= n_nodes) fail(where + ": node " + std::to_string(cand.node) + " out of range");
    if (!(cand.memory > 0.0) || !std::isfinite(cand.memory)) fail(where + ": memory must be > 0");
    for (const GreedyServe& s : cand.serves) {
      if (s.cpv >= p.cpv_times.size()) fail(where + ": CPV " + std::to_string(s.cpv) + " out of range");
      if (seen[s.cpv] == i) fail(where + ": CPV " + std::to_string(s.cpv) + " listed twice");
      seen[s.cpv] = i;
      if (!goodTime(s.t_object) || !goodTime(s.t_impostor)) fail(where + ": times must be finite and >= 0");
    }
  }
}

// One impostor shown in one CPV: `replaced` is what it saves against the node's original geometry there.
struct Shown {
  size_t slot;  // index into Greedy::chosen_
  int node;
  double replaced;
};

struct Slot {
  size_t candidate;
  double memory;
  size_t uses = 0;
};

class Greedy {
 public:
  Greedy(const GreedyProblem& p, const GenerateImpostor& generate)
      : p_(p), generate_(generate), t_(p.cpv_times), shown_(p.cpv_times.size()) {}

  bool isAncestor(int a, int b) const {  // a is a strict ancestor of b
    for (int at = p_.node_parent[size_t(b)]; at >= 0; at = p_.node_parent[size_t(at)])
      if (at == a) return true;
    return false;
  }

  // What the node's geometry costs in CPV c now (section 5.5), or a negative value when an impostor of the node or
  // of an ancestor is already shown there.
  double currentCost(uint32_t c, int node, double t_object) const {
    double cost = t_object;
    for (const Shown& e : shown_[c]) {
      if (e.node == node || isAncestor(e.node, node)) return -1.0;
      if (isAncestor(node, e.node)) cost -= e.replaced;
    }
    return std::max(0.0, cost);
  }

  // Eq. 4-6 with the section 5.5 cost.
  double score(size_t i) const {
    const GreedyCandidate& cand = p_.candidates[i];
    double sum = 0.0;
    for (const GreedyServe& s : cand.serves) {
      if (!(t_[s.cpv] > p_.t_max)) continue;
      const double cost = currentCost(s.cpv, cand.node, s.t_object);
      if (cost < 0.0) continue;
      const double delta = std::min(cost - s.t_impostor, t_[s.cpv] - p_.t_max);
      if (delta > 0.0) sum += delta;
    }
    return sum / cand.memory;
  }

  void choose(size_t i) {
    const GreedyCandidate& cand = p_.candidates[i];
    const GeneratedImpostor made = generate_(i);
    const std::string where = "generated impostor for candidate " + std::to_string(i);
    if (!(made.memory > 0.0) || !std::isfinite(made.memory)) fail(where + ": memory must be > 0");
    if (!made.t_impostor.empty() && made.t_impostor.size() != cand.serves.size())
      fail(where + ": " + std::to_string(made.t_impostor.size()) + " times for " +
           std::to_string(cand.serves.size()) + " served CPVs");
    for (double t : made.t_impostor)
      if (!goodTime(t)) fail(where + ": times must be finite and >= 0");
    ++counters_.choices;
    const size_t slot = chosen_.size();
    chosen_.push_back({i, made.memory});
    for (size_t k = 0; k < cand.serves.size(); ++k) {
      const GreedyServe& s = cand.serves[k];
      const uint32_t c = s.cpv;
      if (!(t_[c] > p_.t_max)) continue;  // solved: showing more would cost memory lookups for nothing
      const double cost = currentCost(c, cand.node, s.t_object);
      const double t_real = made.t_impostor.empty() ? s.t_impostor : made.t_impostor[k];
      const double saving = cost - t_real;
      if (cost < 0.0 || !(saving > 0.0)) continue;
      // The new impostor replaces those of the node's descendants in c; their saving is part of `cost` already.
      std::vector<Shown>& list = shown_[c];
      for (size_t e = 0; e < list.size();) {
        if (isAncestor(cand.node, list[e].node)) {
          release(list[e].slot);
          ++counters_.replacements;
          list[e] = list.back();
          list.pop_back();
        } else {
          ++e;
        }
      }
      list.push_back({slot, cand.node, s.t_object - t_real});
      t_[c] -= saving;
      ++chosen_[slot].uses;
    }
    if (chosen_[slot].uses == 0) ++counters_.freed;  // its real times help nowhere: never shown
  }

  void release(size_t slot) {
    FF_CHECK(chosen_[slot].uses > 0);
    if (--chosen_[slot].uses == 0) ++counters_.freed;
  }

  void runLazy() {
    // Max-heap on (score, -index): equal scores go to the lower index, as in runFull.
    struct Entry {
      double score;
      size_t index;
      size_t stamp;  // counters_.choices when the score was computed
    };
    auto less = [](const Entry& a, const Entry& b) {
      return a.score < b.score || (a.score == b.score && a.index > b.index);
    };
    std::priority_queue<Entry, std::vector<Entry>, decltype(less)> heap(less);
    for (size_t i = 0; i < p_.candidates.size(); ++i) {
      const double s = score(i);
      if (s > 0.0) heap.push({s, i, 0});
      else ++counters_.dropped_zero;
    }
    while (!heap.empty()) {
      Entry top = heap.top();
      heap.pop();
      if (top.stamp != counters_.choices) {
        // Stale: re-rank it. Scores only fall, so a stale score bounds the fresh one from above and the top,
        // once fresh and still not below the next entry's (stale, upper-bound) key, is the best choice.
        top.score = score(top.index);
        top.stamp = counters_.choices;
        ++counters_.recalculations;
        if (!(top.score > 0.0)) {
          ++counters_.dropped_zero;
          continue;
        }
        if (!heap.empty() && less(top, heap.top())) {
          heap.push(top);
          continue;
        }
      }
      choose(top.index);
    }
  }

  void runFull() {
    std::vector<size_t> alive;
    for (size_t i = 0; i < p_.candidates.size(); ++i) {
      if (score(i) > 0.0) alive.push_back(i);
      else ++counters_.dropped_zero;
    }
    bool first = true;
    while (!alive.empty()) {
      size_t best = SIZE_MAX;
      double best_score = 0.0;
      std::vector<size_t> next;
      for (size_t i : alive) {
        const double s = score(i);
        if (!first) ++counters_.recalculations;
        if (!(s > 0.0)) {
          ++counters_.dropped_zero;
          continue;
        }
        next.push_back(i);
        if (best == SIZE_MAX || s > best_score) {  // alive is in index order: ties keep the lower index
          best = i;
          best_score = s;
        }
      }
      first = false;
      if (best == SIZE_MAX) break;
      choose(best);
      alive.clear();
      for (size_t i : next)
        if (i != best) alive.push_back(i);
    }
  }

  GreedyResult result() const {
    GreedyResult r;
    r.counters = counters_;
    std::vector<size_t> remap(chosen_.size(), SIZE_MAX);
    for (size_t slot = 0; slot < chosen_.size(); ++slot) {
      if (chosen_[slot].uses == 0) continue;
      remap[slot] = r.impostors.size();
      r.impostors.push_back({chosen_[slot].candidate, chosen_[slot].memory, {}});
      r.memory += chosen_[slot].memory;
    }
    r.cpv_impostors.resize(shown_.size());
    for (uint32_t c = 0; c < shown_.size(); ++c) {
      for (const Shown& e : shown_[c]) {
        FF_CHECK(remap[e.slot] != SIZE_MAX);
        r.cpv_impostors[c].push_back(uint32_t(remap[e.slot]));
        r.impostors[remap[e.slot]].cpvs.push_back(c);
      }
      std::sort(r.cpv_impostors[c].begin(), r.cpv_impostors[c].end());
      if (t_[c] > p_.t_max) r.unsolved.push_back(c);
    }
    r.cpv_times = t_;
    return r;
  }

 private:
  const GreedyProblem& p_;
  const GenerateImpostor& generate_;
  std::vector<double> t_;
  std::vector<std::vector<Shown>> shown_;
  std::vector<Slot> chosen_;
  GreedyCounters counters_;
};

}  // namespace

GreedyResult placeGreedy(const GreedyProblem& problem, const GenerateImpostor& generate, const GreedyOptions& options) {
  validate(problem);
  if (!generate) fail("no generate callback");
  Greedy greedy(problem, generate);
  if (options.full_recalculation) greedy.runFull();
  else greedy.runLazy();
  return greedy.result();
}

GenerateImpostor estimatesAsGenerated(const GreedyProblem& problem) {
  return [&problem](size_t i) { return GeneratedImpostor{problem.candidates.at(i).memory, {}}; };
}

}  // namespace farfield::placement
