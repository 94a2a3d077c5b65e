// The bake (Decoret et al. 1999, section 5.2): the extractor stages of extract/ (pvs, near-far, single, mmi; see
// extract/pipeline_options.h) run over a city's cells, GL stages and captures on the calling thread, meshes and files
// on worker threads, into an impostor store. Sillion et al. 1997's cell impostors (`farfield bake --technique`) are
// the pipeline near-far,single with one capture station per cell.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/bake/bake.h"
#include "farfield/bake/shard.h"
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

// How a bake covers its view space (bake/shard.h, store/bake_journal.h).
struct BakeControl {
  std::optional<ShardSpec> shard;  // bake only this part of the view space, into a shard database
  bool resume = false;             // continue the bake the journal in the output directory records
};

struct PipelineReport {
  std::vector<PipelineCellReport> cells;  // sorted by half-edge (resumed cells included)
  size_t view_space = 0;                  // cells of the whole bake (all shards)
  std::optional<ShardSpec> shard;
  size_t resumed = 0;                     // cells taken from the journal of a killed bake
  size_t resume_rejected = 0;             // journal cells whose files failed their checks (baked again)
  size_t torn_journal_lines = 0;          // the journal's cut last line (the cell the crash interrupted)
  bool already_complete = false;          // --resume found the finished database: nothing was baked
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
//
// Each finished cell is recorded in out_dir's journal (store/bake_journal.h) and the index is written at the end,
// so the previous database in out_dir stays readable until then. With control.resume, the cells the journal holds
// (their files checked) are kept and the rest baked, into the same generation; a journal of another bake (other
// options, scene, cells or shard) is an error; without a journal, a finished database of this same bake is left as
// it is (already_complete) and anything else starts from the beginning. With control.shard, only that part of the
// view space (bake/shard.h) is baked and the index records the shard (store/impostor_store.h) for `farfield merge`.
PipelineReport bakePipeline(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                            std::vector<uint32_t> half_edges, const extract::PipelineSpec& spec,
                            const extract::PipelineOptions& options, const std::string& out_dir,
                            const BakeControl& control = {});

}  // namespace farfield::bake
