// Sillion et al. 1997, section 5.1: pre-fetching the impostors of the viewer's neighbourhood, in the direction of
// motion.
#include "farfield/runtime/prefetch.h"

#include <algorithm>
#include <cmath>

namespace farfield::runtime {

PrefetchChoice prefetchCells(const urban::StreetGraph& graph, uint32_t cell, Vec2 motion, size_t max_cells) {
  PrefetchChoice out;
  const Vec2 along = graph.direction(cell);
  if (glm::length(motion) < 1e-6f) motion = along;
  motion = glm::normalize(motion);
  const bool forward = glm::dot(motion, along) >= 0.0f;
  out.exit_junction = forward ? graph.destination(cell) : graph.origin(cell);
  // Every cell touching the junction: the streets leaving it, and the same streets towards it (at a junction the
  // cell lookup follows the view, which turns before the viewer leaves the junction: a turning car is found in the
  // cell of the street it turns into, pointing at the junction, for a few frames).
  std::vector<std::pair<float, uint32_t>> ranked;
  for (uint32_t leaving : graph.outgoing(out.exit_junction))
    for (uint32_t next : {leaving, urban::StreetGraph::twin(leaving)})
      if (next != cell) ranked.emplace_back(-glm::dot(graph.direction(next), motion), next);
  std::sort(ranked.begin(), ranked.end());  // best agreement first, then by id
  for (const auto& [score, next] : ranked) out.cells.push_back(next);
  const uint32_t twin = urban::StreetGraph::twin(cell);
  if (std::find(out.cells.begin(), out.cells.end(), twin) == out.cells.end()) out.cells.push_back(twin);
  if (max_cells > 0 && out.cells.size() > max_cells) out.cells.resize(max_cells);
  return out;
}

}  // namespace farfield::runtime
