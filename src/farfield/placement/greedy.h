// Greedy impostor selection with lazy recalculation (Jeschke et al. 2005, sections 5.1-5.5).
//
// Abstract input: per CPV its current rendering time; per candidate its object-hierarchy node, an estimated memory
// and, for every CPV it may serve, estimated times of the node's original geometry (t_object) and of the impostor
// (t_impostor) in that CPV. Times are in any one unit (the unit of t_max), memory in any one unit (bytes).
//
// Rendering acceleration of candidate i for CPV c (eq. 4, with t_CPV^i ~ t_CPV - (t_object - t_impostor)):
//   delta = max(0, t_c - max(t_c - (cost - t_impostor), t_max)) = max(0, min(cost - t_impostor, t_c - t_max))
// where cost is what the node's geometry costs in c now: t_object minus the savings of the impostors already shown
// in c for descendants of the node (section 5.5: chosen impostors are treated as part of the scene). delta is 0
// when c already shows an impostor of the node itself or of an ancestor. Score (eq. 5, 6) = sum of delta / memory.
//
// A choice (section 5.3) calls `generate`, which builds the impostor and returns its real memory and, optionally,
// its real time per served CPV; the impostor is shown in every CPV where it then still helps (t_c > t_max and the
// real saving is positive), replaces the impostors of its descendants there, and t_c drops by the saving. An
// impostor left in no CPV is freed and its memory regained. Scores never rise as choices are made, so lazy
// recalculation (section 5.4) re-ranks only the top of a priority queue; `full_recalculation` re-scores every
// candidate after every choice instead (an oracle: both choose the same sequence, ties broken by lower index).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

namespace farfield::placement {

struct GreedyServe {
  uint32_t cpv = 0;         // index into GreedyProblem::cpv_times
  double t_object = 0.0;    // time of the node's original geometry in this CPV, >= 0
  double t_impostor = 0.0;  // estimated time of the impostor in this CPV, >= 0
};

struct GreedyCandidate {
  int node = 0;            // object-hierarchy node, index into GreedyProblem::node_parent
  double memory = 0.0;     // estimated memory, > 0
  std::vector<GreedyServe> serves;  // at most one entry per CPV
};

struct GreedyProblem {
  std::vector<double> cpv_times;   // t_CPV without impostors, >= 0
  double t_max = 0.0;              // > 0
  std::vector<int> node_parent;    // parent of each object-hierarchy node, -1 for a root
  std::vector<GreedyCandidate> candidates;
};

// What `generate` returns for the chosen candidate: its real memory (> 0) and either no times (the estimates stand)
// or one real impostor time per entry of the candidate's serves, in the same order.
struct GeneratedImpostor {
  double memory = 0.0;
  std::vector<double> t_impostor;
};
using GenerateImpostor = std::function<GeneratedImpostor(size_t candidate)>;

struct GreedyOptions {
  bool full_recalculation = false;  // re-score every candidate after every choice (slow; for checks)
};

struct ChosenImpostor {
  size_t candidate = 0;       // index into GreedyProblem::candidates
  double memory = 0.0;        // real memory from generate
  std::vector<uint32_t> cpvs; // CPVs that show it at the end
};

struct GreedyCounters {
  size_t choices = 0;           // candidates generated
  size_t recalculations = 0;    // score evaluations after the initial ranking
  size_t dropped_zero = 0;      // candidates dropped with a score of 0
  size_t freed = 0;             // impostors removed from every CPV (memory regained), including unused ones
  size_t replacements = 0;      // (CPV, impostor) pairs replaced by an ancestor's impostor
};

struct GreedyResult {
  std::vector<ChosenImpostor> impostors;          // kept impostors, in the order chosen
  std::vector<std::vector<uint32_t>> cpv_impostors;  // per CPV: indices into impostors
  std::vector<double> cpv_times;                  // per CPV: time with its impostors
  std::vector<uint32_t> unsolved;                 // CPVs still over t_max
  double memory = 0.0;                            // sum of the kept impostors' memory
  GreedyCounters counters;
};

// Throws farfield::Error for t_max <= 0, negative or non-finite times, memory <= 0, a CPV or node index out of
// range, a CPV listed twice in one candidate, a cyclic node_parent, an empty generate, or a bad generate result.
GreedyResult placeGreedy(const GreedyProblem& problem, const GenerateImpostor& generate,
                         const GreedyOptions& options = {});

// A generate that returns the estimates unchanged (for tests and for ranking-only runs).
GenerateImpostor estimatesAsGenerated(const GreedyProblem& problem);

}  // namespace farfield::placement
