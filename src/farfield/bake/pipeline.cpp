// The extractor pipeline (Decoret et al. 1999, sections 4-5): PVS sampling, near/far segmentation, layering by
// visibility events and one meshed impostor per layer, baked in parallel like bake.cpp (GL stages and captures on
// the calling thread, meshes and files on worker threads: bake/gl_workers.h).
#include "farfield/bake/pipeline.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <limits>
#include <type_traits>
#include <filesystem>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "farfield/bake/gl_workers.h"
#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/grid_mesh.h"

namespace fs = std::filesystem;

namespace farfield::bake {

// ---------------------------------------------------------------------------------------------------------------
// Parsing

namespace {

const std::vector<std::string>& knownStages() {
  static const std::vector<std::string> stages{kStagePvs, kStageNearFar, kStageMmi};
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
  if (stages_text.empty()) throw Error("--pipeline", "no stages given (expected e.g. pvs,near-far,mmi)");
  for (const std::string& s : splitList(stages_text)) {
    if (stageRank(s) == knownStages().size())
      throw Error("--pipeline", "unknown stage '" + s + "' (known: pvs, near-far, mmi)");
    if (contains(spec.stages, s)) throw Error("--pipeline", "stage '" + s + "' is listed twice");
    if (!spec.stages.empty() && stageRank(s) < stageRank(spec.stages.back()))
      throw Error("--pipeline", "stage '" + s + "' must come before '" + spec.stages.back() +
                                    "' (the order is pvs, near-far, mmi)");
    spec.stages.push_back(s);
  }
  if (contains(spec.stages, kStageMmi) && !contains(spec.stages, kStageNearFar))
    throw Error("--pipeline", "mmi needs near-far before it (the impostors stand for the far geometry)");
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
                                "near-far,mmi)");
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
          {"views", layerViewsName(o.views)},
          {"single_mesh", o.single_mesh}};
}

namespace {

// Strict reading of one JSON object of options: every key the caller asks for must be there with the right type,
// and keys() lists the ones that were never asked for (unknown keys are errors, not ignored).
class StrictOptions {
 public:
  StrictOptions(const nlohmann::json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) throw Error(where_, "pipeline options must be an object");
  }
  bool has(const char* key) const { return j_.contains(key); }
  const nlohmann::json& at(const char* key) {
    const auto it = j_.find(key);
    if (it == j_.end()) throw Error(where_, std::string("pipeline option \"") + key + "\" is missing");
    seen_.push_back(key);
    return *it;
  }
  template <typename T>
  void number(const char* key, T& out) {
    const nlohmann::json& v = at(key);
    if (!v.is_number()) throw Error(where_, std::string("pipeline option \"") + key + "\" must be a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw Error(where_, std::string("pipeline option \"") + key + "\" is not finite");
    if constexpr (std::is_integral_v<T>) {
      if (d != std::floor(d) || d < double(std::numeric_limits<T>::min()) || d > double(std::numeric_limits<T>::max()))
        throw Error(where_, std::string("pipeline option \"") + key + "\" must be an integer in range");
    }
    out = T(d);
  }
  std::string text(const char* key) {
    const nlohmann::json& v = at(key);
    if (!v.is_string()) throw Error(where_, std::string("pipeline option \"") + key + "\" must be a string");
    return v.get<std::string>();
  }
  bool boolean(const char* key) {
    const nlohmann::json& v = at(key);
    if (!v.is_boolean()) throw Error(where_, std::string("pipeline option \"") + key + "\" must be true or false");
    return v.get<bool>();
  }
  // One of `names` (the first maps to 0, ...).
  size_t choice(const char* key, std::initializer_list<const char*> names) {
    const std::string v = text(key);
    size_t i = 0;
    std::string list;
    for (const char* n : names) {
      if (v == n) return i;
      list += (i++ ? ", " : "") + std::string(n);
    }
    throw Error(where_, std::string("pipeline option \"") + key + "\": unknown value '" + v + "' (expected " + list + ")");
  }
  void rejectUnknown() const {
    for (const auto& [key, value] : j_.items())
      if (std::find(seen_.begin(), seen_.end(), key) == seen_.end())
        throw Error(where_, "unknown pipeline option \"" + key + "\"");
  }

 private:
  const nlohmann::json& j_;
  std::string where_;
  std::vector<std::string> seen_;
};

}  // namespace

PipelineOptions pipelineOptionsFromJson(const nlohmann::json& j, const std::string& source, int store_version) {
  PipelineOptions o;
  StrictOptions r(j, source);
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
    StrictOptions v(r.at("validity"), source + ": validity");
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
  o.single_mesh = r.boolean("single_mesh");
  r.rejectUnknown();
  return o;
}

// ---------------------------------------------------------------------------------------------------------------
// PipelineRunner

namespace {

void validatePipelineOptions(const PipelineOptions& o) {
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

Polygon2 footprintOf(const scene::Object& object) {
  if (!object.footprint.empty()) return object.footprint;
  const Box3& b = object.world_bounds;
  if (b.empty()) return {};
  return {{b.lo.x, b.lo.y}, {b.hi.x, b.lo.y}, {b.hi.x, b.hi.y}, {b.lo.x, b.hi.y}};
}

std::vector<uint32_t> allObjects(const scene::Scene& scene) {
  std::vector<uint32_t> ids(scene.objects.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint32_t(i + 1);
  return ids;
}

}  // namespace

PipelineRunner::PipelineRunner(const scene::Scene& scene, const gpu::GpuScene& gpu_scene,
                               const urban::CellMap& cells, const PipelineOptions& options)
    : scene_(scene), gpu_scene_(gpu_scene), cells_(cells), options_(options) {
  validatePipelineOptions(options_);
  if (cells.objectCount() != scene.objects.size())
    throw Error("pipeline", "the cell map was made for " + std::to_string(cells.objectCount()) +
                                " objects but the scene has " + std::to_string(scene.objects.size()));
  threshold_ = bound().angle();
  for (uint32_t id : options_.landmarks)
    if (id == 0 || id > scene.objects.size())
      throw Error("--landmarks", "object id " + std::to_string(id) + " out of range 1.." +
                                     std::to_string(scene.objects.size()));
  ground_ = std::make_unique<GroundHeight>(scene, cells.assignment().shared);
}

PipelineRunner::~PipelineRunner() = default;

ErrorBound PipelineRunner::bound() const {
  return ErrorBound{options_.error_px, options_.frame_width, options_.frame_height,
                    degToRad(double(options_.frame_fov_deg))};
}

CellWork PipelineRunner::start(uint32_t cell) const {
  const auto ground = [this](float x, float y) { return ground_->at(x, y, 0.0f); };
  CellWork work;
  work.cell = cell;
  work.street_camera = cellCamera(cells_, cell, options_.base, ground);  // checks the id and degeneracy
  const Vec2 p = cells_.graph().originPosition(cell), q = cells_.graph().destinationPosition(cell);
  work.segment = {p, q};
  work.p_eye = Vec3(p, ground(p.x, p.y) + options_.base.eye_height);
  work.q_eye = Vec3(q, ground(q.x, q.y) + options_.base.eye_height);
  work.candidates = allObjects(scene_);
  return work;
}

CellWork PipelineRunner::resume(uint32_t cell, const store::CellPipeline& stored) const {
  CellWork work = start(cell);
  work.result = stored;
  if (stored.has_pvs) work.candidates = stored.pvs;
  if (stored.has_split) work.candidates = stored.far;
  return work;
}

void PipelineRunner::runStage(const std::string& stage, CellWork& work) {
  if (stage == kStagePvs)
    runPvs(work);
  else if (stage == kStageNearFar)
    runNearFar(work);
  else if (stage == kStageMmi)
    runMmi(work);
  else
    throw Error("pipeline", "unknown stage '" + stage + "'");
}

void PipelineRunner::runStages(const std::vector<std::string>& stages, CellWork& work) {
  for (const std::string& stage : stages) {
    runStage(stage, work);
    if (stage == kStageMmi) buildMeshes(work);
  }
}

// Section 5.3: 360-degree item buffers from points spaced along the cell at eye height.
void PipelineRunner::runPvs(CellWork& work) {
  if (!pvs_) pvs_ = std::make_unique<urban::PvsSampler>(gpu_scene_, options_.pvs);
  Stopwatch timer;
  const urban::Pvs pvs = pvs_->sample(work.p_eye, work.q_eye);
  work.result.has_pvs = true;
  work.result.pvs = pvs.ids;
  work.result.pvs_samples = pvs.sample_points;
  work.result.pvs_ms = timer.milliseconds();
  work.candidates = pvs.ids;
}

// Section 5.4: the near geometry is the candidates in the cell's local model (the blocks touching the street and the
// shared objects such as the ground), or within near_radius of the street; the rest is far.
void PipelineRunner::runNearFar(CellWork& work) const {
  const std::vector<uint32_t> local = cells_.localObjects(work.cell);
  urban::NearFarSplit split;
  if (options_.near_radius > 0.0f) {
    split = urban::splitNearFar(scene_, work.candidates, work.segment, options_.near_radius);
    // The shared objects (the ground) are geometry in every cell whatever their distance.
    const std::vector<uint32_t>& shared = cells_.assignment().shared;
    auto is_shared = [&](uint32_t id) { return std::binary_search(shared.begin(), shared.end(), id); };
    for (uint32_t id : split.far_ids)
      if (is_shared(id)) split.near_ids.push_back(id);
    split.far_ids.erase(std::remove_if(split.far_ids.begin(), split.far_ids.end(), is_shared), split.far_ids.end());
  } else {
    split = urban::splitNearFar(work.candidates, local);
  }
  std::sort(split.near_ids.begin(), split.near_ids.end());
  std::sort(split.far_ids.begin(), split.far_ids.end());
  work.result.has_split = true;
  work.result.near = std::move(split.near_ids);
  work.result.far = std::move(split.far_ids);
  work.candidates = work.result.far;
}

std::vector<Vec3> PipelineRunner::stationEyes(const CellWork& work) const {
  std::vector<Vec3> eyes{work.p_eye};
  const float length = glm::length(Vec2(work.q_eye) - Vec2(work.p_eye));
  if (options_.station_spacing > 0.0f)
    for (float s = options_.station_spacing; s < length - 0.5f * options_.station_spacing; s += options_.station_spacing)
      eyes.push_back(work.p_eye + (s / length) * (work.q_eye - work.p_eye));
  return eyes;
}

std::vector<Camera> PipelineRunner::viewCameras(const CellWork& work, const Vec3& eye) const {
  if (options_.views == LayerViews::Street) {
    Camera camera = work.street_camera;
    camera.at += eye - camera.eye;
    camera.eye = eye;
    return {camera};
  }
  return urban::cubeFaceCameras(eye, options_.base.resolution, options_.base.near_plane, options_.base.far_plane);
}

// Sections 4.1-4.3: the event graph over the far objects' footprints, the greedy layering with T, then per layer and
// view a capture of that layer's objects alone (so no layer hides another in its image: what the viewer uncovers
// while walking the cell is in the layer behind), and the same for all far objects together (the single mesh).
void PipelineRunner::runMmi(CellWork& work) {
  if (!work.result.has_split)
    throw Error("pipeline", "cell " + std::to_string(work.cell) + ": mmi needs the near-far stage before it");
  // Only the far objects some view shows are layered: with the street view, the PVS (360 degrees) also holds what
  // lies behind the viewer, which no street-facing layer could hold. Moving forward along the cell keeps the view
  // inside the frustum from P (a cone translated along its axis stays inside itself), so P's frustum is enough.
  const std::vector<Camera> cameras = viewCameras(work, work.p_eye);
  std::vector<Frustum> frusta;
  for (const Camera& camera : cameras) frusta.push_back(Frustum::fromMatrix(camera.viewProjection()));
  std::vector<uint32_t> far;
  for (uint32_t id : work.result.far) {
    const Box3& b = scene_.objects[id - 1].world_bounds;
    if (std::any_of(frusta.begin(), frusta.end(), [&](const Frustum& f) { return f.intersects(b); }))
      far.push_back(id);
  }
  Stopwatch weights_timer;
  std::vector<urban::EventObject> objects;
  objects.reserve(far.size());
  for (uint32_t id : far) {
    urban::EventObject o;
    o.footprint = footprintOf(scene_.objects[id - 1]);
    o.landmark = std::find(options_.landmarks.begin(), options_.landmarks.end(), id) != options_.landmarks.end();
    if (o.footprint.empty()) o.footprint = {work.segment.q};  // no geometry: a point, it joins any layer
    objects.push_back(std::move(o));
  }
  const urban::EventGraph graph = urban::computeEventGraph(objects, work.segment, options_.events);
  urban::LayeringOptions lo;
  lo.threshold = threshold_;
  lo.order = options_.layer_order;
  lo.choice = options_.layer_choice;
  const urban::Layering layering = urban::layerObjects(graph, objects, work.segment, lo);
  // Nearest layer first (by the distance of its nearest member to the cell): the front-most layers are the
  // candidates for dynamic updates (section 5.5).
  std::vector<std::pair<double, std::vector<uint32_t>>> layers;
  for (const std::vector<uint32_t>& members : layering.layers) {
    double nearest = std::numeric_limits<double>::infinity();
    std::vector<uint32_t> ids;
    for (uint32_t m : members) {
      nearest = std::min(nearest, urban::distanceToCell(objects[m].footprint, work.segment));
      ids.push_back(far[m]);
    }
    std::sort(ids.begin(), ids.end());
    layers.emplace_back(nearest, std::move(ids));
  }
  std::stable_sort(layers.begin(), layers.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  work.result.has_mmi = true;
  work.result.threshold_rad = threshold_;
  work.result.event_edges = graph.edgeCount();
  work.result.max_weight_rad = graph.maxWeight();
  work.result.weights_ms = weights_timer.milliseconds();
  work.result.layers.clear();
  for (auto& [distance, ids] : layers) {
    store::StoredLayer layer;
    layer.objects = std::move(ids);
    work.result.layers.push_back(std::move(layer));
  }
  work.result.single = {};
  work.result.single.objects = far;

  Stopwatch capture_timer;
  // Every station's views, station-major (view k of station j is capture j * views_per_station + k). Only the
  // objects in a view's frustum are drawn into it (the renderer does not cull).
  std::vector<Camera> station_cameras;
  for (const Vec3& eye : stationEyes(work))
    for (const Camera& camera : viewCameras(work, eye)) station_cameras.push_back(camera);
  work.views_per_station = cameras.size();
  auto capture = [&](const std::vector<uint32_t>& ids, const Camera& camera) {
    const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
    std::vector<uint32_t> seen;
    for (uint32_t id : ids)
      if (frustum.intersects(scene_.objects[id - 1].world_bounds)) seen.push_back(id);
    return impostor::captureView(renderer_, gpu_scene_, seen, camera, options_.base.capture);
  };
  work.layer_captures.assign(work.result.layers.size(), {});
  for (size_t l = 0; l < work.result.layers.size(); ++l)
    for (const Camera& camera : station_cameras)
      work.layer_captures[l].push_back(capture(work.result.layers[l].objects, camera));
  work.single_captures.clear();
  if (options_.single_mesh)
    for (const Camera& camera : station_cameras) work.single_captures.push_back(capture(far, camera));
  work.capture_ms = capture_timer.milliseconds();
}

// Stations are placed every station_spacing metres; a layer whose first station's region already reaches far needs
// no more. Along the centreline each station covers [s_j - back, s_j + reach_j] at the bake's bound; the greedy
// interval cover from the cell's start keeps the fewest stations that cover as much of the cell as they can, and
// drops the rest with their views (geometry is what a viewpoint no kept station covers gets anyway).
void PipelineRunner::pruneStations(store::StoredLayer& layer, std::vector<impostor::DepthMeshImpostor>& views,
                                   const CellWork& work) const {
  const size_t stations = layer.validity.size();
  if (stations <= 1) return;
  const Vec2 start(work.p_eye);
  std::vector<double> from(stations), to(stations);
  for (size_t j = 0; j < stations; ++j) {
    const impostor::ValidityRegion& r = layer.validity[j];
    const double at = glm::length(Vec2(r.origin) - start);
    from[j] = at - double(r.back);
    to[j] = at + r.reach(threshold_);  // -inf when not valid even at the station
  }
  const double length = glm::length(Vec2(work.q_eye) - start);
  std::vector<uint8_t> keep(stations, 0);
  keep[0] = 1;  // the cell's start: the runtime enters there
  double covered = to[0];
  while (covered < length) {
    size_t best = stations;
    for (size_t j = 1; j < stations; ++j)
      if (!keep[j] && from[j] <= std::max(covered, 0.0) + 1e-6 && to[j] > covered && (best == stations || to[j] > to[best]))
        best = j;
    if (best == stations) {
      // A gap no station covers: the next station that covers anything beyond it starts a new run.
      for (size_t j = 1; j < stations; ++j)
        if (!keep[j] && to[j] > covered && from[j] > covered && (best == stations || from[j] < from[best])) best = j;
      if (best == stations) break;
    }
    keep[best] = 1;
    covered = to[best];
  }
  std::vector<uint32_t> renumber(stations, 0);
  std::vector<impostor::ValidityRegion> kept_regions;
  for (size_t j = 0; j < stations; ++j)
    if (keep[j]) {
      renumber[j] = uint32_t(kept_regions.size());
      kept_regions.push_back(std::move(layer.validity[j]));
    }
  std::vector<store::StoredView> kept_records;
  std::vector<impostor::DepthMeshImpostor> kept_views;
  for (size_t v = 0; v < layer.views.size(); ++v)
    if (keep[layer.views[v].station]) {
      kept_records.push_back(std::move(layer.views[v]));
      kept_records.back().station = renumber[kept_records.back().station];
      kept_views.push_back(std::move(views[v]));
    }
  layer.validity = std::move(kept_regions);
  layer.views = std::move(kept_records);
  views = std::move(kept_views);
}

void PipelineRunner::buildMeshes(CellWork& work) const {
  Stopwatch timer;
  auto build = [&](const impostor::ImpostorCapture& capture) {
    if (options_.mesh == LayerMesh::Grid) {
      impostor::GridMeshOptions o;
      o.grid_spacing_px = double(capture.camera.width) / double(options_.grid_cells);
      return impostor::buildGridMesh(capture, o);
    }
    impostor::DepthMeshOptions o = options_.base.depth_mesh;
    o.resolution = capture.camera.width;
    o.fov_y = capture.camera.fov_y;
    return impostor::buildDepthMesh(capture, o);
  };
  work.layer_views.assign(work.layer_captures.size(), {});
  for (size_t l = 0; l < work.layer_captures.size(); ++l)
    for (const impostor::ImpostorCapture& c : work.layer_captures[l]) work.layer_views[l].push_back(build(c));
  work.single_views.clear();
  for (const impostor::ImpostorCapture& c : work.single_captures) work.single_views.push_back(build(c));
  // Counts into the record (file names are the bake's business).
  for (size_t l = 0; l < work.layer_views.size(); ++l) {
    work.result.layers[l].views.assign(work.layer_views[l].size(), {});
    for (size_t v = 0; v < work.layer_views[l].size(); ++v) {
      store::StoredView& sv = work.result.layers[l].views[v];
      sv.camera = work.layer_captures[l][v].camera;
      sv.triangles = work.layer_views[l][v].mesh.triangleCount();
      sv.vertices = work.layer_views[l][v].mesh.vertexCount();
      sv.data_pixels = work.layer_captures[l][v].data_pixels;
      sv.render_ms = work.layer_captures[l][v].render_ms;
    }
  }
  work.result.single.views.assign(work.single_views.size(), {});
  for (size_t v = 0; v < work.single_views.size(); ++v) {
    store::StoredView& sv = work.result.single.views[v];
    sv.camera = work.single_captures[v].camera;
    sv.triangles = work.single_views[v].mesh.triangleCount();
    sv.vertices = work.single_views[v].mesh.vertexCount();
    sv.data_pixels = work.single_captures[v].data_pixels;
    sv.render_ms = work.single_captures[v].render_ms;
  }
  // Validity regions (bake/validity_region.h), per station from its views' triangles and captured depth. The scan
  // runs up to a few times the bake's bound so that a runtime asking for a looser bound still finds its region.
  const double stop = std::max(4.0 * threshold_, 0.05);
  const float street_width = cells_.graph().width(work.cell);
  const size_t per_station = std::max<size_t>(1, work.views_per_station);
  auto regions = [&](store::StoredLayer& layer, std::vector<impostor::DepthMeshImpostor>& views,
                     const std::vector<impostor::ImpostorCapture>& captures) {
    if (views.empty()) return;
    std::vector<Polygon2> footprints;
    std::vector<Box3> bounds;
    for (uint32_t id : layer.objects) {
      footprints.push_back(footprintOf(scene_.objects[id - 1]));
      bounds.push_back(scene_.objects[id - 1].world_bounds);
    }
    std::erase_if(footprints, [](const Polygon2& f) { return f.empty(); });
    const size_t stations = views.size() / per_station;
    layer.validity.clear();
    for (size_t j = 0; j < stations; ++j) {
      std::vector<impostor::TriangleError> triangles;
      for (size_t v = j * per_station; v < (j + 1) * per_station; ++v) {
        const std::vector<impostor::TriangleError> t =
            impostor::triangleErrors(views[v], captures[v].depth, captures[v].camera);
        triangles.insert(triangles.end(), t.begin(), t.end());
        layer.views[v].station = uint32_t(j);
      }
      layer.validity.push_back(computeValidityRegion(captures[j * per_station].camera.eye, work.q_eye, street_width,
                                                     bounds, triangles, footprints, stop, options_.validity));
    }
    pruneStations(layer, views, work);
  };
  for (size_t l = 0; l < work.result.layers.size(); ++l)
    regions(work.result.layers[l], work.layer_views[l], work.layer_captures[l]);
  regions(work.result.single, work.single_views, work.single_captures);
  work.layer_captures.clear();
  work.single_captures.clear();
  work.build_ms = timer.milliseconds();
}

// ---------------------------------------------------------------------------------------------------------------
// Storage (section 5.1)

nlohmann::json storageReport(const store::StoreIndex& index, const std::string& dir, const PipelineOptions& options,
                             size_t city_cells) {
  size_t cells = 0, layers = 0, layer_views = 0, single_views = 0;
  uint64_t texture_bytes = 0, mesh_bytes = 0, raw_texture_bytes = 0, id_bytes = 0;
  auto file_bytes = [&](const std::string& name) -> uint64_t {
    if (name.empty()) return 0;
    std::error_code ec;
    const uintmax_t n = fs::file_size(fs::path(dir) / name, ec);
    return ec ? 0 : uint64_t(n);
  };
  auto count_view = [&](const store::StoredView& v) {
    texture_bytes += file_bytes(v.texture);
    mesh_bytes += file_bytes(v.mesh);
    id_bytes += file_bytes(v.ids);
    if (!v.texture.empty()) raw_texture_bytes += uint64_t(v.camera.width) * uint64_t(v.camera.height) * 4;
  };
  for (const store::CellEntry& c : index.cells) {
    if (!c.pipeline || !c.pipeline->has_mmi) continue;
    ++cells;
    layers += c.pipeline->layers.size();
    for (const store::StoredLayer& l : c.pipeline->layers)
      for (const store::StoredView& v : l.views) {
        ++layer_views;
        count_view(v);
      }
    for (const store::StoredView& v : c.pipeline->single.views) {
      ++single_views;
      count_view(v);
    }
  }
  const int views = options.views == LayerViews::Six ? 6 : 1;
  const double image = double(options.base.resolution) * double(options.base.resolution) * 3.0;  // RGB, as the paper
  const double grid = double(options.grid_cells) * double(options.grid_cells) * 3.0 * 4.0;      // float xyz
  const double mean_layers = cells ? double(layers) / double(cells) : 0.0;
  nlohmann::json j;
  j["cells"] = cells;
  j["layers"] = layers;
  j["mean_layers"] = mean_layers;
  j["views_per_layer"] = views;
  j["image_bytes_each"] = image;
  j["mesh_bytes_each"] = grid;
  j["estimate_bytes_measured_layers"] = double(layer_views) * (image + grid);
  j["estimate_bytes_3_layers"] = double(cells) * 3.0 * double(views) * (image + grid);
  j["estimate_bytes_paper_city"] = 572.0 * 18.0 * (256.0 * 256.0 * 3.0 + 10800.0);  // section 5.1's own numbers
  j["written_texture_bytes"] = texture_bytes;
  j["written_mesh_bytes"] = mesh_bytes;
  j["written_bytes"] = texture_bytes + mesh_bytes;
  j["written_id_bytes"] = id_bytes;  // per-texel object ids: for measurement (item buffers), not for the picture
  j["uncompressed_texture_bytes"] = raw_texture_bytes;
  j["single_mesh_views"] = single_views;
  if (city_cells > 0 && cells > 0) {
    j["city_cells"] = city_cells;
    j["estimate_bytes_city"] = double(city_cells) * mean_layers * double(views) * (image + grid);
    j["projected_written_bytes_city"] = double(city_cells) * double(texture_bytes + mesh_bytes) / double(cells);
  }
  return j;
}

// ---------------------------------------------------------------------------------------------------------------
// The bake

namespace {

struct PipelineJob {
  CellWork work;
  store::CellEntry entry;
};

}  // namespace

PipelineReport bakePipeline(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                            std::vector<uint32_t> half_edges, const PipelineSpec& spec,
                            const PipelineOptions& options, const std::string& out_dir) {
  validatePipelineOptions(options);
  if (spec.stages.empty()) throw Error("--pipeline", "no stages given");
  if (options.base.workers < 0) throw Error("--workers", "must be 0 (automatic) or more");
  if (cells.objectCount() != scene.objects.size())
    throw Error("bake", "the cell map was made for " + std::to_string(cells.objectCount()) +
                            " objects but the scene has " + std::to_string(scene.objects.size()));
  Stopwatch wall;
  PipelineReport report;
  report.store_dir = out_dir;
  CellSelection selection = selectCells(cells, std::move(half_edges));
  const std::vector<uint32_t> todo = std::move(selection.todo);
  report.skipped_degenerate = std::move(selection.skipped_degenerate);
  report.requested = selection.requested;
  {
    std::error_code ec;
    fs::create_directories(fs::path(out_dir) / "cells", ec);
    if (ec) throw Error(out_dir, "cannot create the store directory: " + ec.message());
  }
  // A new generation of files next to those of the store being replaced (which stays readable until the new index
  // is in place: store/impostor_store.h).
  store::StoreIndex index;
  index.generation = store::nextGeneration(out_dir);
  const uint64_t generation = index.generation;
  store::writeStreets(out_dir, index, cells.graph().toJson().dump() + "\n");

  const std::vector<std::string> baked = spec.baked();
  const bool bake_mmi = contains(baked, kStageMmi);
  const size_t workers = workerCount(options.base.workers);
  report.workers = workers;

  std::mutex results_mutex;
  std::vector<store::CellEntry> entries;
  std::vector<PipelineCellReport> records;
  context.makeCurrent();
  gpu::GpuScene gpu_scene(scene);
  PipelineRunner runner(scene, gpu_scene, cells, options);  // outlives the workers, which build meshes with it
  const auto produce = [&](const std::function<bool(std::shared_ptr<PipelineJob>)>& push) {
    for (uint32_t cell : todo) {
      auto job = std::make_shared<PipelineJob>();
      job->work = runner.start(cell);
      for (const std::string& stage : baked) runner.runStage(stage, job->work);
      store::CellEntry& e = job->entry;
      e.half_edge = cell;
      e.camera = job->work.street_camera;
      e.local_objects = cells.localObjects(cell);
      e.distant_objects = cells.distantObjects(cell).size();
      e.render_ms = job->work.capture_ms;
      if (!push(std::move(job))) return;
    }
  };
  const auto consume = [&](PipelineJob& job) {
    CellWork& w = job.work;
    if (bake_mmi) {
      runner.buildMeshes(w);
      // The construction is timed per cell: each view gets an equal share.
      size_t views = w.single_views.size();
      for (const auto& layer : w.layer_views) views += layer.size();
      const double build_share = views ? w.build_ms / double(views) : 0.0;
      const auto write = [&](store::StoredView& record, const impostor::DepthMeshImpostor& view, const char* kind,
                             size_t layer, size_t index) {
        const store::StoredView written =
            store::writeLayerView(out_dir, store::layerFileStem(w.cell, kind, layer, index, generation), view);
        record.texture = written.texture;
        record.texture_check = written.texture_check;
        record.mesh = written.mesh;
        record.mesh_check = written.mesh_check;
        record.ids = written.ids;
        record.ids_check = written.ids_check;
        record.build_ms = build_share;
      };
      for (size_t l = 0; l < w.layer_views.size(); ++l)
        for (size_t v = 0; v < w.layer_views[l].size(); ++v)
          write(w.result.layers[l].views[v], w.layer_views[l][v], "mmi", l, v);
      for (size_t v = 0; v < w.single_views.size(); ++v) write(w.result.single.views[v], w.single_views[v], "smi", 0, v);
    }
    PipelineCellReport r;
    r.half_edge = w.cell;
    r.pvs = w.result.pvs.size();
    r.near = w.result.near.size();
    r.far = w.result.far.size();
    r.layers = w.result.layers.size();
    for (const store::StoredLayer& l : w.result.layers)
      for (const store::StoredView& v : l.views) r.layer_triangles += v.triangles;
    for (const store::StoredView& v : w.result.single.views) r.single_triangles += v.triangles;
    r.pvs_ms = w.result.pvs_ms;
    r.weights_ms = w.result.weights_ms;
    r.capture_ms = w.capture_ms;
    r.build_ms = w.build_ms;
    job.entry.pipeline = std::move(w.result);
    w.layer_views.clear();
    w.single_views.clear();
    std::lock_guard<std::mutex> lock(results_mutex);
    records.push_back(r);
    entries.push_back(std::move(job.entry));
  };
  produceAndConsume<PipelineJob>(workers, options.base.queue_capacity,
                                 options.base.progress ? "bake pipeline" : "", todo.size(), produce, consume);
  const double threshold = runner.threshold();

  std::sort(entries.begin(), entries.end(),
            [](const store::CellEntry& a, const store::CellEntry& b) { return a.half_edge < b.half_edge; });
  std::sort(records.begin(), records.end(),
            [](const PipelineCellReport& a, const PipelineCellReport& b) { return a.half_edge < b.half_edge; });

  index.scene = options.base.scene_label;
  index.scene_objects = scene.objects.size();
  index.local_model = urban::localModelName(cells.options().local);
  index.cell_lookup = urban::cellLookupName(cells.options().lookup);
  index.pipeline = spec.stages;
  index.online = spec.online();
  index.options = {{"pipeline", pipelineOptionsToJson(options)}, {"block_margin", cells.options().block_margin}};
  index.cells = std::move(entries);
  index.storage = storageReport(index, out_dir, options, cells.cellCount());
  store::writeIndex(out_dir, index);

  report.cells = std::move(records);
  report.threshold_rad = threshold;
  report.storage = index.storage;
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake
