// The cells a bake works on (Sillion et al. 1997, section 4.2: one viewing cell per oriented street edge): the
// requested half-edges without repeats and the degenerate ones apart, or the cells a camera path visits. The drivers
// that bake them are in bake/pipeline.h (Sillion's cell impostor is the pipeline's single stage:
// extract/pipeline_options.h).
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/gen/camera_path.h"
#include "farfield/urban/cells.h"

namespace farfield::bake {

// The cells a bake works on: the requested half-edges (empty = every cell) in order without repeats, the degenerate
// ones apart. Throws farfield::Error naming the id for one out of range.
struct CellSelection {
  std::vector<uint32_t> todo;
  std::vector<uint32_t> skipped_degenerate;
  size_t requested = 0;  // distinct cells asked for
};
CellSelection selectCells(const urban::CellMap& cells, std::vector<uint32_t> half_edges);

// The cells a camera path visits (CellMap::lookup of each frame's eye and view direction), in order of first visit.
std::vector<uint32_t> cellsOnPath(const urban::CellMap& cells, const gen::CameraPath& path);

}  // namespace farfield::bake
