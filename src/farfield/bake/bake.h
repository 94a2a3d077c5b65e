// Baking the impostors of a city's viewing cells (Sillion et al. 1997, section 4.2, "impostors are created ... off-line
// as a pre-process"): for each cell (oriented street edge), the creation camera at the edge origin looking towards its
// end, a capture of the cell's distant model, the depth mesh and/or grid mesh built from it, written to an impostor
// store (farfield/store/impostor_store.h).
//
// Concurrency ("both cores"): the calling thread owns the OpenGL context and only renders (captures); the CPU steps
// (contour, discrepancy chains, triangulation, reprojection, PNG and mesh files) run on worker threads at the same
// time, fed through a bounded queue so that captures never pile up in memory.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/extract/bake_options.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/grid_mesh.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/cells.h"

namespace farfield::bake {


// One baked cell.
struct CellBake {
  uint32_t half_edge = 0;
  double render_ms = 0.0;     // capture: render passes and readbacks (GL thread)
  size_t data_pixels = 0;
  size_t distant_objects = 0;
  size_t local_objects = 0;
  std::map<std::string, double> build_ms;     // technique -> construction time (worker thread)
  std::map<std::string, size_t> triangles;    // technique -> triangles of the impostor
  double write_ms = 0.0;      // PNG + mesh files
};

struct BakeReport {
  std::vector<CellBake> cells;              // baked, sorted by half-edge
  std::vector<uint32_t> skipped_degenerate; // requested cells too short to look along (CellOptions::min_cell_length)
  size_t requested = 0;                     // distinct cells asked for
  size_t workers = 0;
  double wall_s = 0.0;                      // whole bake, wall clock
  std::string store_dir;
};

// Bakes the given cells (half-edge ids; duplicates ignored; empty = every cell) into the store directory `out_dir`
// (created; index.json, streets.json and cells/ are (over)written). Makes `context` current on the calling thread.
// Cells shorter than min_cell_length are skipped and reported. The ground height under the cameras comes from the
// shared objects of the segmentation (the ground; see ground_height.h). Throws farfield::Error for bad options, ids
// out of range or files that cannot be written.
BakeReport bakeCells(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                     std::vector<uint32_t> half_edges, const extract::BakeOptions& options, const std::string& out_dir);

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
