// Which cells a bake works on.
#include "farfield/bake/bake.h"

#include <set>
#include <string>

#include "farfield/core/error.h"

namespace farfield::bake {

CellSelection selectCells(const urban::CellMap& cells, std::vector<uint32_t> half_edges) {
  if (half_edges.empty())
    for (uint32_t e = 0; e < cells.cellCount(); ++e) half_edges.push_back(e);
  CellSelection out;
  std::set<uint32_t> seen;
  for (uint32_t e : half_edges) {
    if (e >= cells.cellCount())
      throw Error("cell " + std::to_string(e), "no such half-edge (the street graph has " +
                                                   std::to_string(cells.cellCount()) + ")");
    if (!seen.insert(e).second) continue;
    (cells.degenerate(e) ? out.skipped_degenerate : out.todo).push_back(e);
  }
  out.requested = seen.size();
  return out;
}

std::vector<uint32_t> cellsOnPath(const urban::CellMap& cells, const gen::CameraPath& path) {
  std::vector<uint32_t> order;
  std::set<uint32_t> seen;
  for (const gen::PathFrame& f : path.frames) {
    const uint32_t cell = cells.lookup(f.eye, f.at - f.eye);
    if (cell != urban::kNone && seen.insert(cell).second) order.push_back(cell);
  }
  return order;
}

}  // namespace farfield::bake
