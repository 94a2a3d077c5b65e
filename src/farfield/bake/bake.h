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
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/grid_mesh.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/cells.h"

namespace farfield::bake {

inline constexpr char kDepthMesh[] = "depth-mesh";
inline constexpr char kGridMesh[] = "grid-mesh";

// "depth-mesh", "grid-mesh" or "both" -> the list of techniques; throws farfield::Error naming `what` otherwise.
std::vector<std::string> parseTechniques(const std::string& text, const std::string& what = "--technique");

struct BakeOptions {
  std::vector<std::string> techniques{kDepthMesh};  // built from each capture (one capture per cell)
  int resolution = 512;      // impostor image width = height, pixels
  // Vertical = horizontal field of view of the creation camera. The walker's 60 degrees: on the default city's
  // 600 m drive (10 cells, 100 frames, 512 x 512) wider captures lose more to the coarser texture than they gain in
  // coverage (depth-mesh PSNR 36.8 dB at 60, 36.5 at 75, 35.6 at 90, 35.4 at 110 degrees; cracks 1.1% for all):
  // with the street cell lookup the view rarely turns far from the street's direction within a cell.
  float fov_deg = 60.0f;
  float eye_height = 1.7f;   // metres above the ground under the edge's ends (a pedestrian)
  float near_plane = 0.5f;   // metres
  float far_plane = 20000.0f;
  impostor::CaptureOptions capture;
  impostor::DepthMeshOptions depth_mesh;  // its resolution and fov_y are overridden by the two above
  impostor::GridMeshOptions grid_mesh;
  int workers = 0;            // CPU threads building meshes; 0 = hardware threads - 1, at least 1
  size_t queue_capacity = 2;  // captures waiting for a worker
  bool progress = true;       // progress bar on stderr (also off with FF_PROGRESS=0)
  std::string scene_label;    // recorded in the store's index
};

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

// Where the creation camera of a cell stands and looks: at the edge origin, `eye_height` above the ground there,
// looking at the edge end at the same height above the ground there. `ground` gives the ground height at (x, y).
// Throws farfield::Error for a degenerate cell.
Camera cellCamera(const urban::CellMap& cells, uint32_t cell, const BakeOptions& options,
                  const std::function<float(float, float)>& ground);

// Bakes the given cells (half-edge ids; duplicates ignored; empty = every cell) into the store directory `out_dir`
// (created; index.json, streets.json and cells/ are (over)written). Makes `context` current on the calling thread.
// Cells shorter than min_cell_length are skipped and reported. The ground height under the cameras comes from the
// shared objects of the segmentation (the ground; see ground_height.h). Throws farfield::Error for bad options, ids
// out of range or files that cannot be written.
BakeReport bakeCells(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                     std::vector<uint32_t> half_edges, const BakeOptions& options, const std::string& out_dir);

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
