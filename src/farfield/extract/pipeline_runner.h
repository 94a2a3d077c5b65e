// The extractor stages run on one cell (Decoret et al. 1999, section 5.2): the bake runs the stages before the
// pipeline's split, the runtime (runtime/walkthrough.h) the others when the viewer enters a cell, with this same code.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "farfield/core/error_bound.h"
#include "farfield/extract/ground_height.h"
#include "farfield/extract/pipeline_options.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/impostor_mesh.h"
#include "farfield/scene/scene.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/layering.h"
#include "farfield/urban/pvs.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::extract {

// What flows down the pipeline for one cell.
struct CellWork {
  uint32_t cell = 0;
  urban::CellSegment segment;         // the street centreline [PQ] on the ground plane
  Vec3 p_eye{0.0f}, q_eye{0.0f};      // its ends at eye height above the ground
  Camera street_camera;               // at P looking towards Q (cellCamera)
  std::vector<uint32_t> candidates;   // objects entering the next stage (ascending); all objects at the start
  store::CellPipeline result;         // the stages' results (the store's per-cell record)
  // From the mmi stage (per layer, per view) and the single stage (per view), before they are written or uploaded.
  std::vector<std::vector<impostor::DepthMeshImpostor>> layer_views;
  std::vector<impostor::DepthMeshImpostor> single_views;
  // Captures waiting for their meshes (the bake builds them on worker threads); each stage's flag is set by its GL
  // side and cleared by buildMeshes, which builds only what is pending (a record resumed from a store keeps its
  // stored views).
  std::vector<std::vector<impostor::ImpostorCapture>> layer_captures;
  std::vector<impostor::ImpostorCapture> single_captures;
  bool layers_pending = false, single_pending = false;
  size_t views_per_station = 1;       // 1 (street) or 6 (cube faces); captures are station-major
  double capture_ms = 0.0;            // both image stages together
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

  // The GL side of one stage (pvs: sampling; near-far: the split; single: captures of all far objects in view; mmi:
  // layering and captures per layer). Throws farfield::Error for an unknown stage or a missing input (single or mmi
  // before near-far).
  void runStage(const std::string& stage, CellWork& work);
  // The CPU side of the single and mmi stages: meshes from the pending captures (grid or depth mesh), then the
  // validity regions per capture station, dropping the stations not needed. Thread-safe (no GL, no shared state);
  // frees the captures.
  void buildMeshes(CellWork& work) const;
  // Every stage in order, the meshes included (the runtime's online path).
  void runStages(const std::vector<std::string>& stages, CellWork& work);

  const PipelineOptions& options() const { return options_; }
  ErrorBound bound() const;
  double threshold() const { return threshold_; }

 private:
  void runPvs(CellWork& work);
  void runNearFar(CellWork& work) const;
  void runSingle(CellWork& work);
  void runMmi(CellWork& work);
  std::vector<uint32_t> farInView(const CellWork& work, const char* stage) const;  // far objects a view shows
  std::vector<Camera> stationCameras(CellWork& work) const;  // every station's views, station-major
  impostor::ImpostorCapture capture(const std::vector<uint32_t>& ids, const Camera& camera);
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

}  // namespace farfield::extract
