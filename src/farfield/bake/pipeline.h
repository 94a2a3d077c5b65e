// The pipeline of geometry extractors (Decoret et al. 1999, section 5.2, Figure 6): per viewing cell, the geometry
// travels down a chain of small stages, each with one job, and comes out as an efficient representation:
//
//   pvs       visibility culling: the objects seen in 360-degree item buffers from points along the cell (5.3)
//   near-far  segmentation of what is left into near geometry (drawn as polygons) and far geometry (5.4)
//   mmi       image-based extraction of the far geometry: layering by visibility events (4.1-4.2), then one meshed
//             impostor per layer and view (4.3, 5.1), and the single-mesh impostor of the same objects for comparison
//
// The stages are composed from the CLI (`farfield bake --pipeline pvs,near-far,mmi`). Where the pipeline splits
// between preprocessing and online computation is an option (`--online mmi`, or `--online near-far,mmi`): the bake
// runs and stores the stages before the split; the runtime (farfield/runtime/walkthrough.h) runs the others with the same
// code when the viewer enters a cell, inside that frame, so their cost shows in the frame times. A stage that is
// skipped leaves its input as it is: without `pvs` every object is a candidate; `mmi` needs `near-far` before it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/bake/bake.h"
#include "farfield/bake/ground_height.h"
#include "farfield/bake/validity_region.h"
#include "farfield/core/error_bound.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/impostor_mesh.h"
#include "farfield/scene/scene.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/layering.h"
#include "farfield/urban/pvs.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::bake {

inline constexpr char kStagePvs[] = "pvs";
inline constexpr char kStageNearFar[] = "near-far";
inline constexpr char kStageMmi[] = "mmi";

// The stages of a pipeline and the split between bake and runtime.
struct PipelineSpec {
  std::vector<std::string> stages;  // in order
  size_t online_from = 0;           // stages[online_from..] run online; == stages.size() when all are baked
  std::vector<std::string> baked() const;
  std::vector<std::string> online() const;
};
// "pvs,near-far,mmi" and the online stages ("" = none; "mmi"; "near-far,mmi"). Throws farfield::Error naming
// --pipeline / --online for an unknown or repeated stage, a wrong order (pvs, near-far, mmi), mmi without near-far,
// online stages that are not the pipeline's tail, or pvs online (hundreds of renders: never inside a frame).
PipelineSpec parsePipeline(const std::string& stages, const std::string& online = "");

enum class LayerMesh { Grid, DepthMesh };
// "grid" or "depth-mesh"; throws farfield::Error naming `what`.
LayerMesh parseLayerMesh(const std::string& text, const std::string& what = "--layer-mesh");
const char* layerMeshName(LayerMesh mesh);

enum class LayerViews {
  Street,  // one view along the cell (the street direction), the default
  Six,     // six 90-degree cube faces from the cell's origin: 360 degrees
};
LayerViews parseLayerViews(const std::string& text, const std::string& what = "--views");
const char* layerViewsName(LayerViews views);

struct PipelineOptions {
  BakeOptions base;  // resolution, field of view, eye height, planes, capture, workers, progress, scene label
  // The error bound (core/error_bound.h): error_px pixels in final frames frame_width x frame_height with the vertical
  // field of view frame_fov_deg (the walkthrough's frames, not the captures). Its angle is the layering threshold T
  // (the paper: 10 px at 512 x 512) and the bound the validity regions are reported against.
  double error_px = 10.0;
  int frame_width = 640;
  int frame_height = 360;
  float frame_fov_deg = 60.0f;
  ValidityOptions validity;              // sampling of the validity regions (bake/validity_region.h)
  // Capture stations along the cell, metres apart (0: the cell's start only, as in the paper). Each layer is captured
  // from every station; stations a layer does not need (its earlier stations' validity regions already cover the
  // cell at the bound) are dropped.
  float station_spacing = 5.0f;
  urban::PvsOptions pvs;                 // sample spacing, cube face size
  float near_radius = 0.0f;              // near/far by distance (metres) instead of the local model when > 0
  urban::VisibilityEventOptions events;  // representative points, landmark boost
  std::vector<uint32_t> landmarks;       // object ids whose event weights are boosted (section 4.2)
  urban::LayerOrder layer_order = urban::LayerOrder::NearestFirst;
  urban::LayerChoice layer_choice = urban::LayerChoice::LeastGrowth;
  LayerMesh mesh = LayerMesh::Grid;
  int grid_cells = 30;                   // regular grid: cells per side (section 5.1: 30 x 30)
  LayerViews views = LayerViews::Street;
  bool single_mesh = true;               // also build the SMI of the far objects (the bench's "smi" mode)
};

// What flows down the pipeline for one cell.
struct CellWork {
  uint32_t cell = 0;
  urban::CellSegment segment;         // the street centreline [PQ] on the ground plane
  Vec3 p_eye{0.0f}, q_eye{0.0f};      // its ends at eye height above the ground
  Camera street_camera;               // at P looking towards Q (bake::cellCamera)
  std::vector<uint32_t> candidates;   // objects entering the next stage (ascending); all objects at the start
  store::CellPipeline result;         // the stages' results (the store's per-cell record)
  // From the mmi stage, before they are written or uploaded: per layer, per view; and the single mesh's views.
  std::vector<std::vector<impostor::DepthMeshImpostor>> layer_views;
  std::vector<impostor::DepthMeshImpostor> single_views;
  // Captures waiting for their meshes (the bake builds them on worker threads).
  std::vector<std::vector<impostor::ImpostorCapture>> layer_captures;
  std::vector<impostor::ImpostorCapture> single_captures;
  size_t views_per_station = 1;       // 1 (street) or 6 (cube faces); captures are station-major
  double capture_ms = 0.0;
  double build_ms = 0.0;
};

// Runs stages on cells. Holds the scene, its GPU copy, the cell map and the options (all must outlive it), the ground
// height, a renderer and (made on first use) the PVS sampler. Needs the OpenGL context current on the calling thread
// for construction and for every GL stage.
class PipelineRunner {
 public:
  PipelineRunner(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const urban::CellMap& cells,
                 const PipelineOptions& options);
  ~PipelineRunner();

  // A cell's work record: segment, eye points, street camera, all objects as candidates. Throws farfield::Error for
  // a degenerate cell or an id out of range.
  CellWork start(uint32_t cell) const;
  // Rebuilds a cell's work record from stored results (the stages the bake ran), to continue online.
  CellWork resume(uint32_t cell, const store::CellPipeline& stored) const;

  // The GL side of one stage (pvs: sampling; near-far: the split; mmi: layering and captures). Throws
  // farfield::Error for an unknown stage or a missing input (mmi before near-far).
  void runStage(const std::string& stage, CellWork& work);
  // The CPU side of the mmi stage: meshes from the captures (grid or depth mesh). Thread-safe (no GL, no shared
  // state); frees the captures.
  void buildMeshes(CellWork& work) const;
  // Every stage in order, the meshes included (the runtime's online path).
  void runStages(const std::vector<std::string>& stages, CellWork& work);

  const PipelineOptions& options() const { return options_; }
  ErrorBound bound() const;
  double threshold() const { return threshold_; }

 private:
  void runPvs(CellWork& work);
  void runNearFar(CellWork& work) const;
  void runMmi(CellWork& work);
  std::vector<Vec3> stationEyes(const CellWork& work) const;    // capture stations along the cell, start first
  std::vector<Camera> viewCameras(const CellWork& work, const Vec3& eye) const;  // a station's creation cameras
  void pruneStations(store::StoredLayer& layer, std::vector<impostor::DepthMeshImpostor>& views,
                     const CellWork& work) const;

  const scene::Scene& scene_;
  const gpu::GpuScene& gpu_scene_;
  const urban::CellMap& cells_;
  PipelineOptions options_;
  double threshold_ = 0.0;
  std::unique_ptr<GroundHeight> ground_;
  gpu::Renderer renderer_;
  std::unique_ptr<urban::PvsSampler> pvs_;
};

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
nlohmann::json storageReport(const store::StoreIndex& index, const std::string& dir, const PipelineOptions& options,
                             size_t city_cells = 0);

// Bakes the baked stages of `spec` for the given cells (empty = all) into the store `out_dir`: GL stages and captures
// on the calling thread, meshes and files on worker threads, a progress bar. The store holds what the bench modes
// local, visible, smi, mmi and mmi-dynamic need. Throws farfield::Error for bad options or unwritable files.
PipelineReport bakePipeline(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                            std::vector<uint32_t> half_edges, const PipelineSpec& spec,
                            const PipelineOptions& options, const std::string& out_dir);

// Options of a pipeline store as recorded in its index (index.options["pipeline"]), and back: the runtime re-creates
// the runner for online stages from them. Saved whole and read back strictly: a missing key, an unknown key or a
// value of the wrong type or out of range is a farfield::Error naming `source` and the key. Stores of version 2
// lacked frame_height, frame_fov_deg and validity: with store_version 2 those take the values version 2 meant
// (square frames of frame_width at fov_deg; default sampling); every other key is still required.
nlohmann::json pipelineOptionsToJson(const PipelineOptions& options);
PipelineOptions pipelineOptionsFromJson(const nlohmann::json& json, const std::string& source, int store_version = 3);

}  // namespace farfield::bake
