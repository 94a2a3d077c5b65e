// The walkthrough an engine embeds (DESIGN.md, "runtime"): it opens a scene and an impostor database baked by
// `farfield bake --pipeline` and turns each frame's camera into a FramePlan, the draw items of the frame (geometry
// and impostors) with what was decided for every layer and why, keeping the two promises:
//   - the error bound: a layer (or the single mesh) is drawn as an impostor only where the validity region of one of
//     its capture stations, computed at bake time (extract/validity_region.h), says its error stays under the bound
//     where the layer appears in the frame (ErrorBound::angleWithin); the station with the smallest error is drawn,
//     and the layer's objects are drawn as geometry where none holds the eye (reported per frame);
//   - the frame budget (Representation::MmiDynamic): a cost model fitted on this machine (gpu/cost_model.h)
//     predicts the frame's time, and the time left under the budget re-renders the front-most layers from the
//     viewer's eye (Decoret et al. 1999, section 5.5; runtime/dynamic_impostor.h), most wrong first.
// It needs no benchmark harness: eval's bench modes (local, visible, smi, mmi, mmi-dynamic) are thin adapters over
// it, and examples/embed_walkthrough.cpp drives it from a plain render loop.
//
// Cells: the viewer's cell (oriented street edge) is looked up per frame (urban::CellLocator). The cells it may enter
// next (the streets leaving the junction ahead, the way back included) are read ahead on a background thread
// (store/cell_reader.h); a cell's impostors are uploaded when the viewer enters it, inside that frame, or before, in
// the time a host spares after its frames (loadAhead), and stay resident on the GPU under a byte budget, least
// recently used evicted first. When the database left stages to the
// runtime (`bake --online mmi`) they run on entry instead. A cell the database does not hold falls back to
// frustum-culled full geometry (reported).
//
// Contract: construct and call plan() with the OpenGL context current on the calling thread; the scene, its GPU copy,
// its BVH and the renderer must outlive the walkthrough. Throws farfield::Error naming the file for a database that
// is missing, damaged (store/impostor_store.h) or baked for another scene, and for bad options.
#pragma once

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

#include "farfield/extract/pipeline_runner.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/drawable.h"
#include "farfield/impostor/validity.h"
#include "farfield/gpu/cost_model.h"
#include "farfield/runtime/dynamic_impostor.h"
#include "farfield/runtime/streaming.h"
#include "farfield/runtime/upload_rate.h"
#include "farfield/scene/bvh.h"
#include "farfield/store/cell_reader.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/street_graph.h"

namespace farfield::runtime {

// What stands for a cell's far objects.
enum class Representation {
  Local,       // nothing: the cell's near geometry only (the upper bound of the frame rate)
  Visible,     // the cell's potentially visible set as geometry (what any image-based method must beat)
  Smi,         // the single-mesh impostor of the far objects
  Mmi,         // the multi-mesh impostor, one mesh per layer (Decoret et al. 1999)
  MmiDynamic,  // mmi, with front-most layers re-rendered under the frame budget (section 5.5)
  Placed,      // a placement database (`farfield place`, Jeschke et al. 2005): per conservative problem view, the
               // layered impostors of object clusters chosen to keep the frame under t_max; geometry elsewhere
};
const char* representationName(Representation representation);
// The representation of that name (representationName's inverse), none for another name.
std::optional<Representation> representationFromName(const std::string& name);
// Why a walkthrough of `kind` cannot open the pipeline store `index` (the stage its pipeline lacks, or a stage left
// to the runtime that must be baked), "" when it can. Placed always has a reason: it needs a placement database.
std::string missingStage(const store::StoreIndex& index, Representation kind);

struct WalkthroughOptions {
  std::string database;                        // directory written by `farfield bake --pipeline` (or, for Placed,
                                               // by `farfield place`)
  Representation representation = Representation::Mmi;
  double error_px = 0.0;                       // the bound in pixels of the frames; 0 = the database's
  // GPU bytes of resident impostors (textures, id textures, meshes); least recently used cells are evicted beyond
  // it. The current cell stays even when it alone exceeds the budget (reported as over_gpu_budget).
  uint64_t gpu_budget_bytes = uint64_t(512) << 20;
  // Read the cells (Placed: the impostors of the CPVs the eye will be in over the next placed_read_ahead_frames
  // frames, along its motion) ahead on a background thread, so that the frame that needs them only uploads them.
  bool read_ahead = true;
  uint64_t read_ahead_bytes = uint64_t(256) << 20;  // decoded bytes read ahead and not yet used
  // One budget for the database in memory (> 0 replaces the two above): a quarter for the cells read ahead, the rest
  // for the resident impostors; the current cell stays even when it alone exceeds it.
  uint64_t memory_budget_bytes = 0;
  size_t prefetch_cells = 6;                   // cells read ahead in the direction of motion (runtime/prefetch.h)
  std::string streaming_csv;                   // when set, the per-frame streaming log (runtime/streaming.h) is
                                               // written there when the walkthrough ends
  bool object_ids = true;                      // impostors carry per-texel object ids (item buffers show objects)
  std::string cell_lookup;                     // "street" or "nearest"; "" = the database's
  bool layer_tiles = true;                     // Placed: layers drawn as their tiles (false: whole quads, the same
                                               // image with every texel shaded; for comparisons)
  // Placed: impostors placed under a coarser bound than error_px (`place --fallback-bounds`) are drawn, held to their
  // own bound and counted (true), or their objects drawn as geometry so that every frame keeps error_px (false: a
  // frame governor then takes them as a coarser level by raising error_px).
  bool coarser_impostors = true;
  // Placed: how many frames ahead loadAhead() and the background reads look along the eye's motion (0: none).
  size_t placed_read_ahead_frames = 15;
  // true: the plan's geometry as draw items culled per cluster on the CPU (FramePlan::items, geometry_items);
  // false: as the objects a GPU-driven frame culls itself (FramePlan::geometry_objects, gpu::GpuCuller), the items
  // then holding the impostors only.
  bool geometry_items = true;
  // MmiDynamic.
  double frame_budget_ms = 1000.0 / 30.0;
  double dynamic_error_px = 2.0;               // a dynamic impostor is refreshed beyond this error
  DynamicImpostorOptions dynamic;
  size_t max_updates = 1;                      // layer updates per frame at most
  double min_lifetime_frames = 3.0;            // fast motion: every layer falls back to its baked views
  int width = 640;                             // frame size the cost model is calibrated for (MmiDynamic)
  int height = 360;
};

// One entry of a frame's plan: what was drawn for one layer of the current cell.
struct LayerAsImpostor {   // a baked station's views, valid under the bound
  uint32_t layer = 0;
  uint32_t station = 0;
  double error_rad = 0.0;  // the region's error at the eye
  double bound_rad = 0.0;  // the bound where the layer appears
};
struct LayerAsGeometry {   // no station holds the eye under the bound: its objects as geometry
  uint32_t layer = 0;
  uint64_t triangles = 0;  // of its objects whose bounds meet the frustum (before culling per cluster)
};
struct LayerUnchecked {    // a version 2 database has no validity regions: every view drawn, the bound unchecked
  uint32_t layer = 0;
};
struct LayerAsDynamic {    // a dynamic impostor rendered from a recent eye (MmiDynamic)
  uint32_t layer = 0;
};
struct ClusterAsImpostor {  // Placed: a layered impostor of an object cluster, valid where the eye is (its shaft)
  uint32_t impostor = 0;     // id in the placement database
  uint32_t objects = 0;      // objects it stands for
  double error_rad = 0.0;    // its plan's parallax bound from anywhere in its shaft
  double bound_rad = 0.0;    // the bound of this frame
};
struct ClusterAsGeometry {  // Placed: an impostor of the CPV that cannot keep this frame's bound (a narrower field of
  uint32_t impostor = 0;     // view or a larger frame than placed for, or the eye outside its shaft): its objects
  uint64_t triangles = 0;    // are drawn as geometry
};
using LayerDecision = std::variant<LayerAsImpostor, LayerAsGeometry, LayerUnchecked, LayerAsDynamic, ClusterAsImpostor,
                                   ClusterAsGeometry>;

// What a frame could not promise, and why.
struct FrameReport {
  uint32_t cell = urban::kNone;   // half-edge, kNone outside the street graph
  uint32_t cpv = urban::kNone;    // Placed: the conservative problem view holding the camera, kNone for none
  double cpv_t_after_ms = 0.0;    // Placed: the placement's time bound of that CPV with its impostors
  bool baked = false;             // false: the database does not hold the cell (frustum-culled geometry)
  bool loaded = false;            // the frame entered a cell that was not resident, or that loadAhead made resident
  // When loaded, how: "ready" (read ahead, uploaded in this frame), "waited" (its read ahead unfinished), "cold"
  // (read in this frame), "partly" (loadAhead uploaded some of its views, the frame the rest), "uploaded" (loadAhead
  // uploaded all: nothing to do).
  const char* read = "";
  double load_ms = 0.0;           // when loaded: the time the frame spent on it (a stall if "waited" or "cold")
  uint64_t read_ahead_bytes = 0;  // decoded cells read ahead and not yet entered, after this frame
  uint64_t resident_bytes = 0;    // GPU bytes of resident impostors after this frame's loads and evictions
  bool over_gpu_budget = false;   // the current cell alone exceeds gpu_budget_bytes
  double bound_px = 0.0;
  double bound_rad = 0.0;         // at the frame's corner pixel (ErrorBound::angle)
  size_t layers_as_geometry = 0;  // the error bound is kept by drawing these as geometry
  size_t layers_unchecked = 0;    // the bound cannot be checked (no validity regions)
  uint64_t geometry_triangles = 0;  // drawn (after culling per cluster); with geometry_objects, of those objects
                                    // whole (the GPU culls their clusters)
  uint64_t impostor_triangles = 0;
  double predicted_ms = 0.0;      // MmiDynamic: the cost model's prediction before updates (0 otherwise)
  bool over_budget = false;       // MmiDynamic: the prediction exceeded the budget
  bool fast_motion = false;       // MmiDynamic: every dynamic impostor dropped
  size_t updates = 0;             // MmiDynamic: layers re-rendered in this frame
  gpu::FrameStats update_stats;   // what the updates drew (not in items)
};

struct FramePlan {
  std::vector<gpu::DrawItem> items;   // the frame's main pass: geometry and impostors
  // items[0, geometry_items) are scene geometry, with the bounds of each in its mesh's own space in geometry_bounds
  // (parallel): an engine may occlusion-cull them against the depth of the nearest ones (gpu::OcclusionCuller, exact:
  // the frame stays the same) before it draws the rest of the items.
  size_t geometry_items = 0;
  std::vector<Box3> geometry_bounds;
  // Without geometry items (WalkthroughOptions::geometry_items false): the objects (ids, ascending) drawn as geometry,
  // those of the frame's view that no impostor stands for, for a GPU-driven frame to cull per cluster
  // (gpu::GpuCuller::setObjects). geometry_version changes exactly when the list does, so a frame that sees it
  // unchanged sends nothing. The list is not frustum-culled (the GPU culls it by the frustum), so that it changes
  // only when the plan does: over a placement (Representation::Placed), the eye's region's visible set (or every
  // object) less what the impostors drawn stand for; over cells, the cell's geometry and the objects of its layers
  // drawn as geometry (every object outside the baked cells). MmiDynamic keeps the frustum's objects, whose triangles
  // its budget predicts from.
  std::vector<uint32_t> geometry_objects;
  uint64_t geometry_version = 0;
  std::vector<LayerDecision> layers;  // per layer of the current cell, or per impostor of the current CPV (Placed)
  FrameReport report;
};

class Walkthrough {
 public:
  Walkthrough(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const scene::Bvh& bvh,
              gpu::Renderer& renderer, WalkthroughOptions options);
  ~Walkthrough();
  Walkthrough(const Walkthrough&) = delete;
  Walkthrough& operator=(const Walkthrough&) = delete;

  // The frame for `camera` (its size and field of view set the bound's angle). before_gpu_work, when given, is called
  // once before the walkthrough renders anything itself in this frame (dynamic updates into their own targets), so a
  // host can start its frame timer or clear its target first. The plan stays valid until the next call.
  const FramePlan& plan(const Camera& camera, const std::function<void()>& before_gpu_work = {});

  // What the walkthrough will soon need, loaded within `budget_ms` (the time the host can spare in this frame: Decoret
  // et al. 1999, section 5.5, "from the desired and the predicted frame times we can determine how much time we have
  // to accomplish such updates"), so that the frame that first draws it does not load it. Call it after the frame's
  // plan (before the next one). Returns the milliseconds spent; 0 before a first plan.
  //  - Placed: the impostors, not yet resident, of the CPV holding the eye `placed_read_ahead_frames` frames on along
  //    its motion over the last frame, looking as now. With read_ahead, one the background thread has read is
  //    uploaded when the expected upload (the recent uploads' 90th percentile: runtime/upload_rate.h) fits in what
  //    is left; one it has not, read (or waited for) when the slowest load so far fits, else left to the thread;
  //    without, read when the slowest load fits (the first of either on trust).
  //  - Cells (Smi, Mmi, MmiDynamic with read_ahead): the cells read ahead (the streets the viewer may enter next, in
  //    the reader's order) are uploaded view by view, one cell at a time, while the next view's expected upload time
  //    (runtime/upload_rate.h) fits in what is left (the first on trust). A cell begun and not finished is finished
  //    by the frame that enters it (report.read "partly"), one finished is entered with nothing to do ("uploaded").
  //    Nothing is evicted for it: it stops where the next view does not fit the GPU budget (a cell being uploaded is
  //    dropped when the cell the viewer enters needs its bytes). Online stages: nothing (they run on entry).
  double loadAhead(const Camera& camera, double budget_ms);
  // Placed: what a frame at `eye` draws at most as geometry, known before planning it: the triangles of the visible
  // set of the region holding the eye (every object where placement sampled none), whole objects. A host that keeps a
  // frame budget tells its governor (runtime::GovernorLoop::decide's workload) so that a new region's heavier set is
  // seen in its first frame. 0 for another representation.
  double expectedTriangles(const Vec3& eye) const;

  const WalkthroughOptions& options() const { return options_; }
  double errorBoundPx() const { return options_.error_px; }
  const store::StoreIndex& database() const { return index_; }
  // Totals over the frames so far (the bench's info()).
  std::map<std::string, double> statistics() const;

 private:
  struct Layer;
  struct Cell;
  struct Placed;  // walkthrough_placed.cpp
  void openPlacement();
  const FramePlan& planPlaced(const Camera& camera);
  double loadPlacedAhead(const Camera& camera, double budget_ms);
  std::map<std::string, double> placedStatistics() const;
  std::unique_ptr<Placed> placed_;
  struct CellUpload;  // walkthrough_cells.h
  // The cell the eye is in, made resident (finishing an upload begun ahead) when it is not (walkthrough_cell_loads.cpp).
  Cell& cell(uint32_t half_edge, bool* loaded);
  // A cell's upload begun: the online stages run, or its decoded views taken (`read`, null: from the reader now).
  std::unique_ptr<CellUpload> startCell(const store::CellEntry& entry, std::shared_ptr<store::CellViews> read);
  // Uploads the next view of the cell; returns its bytes on the GPU, 0 when none was left. One larger than `room` is
  // given back and stays the next (then *full is set).
  uint64_t uploadNextView(CellUpload& upload, uint64_t room = ~uint64_t(0), bool* full = nullptr);
  // The cells the viewer may enter next queued for the reader.
  void queueCellsAhead(uint32_t half_edge, const Vec3& eye);
  double loadCellsAhead(double budget_ms);
  void evict(uint32_t keep);
  void dropStaleDynamic(const Camera& camera, Cell& cell);
  // The frame's geometry (ids_, ascending) into the plan: items culled per cluster, or the objects.
  void setGeometry(FramePlan& plan, const Camera& camera);
  // A GPU-driven frame's list without a frustum query (geometry_items false): remade only when its key changes, the
  // base (a cell, a region; ~0 = every object) and what else decides it (the layers drawn as geometry, the impostors
  // drawn). listedUnchanged() is true, with the report's triangles set, when the key is the last one; otherwise it
  // keeps the key, and the caller makes ids_ (ascending) and calls setListed().
  bool listedUnchanged(FramePlan& plan, uint64_t base, const std::vector<uint32_t>& extra);
  void setListed(FramePlan& plan);
  struct Listed {
    bool valid = false;
    uint64_t base = 0;
    std::vector<uint32_t> extra;
    uint64_t triangles = 0;
  };
  Listed listed_;
  std::vector<uint32_t> listed_extra_;  // this frame's key (scratch)
  void updateDynamic(const Camera& camera, Cell& cell, const std::function<void()>& before_gpu_work);

  const scene::Scene& scene_;
  const gpu::GpuScene& gpu_scene_;
  const scene::Bvh& bvh_;
  gpu::Renderer& renderer_;
  WalkthroughOptions options_;

  store::StoreIndex index_;
  urban::StreetGraph graph_;
  urban::CellLocator locator_;
  std::unique_ptr<urban::CellMap> cell_map_;        // for online stages
  std::unique_ptr<extract::PipelineRunner> runner_;    // for online stages
  std::vector<std::string> online_stages_;
  std::unique_ptr<store::CellReader> reader_;        // read ahead (none with online stages)
  std::vector<uint32_t> cells_ahead_;               // the cells last queued, best first
  std::unique_ptr<CellUpload> uploading_;           // a cell loadAhead began and has not finished
  std::vector<uint32_t> uploaded_ahead_;            // cells loadAhead made resident, not entered since
  UploadRate upload_rate_;                          // views' upload times
  uint64_t full_at_bytes_ = ~uint64_t(0);           // loadAhead stopped at the GPU budget with this many resident
  std::list<uint32_t> order_;                       // LRU of loaded cells, most recent first
  uint64_t resident_bytes_ = 0;
  uint32_t ahead_of_ = urban::kNone;                // the cell whose successors were last queued
  uint32_t ahead_junction_ = urban::kNone;          // ... towards this junction
  Vec3 motion_from_{0.0f};                          // the eye where the current motion started
  StreamingLog streaming_;
  std::unordered_map<uint32_t, std::unique_ptr<Cell>> cells_;
  std::vector<uint64_t> object_triangles_;
  std::vector<uint32_t> ids_;
  std::vector<uint8_t> invalid_object_;             // per object id: in a layer drawn as geometry this frame
  uint32_t layer_id_base_ = 0;
  gpu::CostModel cost_;
  double dynamic_threshold_rad_ = 0.0;
  bool has_previous_ = false;
  bool fast_ = false;
  Vec3 previous_eye_{0.0f};
  double update_overhead_ms_ = 0.0;  // update time the cost model does not see (readback, meshing), running mean
  FramePlan plan_;

  struct Statistics {
    size_t frames = 0, fallback_frames = 0, loads = 0, evictions = 0, online_runs = 0, over_gpu_budget_frames = 0;
    uint64_t resident_bytes_max = 0;
    double load_ms_max = 0.0, load_ms_total = 0.0, online_ms_total = 0.0;
    // loadAhead over cells: cells and views uploaded ahead, cells dropped unfinished, entries with nothing to do or
    // with the rest of the views to upload, the slowest single view upload (ahead or not), and the time spent.
    size_t cells_uploaded_ahead = 0, views_uploaded_ahead = 0, uploads_dropped = 0, entered_uploaded = 0,
           entered_partly = 0;
    double view_upload_ms_max = 0.0, ahead_ms_total = 0.0;
    std::map<uint32_t, size_t> visited;
    double geometry_triangles = 0.0, impostor_triangles = 0.0, layers = 0.0;
    size_t impostor_frames = 0;
    size_t invalid_layer_draws = 0, unchecked_layer_draws = 0, invalid_frames = 0;
    double invalid_triangles = 0.0;
    size_t updates = 0, fast_frames = 0, skipped_for_budget = 0, over_budget_frames = 0;
    double update_ms_total = 0.0, update_ms_max = 0.0, dynamic_layers = 0.0;
    double predicted_ms = 0.0, predicted_update_error_ms = 0.0;
    size_t predicted_frames = 0;
  } stats_;
};

}  // namespace farfield::runtime
