// The bake (Decoret et al. 1999, section 5.2): the extractor stages of extract/ (pvs, near-far, single, mmi; see
// extract/pipeline_options.h) run over a city's cells, GL stages and captures on the calling thread, meshes and files
// on worker threads, into an impostor store. Sillion et al. 1997's cell impostors (`farfield bake --technique`) are
// the pipeline near-far,single with one capture station per cell.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/bake/bake.h"
#include "farfield/extract/pipeline_options.h"
#include "farfield/extract/pipeline_runner.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/scene.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"

namespace farfield::bake {

// One baked cell of a pipeline bake.
struct PipelineCellReport {
  uint32_t half_edge = 0;
  size_t pvs = 0, near = 0, far = 0, layers = 0;
  size_t layer_triangles = 0, single_triangles = 0;
  double pvs_ms = 0.0, weights_ms = 0.0, capture_ms = 0.0, build_ms = 0.0;
};

struct PipelineReport {
  std::vector<PipelineCellReport> cells;  // sorted by half-edge
  std::vector<uint32_t> skipped_degenerate;
  size_t requested = 0;
  size_t workers = 0;
  double wall_s = 0.0;
  double threshold_rad = 0.0;
  nlohmann::json storage;  // see storageReport()
  std::string store_dir;
};

// The paper's storage estimate (section 5.1) for the cells baked, next to the bytes written: images of
// resolution^2 x 3 bytes and meshes of grid^2 float xyz positions (the paper's 10.8 kB for 30 x 30) per layer view, with the mean
// layer count measured here and with the paper's worst case of 3 layers; the bytes of the textures (PNG) and meshes
// actually written, and their uncompressed size. With city_cells > 0 (every cell of the street graph), the same
// estimate and the bytes written per cell scaled to the whole city.
nlohmann::json storageReport(const store::StoreIndex& index, const std::string& dir, const extract::PipelineOptions& options,
                             size_t city_cells = 0);

// Bakes the baked stages of `spec` for the given cells (empty = all) into the store `out_dir`: GL stages and captures
// on the calling thread, meshes and files on worker threads, a progress bar. The store holds what the bench modes
// local, visible, smi (and depth-mesh, grid-mesh: the single stage), mmi and mmi-dynamic need. Throws
// farfield::Error for bad options or unwritable files.
PipelineReport bakePipeline(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                            std::vector<uint32_t> half_edges, const extract::PipelineSpec& spec,
                            const extract::PipelineOptions& options, const std::string& out_dir);

}  // namespace farfield::bake
