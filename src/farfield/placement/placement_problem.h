// The greedy's input from CPVs, object hierarchy and candidates (Jeschke et al. 2005, sections 5.1-5.2).
//
// The estimates are the caller's cost model (Wimmer and Wonka 2003 in the paper; a calibrated model in Farfield):
// only ranking uses them, so they need not be exact, but the frame-time promise holds only if t_object does not
// underestimate what a node's geometry costs in a CPV (e.g. count its objects that intersect the CPV's enclosing
// frustum) and the CPV times (t_enc) are conservative.
#pragma once

#include <cstdint>
#include <functional>

#include "farfield/placement/candidates.h"
#include "farfield/placement/greedy.h"
#include "farfield/placement/object_hierarchy.h"
#include "farfield/placement/view_space.h"

namespace farfield::placement {

struct PlacementEstimates {
  // Time of the node's original geometry in the CPV, >= 0; called once per (node, CPV) pair that some candidate serves.
  std::function<double(int node, uint32_t cpv)> t_object;
  // Time of the candidate's impostor in the CPV, >= 0.
  std::function<double(const Candidate& candidate, uint32_t cpv)> t_impostor;
  // Memory of the candidate's impostor, > 0 (bytes).
  std::function<double(const Candidate& candidate)> memory;
};

// GreedyProblem with one candidate per CandidateSet entry (same order), CPV times = t_enc, t_max from the view space
// options and node_parent from the hierarchy. Throws farfield::Error for a missing estimate; placeGreedy checks the
// values.
GreedyProblem makeGreedyProblem(const ViewSpace& view_space, const ObjectHierarchy& hierarchy,
                                const CandidateSet& candidates, const PlacementEstimates& estimates);

}  // namespace farfield::placement
