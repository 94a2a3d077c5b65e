// The pipeline of geometry extractors (Decoret et al. 1999, section 5.2, Figure 6): per viewing cell, the geometry
// travels down a chain of small stages, each with one job, and comes out as an efficient representation:
//
//   pvs       visibility culling: the objects seen in 360-degree item buffers from points along the cell (5.3)
//   near-far  segmentation of what is left into near geometry (drawn as polygons) and far geometry (5.4)
//   single    image-based extraction of the far geometry as one meshed impostor per capture station and view: the
//             single-mesh impostor (SMI), which is also Sillion et al. 1997's cell impostor (sections 4.1-4.2: one
//             capture from the cell's start, `--station-spacing 0`, meshed as a depth mesh or a regular grid)
//   mmi       image-based extraction of the far geometry: layering by visibility events (4.1-4.2), then one meshed
//             impostor per layer and view (4.3, 5.1)
//
// The stages are composed from the CLI (`farfield bake --pipeline pvs,near-far,single,mmi`; `farfield bake --technique
// depth-mesh` is `--pipeline near-far,single --layer-mesh depth-mesh --station-spacing 0`). The order is pvs, near-far,
// single, mmi; single and mmi both need near-far and are independent of each other (the SMI is built once, by
// single). Where the pipeline splits between preprocessing and online computation is an option (`--online mmi`, or
// `--online near-far,single,mmi`): the bake runs and stores the stages before the split; the runtime
// (farfield/runtime/walkthrough.h) runs the others with the same code when the viewer enters a cell, inside that frame,
// so their cost shows in the frame times. A stage that is skipped leaves its input as it is: without `pvs` every
// object is a candidate.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/error_bound.h"
#include "farfield/extract/bake_options.h"
#include "farfield/extract/validity_region.h"
#include "farfield/urban/layering.h"
#include "farfield/urban/pvs.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::extract {

inline constexpr char kStagePvs[] = "pvs";
inline constexpr char kStageNearFar[] = "near-far";
inline constexpr char kStageSingle[] = "single";
inline constexpr char kStageMmi[] = "mmi";

// The stages of a pipeline and the split between bake and runtime.
struct PipelineSpec {
  std::vector<std::string> stages;  // in order
  size_t online_from = 0;           // stages[online_from..] run online; == stages.size() when all are baked
  std::vector<std::string> baked() const;
  std::vector<std::string> online() const;
};
// "pvs,near-far,single,mmi" and the online stages ("" = none; "mmi"; "single,mmi"). Throws farfield::Error naming
// --pipeline / --online for an unknown or repeated stage, a wrong order (pvs, near-far, single, mmi), single or mmi
// without near-far, online stages that are not the pipeline's tail, or pvs online (hundreds of renders: never inside
// a frame).
PipelineSpec parsePipeline(const std::string& stages, const std::string& online = "");

enum class LayerMesh { Grid, DepthMesh };
// "grid" or "depth-mesh"; throws farfield::Error naming `what`.
LayerMesh parseLayerMesh(const std::string& text, const std::string& what = "--layer-mesh");
const char* layerMeshName(LayerMesh mesh);

// Sillion et al. 1997's cell impostor (`farfield bake --technique`, the bench modes of the same names) is the
// pipeline's single stage: kTechniquePipeline with the technique's mesh and one capture station at the cell's start.
inline constexpr char kDepthMesh[] = "depth-mesh";
inline constexpr char kGridMesh[] = "grid-mesh";
inline constexpr char kTechniquePipeline[] = "near-far,single";
// "depth-mesh" -> LayerMesh::DepthMesh, "grid-mesh" -> LayerMesh::Grid; throws farfield::Error naming `what` for
// anything else ("both" included: one store holds one mesh kind; bake twice).
LayerMesh techniqueMesh(const std::string& technique, const std::string& what = "--technique");

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
  ValidityOptions validity;              // sampling of the validity regions (extract/validity_region.h)
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
};

// Throws farfield::Error naming the option (as the CLI spells it) for a value out of range.
void validatePipelineOptions(const PipelineOptions& options);

// Options of a pipeline store as recorded in its index (index.options["pipeline"]), and back: the runtime re-creates
// the runner for online stages from them. Saved whole and read back strictly: a missing key, an unknown key or a
// value of the wrong type or out of range is a farfield::Error naming `source` and the key. Stores of version 2
// lacked frame_height, frame_fov_deg and validity: with store_version 2 those take the values version 2 meant
// (square frames of frame_width at fov_deg; default sampling); every other key is still required. Stores of versions
// 2 and 3 also have "single_mesh" (required there, a boolean; an error in version 4): the mmi stage then built the
// single mesh too. It is not an option any more but the single stage: the store's reader maps it to that stage
// (store/impostor_store.h, "Version 4"); here it is only checked.
nlohmann::json pipelineOptionsToJson(const PipelineOptions& options);
PipelineOptions pipelineOptionsFromJson(const nlohmann::json& json, const std::string& source, int store_version = 4);

}  // namespace farfield::extract
