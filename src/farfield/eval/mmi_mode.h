// Walkthrough modes over a pipeline store (Decoret et al. 1999, section 6.1, Table 1): `farfield bake --pipeline
// pvs,near-far,mmi` writes per cell the PVS, the near/far split, the multi-mesh impostor (MMI) layers and the single
// mesh (SMI) of the same far objects; these modes draw them.
//
//   local        the cell's near geometry only (frustum-culled): the upper bound of the frame rate
//   visible      the cell's PVS (frustum-culled): what any image-based method must beat
//   smi          near geometry + the single-mesh impostor of the far objects
//   mmi          near geometry + one meshed impostor per layer
//   mmi-dynamic  mmi, with the front-most layers turned into dynamically updated impostors while the frame budget
//                allows (section 5.5; see below)
//
// Mode options (--mode-option key=value; `farfield bench --impostors DIR` sets impostor_dir):
//   impostor_dir=DIR        the pipeline store (mmi_dir=DIR overrides it for these modes)
//   impostor_cache=N        cells kept loaded (least recently used evicted), default 16
//   impostor_ids=object|layer  item buffers show, per impostor pixel, the object captured there (default: the
//                           views' per-texel ids as an id texture) or one id per layer
//   cell_lookup=street|nearest  as for the depth-mesh mode
//   error_px=PX             the error bound in pixels of this walk's frames (default: the bake's --error-px); the
//                           bound's angle follows from the frame size and field of view (core/error_bound.h)
//   mmi-dynamic only:
//   frame_budget_ms=MS      the desired frame time (default 33.3: 30 Hz)
//   dynamic_error_px=PX     a layer is refreshed when its error angle exceeds PX pixels (default 2)
//   dynamic_resolution=PX   dynamic impostor image size (default: frame width x fov margin)
//   dynamic_grid_px=PX      grid spacing of the dynamic meshes (default 8)
//   dynamic_max_updates=N   layer updates per frame at most (default 1: updates are spread over frames)
//   dynamic_min_lifetime=F  fast motion: when the nearest layer's error would outgrow dynamic_error_px within F
//                           frames at the current speed, every layer falls back to its MMI (default 3)
//
// Cells: the cell is looked up per frame as in the depth-mesh mode. Its record is read (and its impostors uploaded)
// the first time the viewer enters it, inside that frame.
//
// The error bound: a layer (or the single mesh) is drawn as an impostor only where the validity region of one of its
// capture stations, computed at bake time (bake/validity_region.h), says its error stays under the bound where the
// layer appears in the frame (ErrorBound::angleWithin); the station with the smallest error is drawn. Elsewhere its
// objects are drawn as geometry (frustum-culled), counted in info() as invalid layer draws. Stores without validity regions (version 2)
// draw every layer and count it as unchecked. When the store left stages to the runtime (`bake
// --online mmi`), they run then, with the bake's code (PipelineRunner), and their time counts in that frame. A cell
// the store does not hold falls back to frustum-culled full geometry (counted).
//
// Dynamic updates (section 5.5): a cost model with coefficients fitted on this machine at prepare() (triangles, draw
// calls, pixels; runtime/cost_model.h) predicts the frame time of the cell's geometry and impostors; the time left
// under the budget is spent re-rendering layers from the current viewpoint into impostors with 8-bit depth on a
// regular grid (runtime/dynamic_impostor.h), in decreasing order of Schaufler's error angle, and only when the
// predicted cost of the update fits. A dynamic impostor is reused while it covers the view and its error angle stays
// under dynamic_error_px; otherwise the layer's MMI is drawn until the next update.
#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/eval/mode.h"
#include "farfield/impostor/drawable.h"
#include "farfield/runtime/cost_model.h"
#include "farfield/runtime/dynamic_impostor.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/street_graph.h"

namespace farfield::runtime {

enum class MmiKind { Local, Visible, Smi, Mmi, MmiDynamic };
const char* mmiKindName(MmiKind kind);

// Registers local, visible, smi, mmi and mmi-dynamic (called by registerModes()).
void registerMmiModes();

class MmiMode final : public eval::Mode {
 public:
  MmiMode(MmiKind kind, const eval::ModeContext& context);
  ~MmiMode() override;

  std::string name() const override { return mmiKindName(kind_); }
  void prepare(const eval::ModeContext& context) override;
  void frame(eval::FrameContext& frame) override;
  std::map<std::string, double> info() const override;

 private:
  struct Layer {
    std::vector<uint32_t> objects;
    Box3 bounds;                                        // world bounds of its objects
    uint64_t geometry_triangles = 0;                    // of its objects as geometry
    std::vector<std::unique_ptr<impostor::GpuImpostor>> views;
    std::vector<Vec3> view_eyes;                        // creation eyes of the views
    std::vector<uint32_t> view_station;                 // capture station of each view
    std::vector<impostor::ValidityRegion> validity;     // per station, from the bake (none in version 2 stores)
    std::unique_ptr<DynamicImpostor> dynamic;
  };
  struct Cell {
    std::vector<uint8_t> geometry_mask;  // per object id: drawn as geometry in this mode
    std::vector<Layer> layers;           // MMI layers (mmi, mmi-dynamic) or the single mesh as one layer (smi)
    uint64_t impostor_triangles = 0;
    size_t impostor_meshes = 0;
    bool online = false;                 // stages run at load time
  };
  Cell& cell(uint32_t half_edge);
  std::unique_ptr<Cell> loadCell(const store::CellEntry& entry);
  // Section 5.5 in two steps around the validity pass: drops the dynamic impostors that fast motion or their own
  // error angle made stale, then (after the frame's geometry is known) schedules updates into the budget.
  void dropStaleDynamic(const Camera& camera, Cell& cell);
  void updateDynamic(eval::FrameContext& frame, Cell& cell, uint64_t frame_triangles, size_t frame_draws);

  MmiKind kind_;
  std::string dir_;
  size_t cache_capacity_ = 16;
  bool object_ids_ = true;
  std::string lookup_option_;
  // Dynamic updates.
  double budget_ms_ = 1000.0 / 30.0;
  double dynamic_error_px_ = 2.0;
  DynamicImpostorOptions dynamic_options_;
  size_t max_updates_ = 1;
  double min_lifetime_frames_ = 3.0;
  double error_px_ = 0.0;        // 0 until prepare(): the option, or the bake's bound
  double bound_rad_ = 0.0;       // of the last frame
  std::vector<uint8_t> invalid_object_;  // per object id: in a layer drawn as geometry this frame
  std::vector<int> layer_station_;       // per layer of the current cell: the station drawn this frame

  const eval::ModeContext* context_ = nullptr;
  store::StoreIndex index_;
  urban::StreetGraph graph_;
  urban::CellLocator locator_;
  std::unique_ptr<urban::CellMap> cell_map_;        // for online stages
  std::unique_ptr<bake::PipelineRunner> runner_;    // for online stages
  std::vector<std::string> online_stages_;
  std::list<uint32_t> order_;                       // LRU of loaded cells, most recent first
  std::unordered_map<uint32_t, std::unique_ptr<Cell>> cells_;
  std::vector<uint64_t> object_triangles_;
  std::vector<uint32_t> ids_;
  uint32_t layer_id_base_ = 0;
  CostModel cost_;
  double dynamic_threshold_rad_ = 0.0;
  bool has_previous_ = false;
  bool fast_ = false;  // this frame is fast motion (dropStaleDynamic)
  Vec3 previous_eye_{0.0f};

  // Statistics.
  size_t frames_ = 0, fallback_frames_ = 0, loads_ = 0, evictions_ = 0, online_runs_ = 0;
  double load_ms_max_ = 0.0, load_ms_total_ = 0.0, online_ms_total_ = 0.0;
  std::map<uint32_t, size_t> visited_;
  double geometry_triangles_sum_ = 0.0, impostor_triangles_sum_ = 0.0, layers_sum_ = 0.0;
  size_t impostor_frames_ = 0;
  size_t invalid_layer_draws_ = 0, unchecked_layer_draws_ = 0, invalid_frames_ = 0;
  double invalid_triangles_sum_ = 0.0;  // geometry triangles drawn for invalid layers
  size_t updates_ = 0, fast_frames_ = 0, skipped_for_budget_ = 0;
  double update_ms_total_ = 0.0, update_ms_max_ = 0.0, dynamic_layers_sum_ = 0.0;
  double predicted_ms_sum_ = 0.0, predicted_update_error_ms_ = 0.0;
  size_t predicted_frames_ = 0;
  double update_overhead_ms_ = 0.0;  // update time the cost model does not see (readback, meshing), running mean
};

}  // namespace farfield::runtime
