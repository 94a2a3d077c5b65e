#include "farfield/extract/pipeline_options.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <limits>
#include <type_traits>
#include <set>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/strict_json.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/grid_mesh.h"

namespace farfield::extract {

// ---------------------------------------------------------------------------------------------------------------
// Parsing

namespace {

const std::vector<std::string>& knownStages() {
  static const std::vector<std::string> stages{kStagePvs, kStageNearFar, kStageSingle, kStageMmi};
  return stages;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
  if (!text.empty() && text.back() == ',') out.emplace_back();
  return out;
}

size_t stageRank(const std::string& stage) {
  const auto& k = knownStages();
  return size_t(std::find(k.begin(), k.end(), stage) - k.begin());
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

std::vector<std::string> PipelineSpec::baked() const {
  return {stages.begin(), stages.begin() + std::ptrdiff_t(std::min(online_from, stages.size()))};
}

std::vector<std::string> PipelineSpec::online() const {
  return {stages.begin() + std::ptrdiff_t(std::min(online_from, stages.size())), stages.end()};
}

PipelineSpec parsePipeline(const std::string& stages_text, const std::string& online_text) {
  PipelineSpec spec;
  if (stages_text.empty()) throw Error("--pipeline", "no stages given (expected e.g. pvs,near-far,single,mmi)");
  for (const std::string& s : splitList(stages_text)) {
    if (stageRank(s) == knownStages().size())
      throw Error("--pipeline", "unknown stage '" + s + "' (known: pvs, near-far, single, mmi)");
    if (contains(spec.stages, s)) throw Error("--pipeline", "stage '" + s + "' is listed twice");
    if (!spec.stages.empty() && stageRank(s) < stageRank(spec.stages.back()))
      throw Error("--pipeline", "stage '" + s + "' must come before '" + spec.stages.back() +
                                    "' (the order is pvs, near-far, single, mmi)");
    spec.stages.push_back(s);
  }
  for (const char* image_stage : {kStageSingle, kStageMmi})
    if (contains(spec.stages, image_stage) && !contains(spec.stages, kStageNearFar))
      throw Error("--pipeline", std::string(image_stage) +
                                    " needs near-far before it (the impostors stand for the far geometry)");
  spec.online_from = spec.stages.size();
  if (!online_text.empty()) {
    const std::vector<std::string> online = splitList(online_text);
    for (const std::string& s : online) {
      if (!contains(spec.stages, s)) throw Error("--online", "stage '" + s + "' is not in the pipeline");
      if (s == kStagePvs)
        throw Error("--online", "pvs cannot run online: it renders hundreds of 360-degree views per cell");
    }
    const size_t from = spec.stages.size() - online.size();
    for (size_t i = 0; i < online.size(); ++i)
      if (from + i >= spec.stages.size() || spec.stages[from + i] != online[i])
        throw Error("--online", "the online stages must be the end of the pipeline, in its order (e.g. mmi, or "
                                "single,mmi)");
    spec.online_from = from;
  }
  return spec;
}

LayerMesh parseLayerMesh(const std::string& text, const std::string& what) {
  if (text == "grid") return LayerMesh::Grid;
  if (text == "depth-mesh") return LayerMesh::DepthMesh;
  throw Error(what, "unknown layer mesh '" + text + "' (expected grid or depth-mesh)");
}

const char* layerMeshName(LayerMesh mesh) { return mesh == LayerMesh::Grid ? "grid" : "depth-mesh"; }

LayerMesh techniqueMesh(const std::string& technique, const std::string& what) {
  if (technique == kDepthMesh) return LayerMesh::DepthMesh;
  if (technique == kGridMesh) return LayerMesh::Grid;
  if (technique == "both")
    throw Error(what, "'both' is gone: a store holds one mesh kind. Bake twice (--technique depth-mesh -o A, "
                      "--technique grid-mesh -o B; bench them with --mode-option depth_mesh_dir=A --mode-option "
                      "grid_mesh_dir=B) or use --pipeline near-far,single --layer-mesh grid|depth-mesh");
  throw Error(what, "unknown technique '" + technique + "' (expected depth-mesh or grid-mesh)");
}

LayerViews parseLayerViews(const std::string& text, const std::string& what) {
  if (text == "street") return LayerViews::Street;
  if (text == "six") return LayerViews::Six;
  throw Error(what, "unknown views '" + text + "' (expected street or six)");
}

const char* layerViewsName(LayerViews views) { return views == LayerViews::Street ? "street" : "six"; }

// ---------------------------------------------------------------------------------------------------------------
// Options as JSON

nlohmann::json pipelineOptionsToJson(const PipelineOptions& o) {
  return {{"resolution", o.base.resolution},
          {"fov_deg", o.base.fov_deg},
          {"eye_height", o.base.eye_height},
          {"near", o.base.near_plane},
          {"far", o.base.far_plane},
          {"detect_seen_from_below", o.base.capture.detect_seen_from_below},
          {"error_px", o.error_px},
          {"frame_width", o.frame_width},
          {"frame_height", o.frame_height},
          {"frame_fov_deg", o.frame_fov_deg},
          {"station_spacing", o.station_spacing},
          {"validity",
           {{"step", o.validity.step},
            {"back", o.validity.back},
            {"width_share", o.validity.width_share},
            {"laterals", o.validity.laterals},
            {"below", o.validity.below},
            {"above", o.validity.above}}},
          {"pvs_spacing", o.pvs.spacing},
          {"pvs_face_size", o.pvs.face_size},
          {"near_radius", o.near_radius},
          {"representative_points",
           o.events.points == urban::RepresentativePoints::HullVertices ? "hull" : "footprint"},
          {"landmark_boost", o.events.landmark_boost},
          {"landmarks", o.landmarks},
          {"layer_order", o.layer_order == urban::LayerOrder::Given ? "given" : "nearest-first"},
          {"layer_choice", o.layer_choice == urban::LayerChoice::SmallestArea ? "smallest-area" : "least-growth"},
          {"layer_mesh", layerMeshName(o.mesh)},
          {"grid_cells", o.grid_cells},
          {"views", layerViewsName(o.views)}};
}


PipelineOptions pipelineOptionsFromJson(const nlohmann::json& j, const std::string& source, int store_version) {
  PipelineOptions o;
  StrictJson r(j, source, "pipeline option");
  r.number("resolution", o.base.resolution);
  r.number("fov_deg", o.base.fov_deg);
  r.number("eye_height", o.base.eye_height);
  r.number("near", o.base.near_plane);
  r.number("far", o.base.far_plane);
  o.base.capture.detect_seen_from_below = r.boolean("detect_seen_from_below");
  r.number("error_px", o.error_px);
  r.number("frame_width", o.frame_width);
  if (store_version >= 3 || r.has("frame_height")) {
    r.number("frame_height", o.frame_height);
    r.number("frame_fov_deg", o.frame_fov_deg);
    r.number("station_spacing", o.station_spacing);
    StrictJson v(r.at("validity"), source + ": validity", "pipeline option");
    v.number("step", o.validity.step);
    v.number("back", o.validity.back);
    v.number("width_share", o.validity.width_share);
    v.number("laterals", o.validity.laterals);
    v.number("below", o.validity.below);
    v.number("above", o.validity.above);
    v.rejectUnknown();
  } else {
    // Version 2 meant square frames of frame_width with the capture's field of view.
    o.frame_height = o.frame_width;
    o.frame_fov_deg = o.base.fov_deg;
    o.station_spacing = 0.0f;  // one capture at the cell's start
  }
  r.number("pvs_spacing", o.pvs.spacing);
  r.number("pvs_face_size", o.pvs.face_size);
  r.number("near_radius", o.near_radius);
  o.events.points = r.choice("representative_points", {"footprint", "hull"}) == 1
                        ? urban::RepresentativePoints::HullVertices
                        : urban::RepresentativePoints::FootprintVertices;
  r.number("landmark_boost", o.events.landmark_boost);
  const nlohmann::json& landmarks = r.at("landmarks");
  if (!landmarks.is_array()) throw Error(source, "pipeline option \"landmarks\" must be an array of ids");
  for (const nlohmann::json& id : landmarks) {
    if (!id.is_number_unsigned() || id.get<uint64_t>() > std::numeric_limits<uint32_t>::max())
      throw Error(source, "pipeline option \"landmarks\" must hold object ids");
    o.landmarks.push_back(id.get<uint32_t>());
  }
  o.layer_order = r.choice("layer_order", {"nearest-first", "given"}) == 1 ? urban::LayerOrder::Given
                                                                            : urban::LayerOrder::NearestFirst;
  o.layer_choice = r.choice("layer_choice", {"least-growth", "smallest-area"}) == 1
                       ? urban::LayerChoice::SmallestArea
                       : urban::LayerChoice::LeastGrowth;
  o.mesh = parseLayerMesh(r.text("layer_mesh"), source + ": layer_mesh");
  r.number("grid_cells", o.grid_cells);
  o.views = parseLayerViews(r.text("views"), source + ": views");
  // Versions 2 and 3: whether the mmi stage also built the single mesh. The store's reader made it the single stage
  // (store::indexFromJson); here it must be there and be a boolean, as it was written.
  if (store_version <= 3) r.boolean("single_mesh");
  r.rejectUnknown();
  return o;
}

void validatePipelineOptions(const PipelineOptions& o) {
  validateBakeOptions(o.base);
  if (!(o.error_px > 0.0) || !std::isfinite(o.error_px))
    throw Error("--error-px", "must be a positive number of pixels");
  if (o.frame_width < 1 || o.frame_height < 1) throw Error("--frame-size", "must be at least 1 x 1 pixels");
  if (!(o.frame_fov_deg > 0.0f && o.frame_fov_deg < 180.0f)) throw Error("--frame-fov", "must be in (0, 180) degrees");
  if (!(o.station_spacing >= 0.0f) || !std::isfinite(o.station_spacing))
    throw Error("--station-spacing", "must be a finite number of metres >= 0");
  const ValidityOptions& v = o.validity;
  if (!(v.step > 0.0f) || !(v.back >= 0.0f) || v.laterals < 1 || v.laterals % 2 == 0 || !(v.below >= 0.0f) ||
      !(v.above >= 0.0f) || !(v.width_share >= 0.0f))
    throw Error("validity options", "need step > 0, back, below, above, width share >= 0 and an odd lateral count");
  if (o.grid_cells < 1 || o.grid_cells > o.base.resolution)
    throw Error("--grid-cells", "must be 1.." + std::to_string(o.base.resolution) + " (the impostor resolution)");
  if (!(o.events.landmark_boost >= 1.0) || !std::isfinite(o.events.landmark_boost))
    throw Error("--landmark-boost", "must be a finite number >= 1");
  if (!(o.near_radius >= 0.0f) || !std::isfinite(o.near_radius))
    throw Error("--near-radius", "must be a finite number of metres >= 0");
}

}  // namespace farfield::extract
