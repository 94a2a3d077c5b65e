// Walkthrough with cell impostors (Sillion et al. 1997, sections 3 and 5): per frame, the viewer's cell (oriented
// street edge) is looked up from the camera position and heading, its local model is drawn as geometry (culled to the
// view frustum) and its distant model as the cell's baked impostor. Bench/walk modes "depth-mesh" and "grid-mesh".
//
// Mode options (--mode-option key=value, or `farfield bench --impostors DIR`):
//   impostor_dir=DIR      impostor store written by `farfield bake` (farfield/store/impostor_store.h). One store may
//                         hold both techniques (`bake --technique both`); each mode reads its own technique's meshes.
//   depth_mesh_dir=DIR    store for the depth-mesh mode only (overrides impostor_dir), likewise grid_mesh_dir=DIR:
//                         for stores baked separately (`bake --technique depth-mesh -o A`, `--technique grid-mesh -o B`).
//   impostor_cache=N      impostors kept on the GPU (least recently used evicted), default 16.
//   impostor_projective=0 draw with the meshes' interpolated uvs instead of projective texturing (default 1).
//   cell_lookup=street|nearest  how the viewer's cell is found (urban::CellLocator); default: the store's, which is
//                         the rule the bake used to choose the cells of a path.
//
// Loading: prepare() reads the store's index and street graph only. The impostor of a cell is read from disk and
// uploaded the first time the viewer enters the cell, inside that frame (so the load counts in the frame's time),
// and kept in an LRU cache. A cell that was not baked falls back to frustum-culled geometry for everything. Both are
// counted in info().
//
// Item buffers: the impostor is drawn with object id (scene object count + 1), so id images tell impostor pixels
// (non-zero) from sky (0).
#pragma once

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "farfield/eval/mode.h"
#include "farfield/runtime/database.h"
#include "farfield/impostor/drawable.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/street_graph.h"

namespace farfield::eval {

// Registers "depth-mesh" and "grid-mesh", and the pipeline-store modes of mmi_mode.h (local, visible, smi, mmi,
// mmi-dynamic), into eval's mode registry (idempotent). Executables call it before they
// list or create modes (see the .cpp for why registration is not a static object).
void registerImpostorModes();

// Least-recently-used cache of GPU impostors by cell. Needs a current context for get() and for destruction.
class ImpostorCache {
 public:
  using Loader = std::function<std::unique_ptr<impostor::GpuImpostor>(uint32_t cell)>;
  ImpostorCache(size_t capacity, Loader loader);

  // The impostor of the cell, loaded (and the least recently used one evicted) on a miss.
  const impostor::GpuImpostor& get(uint32_t cell);
  bool contains(uint32_t cell) const { return map_.count(cell) != 0; }
  size_t size() const { return map_.size(); }
  size_t loads() const { return loads_; }
  size_t evictions() const { return evictions_; }
  double loadMsTotal() const { return load_ms_total_; }
  double loadMsMax() const { return load_ms_max_; }
  size_t gpuBytes() const;

 private:
  struct Slot {
    std::list<uint32_t>::iterator position;
    std::unique_ptr<impostor::GpuImpostor> impostor;
  };
  size_t capacity_;
  Loader loader_;
  std::list<uint32_t> order_;  // most recent first
  std::unordered_map<uint32_t, Slot> map_;
  size_t loads_ = 0;
  size_t evictions_ = 0;
  double load_ms_total_ = 0.0;
  double load_ms_max_ = 0.0;
};

class ImpostorMode final : public Mode {
 public:
  // technique: "depth-mesh" or "grid-mesh" (the mode's name).
  ImpostorMode(std::string technique, const ModeContext& context);
  ~ImpostorMode() override;

  std::string name() const override { return technique_; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  // frames, impostor_loads (the warm-up frame's included), impostor_load_ms_max/mean, cache_evictions,
  // fallback_frames (no impostor baked for the cell), cells_visited, cell_changes, baked_cells,
  // mean_impostor_triangles (frames with an impostor), mean_geometry_triangles and mean_geometry_objects (the culled
  // local model, or everything culled in fallback frames), peak_cache_gpu_bytes.
  std::map<std::string, double> info() const override;

 private:
  std::string technique_;
  std::string dir_;
  size_t cache_capacity_ = 16;
  bool projective_ = true;
  std::string lookup_option_;  // "" = the store's
  const gpu::GpuScene* gpu_scene_ = nullptr;
  const scene::Scene* scene_ = nullptr;
  const scene::Bvh* bvh_ = nullptr;
  store::StoreIndex index_;
  urban::StreetGraph graph_;
  urban::CellLocator locator_;
  std::unique_ptr<ImpostorCache> cache_;
  uint32_t impostor_id_ = 0;
  std::vector<uint64_t> object_triangles_;  // per object id

  // The current cell's local model as a membership mask over object ids.
  uint32_t current_cell_ = 0xffffffffu;
  std::vector<uint8_t> local_mask_;
  const store::CellEntry* current_entry_ = nullptr;
  std::vector<uint32_t> ids_;

  size_t frames_ = 0;
  size_t fallback_frames_ = 0;
  size_t cell_changes_ = 0;
  std::map<uint32_t, size_t> visited_;
  double impostor_triangles_sum_ = 0.0;
  double local_triangles_sum_ = 0.0;
  double local_objects_sum_ = 0.0;
  size_t peak_gpu_bytes_ = 0;
};

}  // namespace farfield::eval
