// The greedy's input from CPVs, object hierarchy and candidates (Jeschke et al. 2005, sections 5.1-5.2).
#include "farfield/placement/placement_problem.h"

#include <unordered_map>

#include "farfield/core/error.h"

namespace farfield::placement {

GreedyProblem makeGreedyProblem(const ViewSpace& view_space, const ObjectHierarchy& hierarchy,
                                const CandidateSet& candidates, const PlacementEstimates& estimates) {
  if (!estimates.t_object || !estimates.t_impostor || !estimates.memory)
    throw Error("impostor placement", "t_object, t_impostor and memory estimates are all required");
  GreedyProblem p;
  p.t_max = view_space.options.t_max;
  p.node_parent = hierarchy.parents();
  p.cpv_times.reserve(view_space.cpvs.size());
  for (const Cpv& c : view_space.cpvs) p.cpv_times.push_back(c.t_enc);
  // Many candidates share a node and CPVs: each (node, CPV) time is asked for once.
  std::unordered_map<uint64_t, double> t_object;
  p.candidates.reserve(candidates.candidates.size());
  for (const Candidate& cand : candidates.candidates) {
    GreedyCandidate g;
    g.node = cand.node;
    g.memory = estimates.memory(cand);
    g.serves.reserve(cand.cpvs.size());
    for (uint32_t c : cand.cpvs) {
      const uint64_t key = uint64_t(uint32_t(cand.node)) << 32 | c;
      auto it = t_object.find(key);
      if (it == t_object.end()) it = t_object.emplace(key, estimates.t_object(cand.node, c)).first;
      g.serves.push_back({c, it->second, estimates.t_impostor(cand, c)});
    }
    p.candidates.push_back(std::move(g));
  }
  return p;
}

}  // namespace farfield::placement
