#include "farfield/extract/pipeline_runner.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <limits>
#include <type_traits>
#include <set>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/grid_mesh.h"

namespace farfield::extract {


// ---------------------------------------------------------------------------------------------------------------
// PipelineRunner

namespace {


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
  else if (stage == kStageSingle)
    runSingle(work);
  else if (stage == kStageMmi)
    runMmi(work);
  else
    throw Error("pipeline", "unknown stage '" + stage + "'");
}

void PipelineRunner::runStages(const std::vector<std::string>& stages, CellWork& work) {
  for (const std::string& stage : stages) runStage(stage, work);
  if (work.layers_pending || work.single_pending) buildMeshes(work);
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

// Only the far objects some view shows are captured and layered: with the street view, the PVS (360 degrees) also
// holds what lies behind the viewer, which no street-facing image could hold. Moving forward along the cell keeps the
// view inside the frustum from P (a cone translated along its axis stays inside itself), so P's frustum is enough.
std::vector<uint32_t> PipelineRunner::farInView(const CellWork& work, const char* stage) const {
  if (!work.result.has_split)
    throw Error("pipeline", "cell " + std::to_string(work.cell) + ": " + stage +
                                " needs the near-far stage before it");
  std::vector<Frustum> frusta;
  for (const Camera& camera : viewCameras(work, work.p_eye)) frusta.push_back(Frustum::fromMatrix(camera.viewProjection()));
  std::vector<uint32_t> far;
  for (uint32_t id : work.result.far) {
    const Box3& b = scene_.objects[id - 1].world_bounds;
    if (std::any_of(frusta.begin(), frusta.end(), [&](const Frustum& f) { return f.intersects(b); }))
      far.push_back(id);
  }
  return far;
}

// Every station's views, station-major (view k of station j is capture j * views_per_station + k).
std::vector<Camera> PipelineRunner::stationCameras(CellWork& work) const {
  std::vector<Camera> cameras;
  for (const Vec3& eye : stationEyes(work))
    for (const Camera& camera : viewCameras(work, eye)) cameras.push_back(camera);
  work.views_per_station = viewCameras(work, work.p_eye).size();
  return cameras;
}

// Only the objects in the view's frustum are drawn into it (the renderer does not cull).
impostor::ImpostorCapture PipelineRunner::capture(const std::vector<uint32_t>& ids, const Camera& camera) {
  const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  std::vector<uint32_t> seen;
  for (uint32_t id : ids)
    if (frustum.intersects(scene_.objects[id - 1].world_bounds)) seen.push_back(id);
  return impostor::captureView(renderer_, gpu_scene_, seen, camera, options_.base.capture);
}

// The single-mesh impostor (Decoret 1999's SMI; Sillion 1997's cell impostor with one station): all far objects in
// view captured together, from every station, so nearer ones hide farther ones in one image.
void PipelineRunner::runSingle(CellWork& work) {
  const std::vector<uint32_t> far = farInView(work, kStageSingle);
  Stopwatch capture_timer;
  work.result.has_single = true;
  work.result.single = {};
  work.result.single.objects = far;
  work.single_captures.clear();
  for (const Camera& camera : stationCameras(work)) work.single_captures.push_back(capture(far, camera));
  work.single_pending = true;
  work.capture_ms += capture_timer.milliseconds();
}

// Sections 4.1-4.3: the event graph over the far objects' footprints, the greedy layering with T, then per layer and
// view a capture of that layer's objects alone (so no layer hides another in its image: what the viewer uncovers
// while walking the cell is in the layer behind).
void PipelineRunner::runMmi(CellWork& work) {
  const std::vector<uint32_t> far = farInView(work, kStageMmi);
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

  Stopwatch capture_timer;
  const std::vector<Camera> station_cameras = stationCameras(work);
  work.layer_captures.assign(work.result.layers.size(), {});
  for (size_t l = 0; l < work.result.layers.size(); ++l)
    for (const Camera& camera : station_cameras)
      work.layer_captures[l].push_back(capture(work.result.layers[l].objects, camera));
  work.layers_pending = true;
  work.capture_ms += capture_timer.milliseconds();
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
  // Counts into the record (file names are the bake's business).
  auto record = [](store::StoredView& sv, const impostor::ImpostorCapture& capture,
                   const impostor::DepthMeshImpostor& view) {
    sv.camera = capture.camera;
    sv.triangles = view.mesh.triangleCount();
    sv.vertices = view.mesh.vertexCount();
    sv.data_pixels = capture.data_pixels;
    sv.render_ms = capture.render_ms;
  };
  if (work.layers_pending) {
    work.layer_views.assign(work.layer_captures.size(), {});
    for (size_t l = 0; l < work.layer_captures.size(); ++l) {
      work.result.layers[l].views.assign(work.layer_captures[l].size(), {});
      for (size_t v = 0; v < work.layer_captures[l].size(); ++v) {
        work.layer_views[l].push_back(build(work.layer_captures[l][v]));
        record(work.result.layers[l].views[v], work.layer_captures[l][v], work.layer_views[l][v]);
      }
    }
  }
  if (work.single_pending) {
    work.single_views.clear();
    work.result.single.views.assign(work.single_captures.size(), {});
    for (size_t v = 0; v < work.single_captures.size(); ++v) {
      work.single_views.push_back(build(work.single_captures[v]));
      record(work.result.single.views[v], work.single_captures[v], work.single_views[v]);
    }
  }
  // Validity regions (extract/validity_region.h), per station from its views' triangles and captured depth. The scan
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
  if (work.layers_pending)
    for (size_t l = 0; l < work.result.layers.size(); ++l)
      regions(work.result.layers[l], work.layer_views[l], work.layer_captures[l]);
  if (work.single_pending) regions(work.result.single, work.single_views, work.single_captures);
  work.layer_captures.clear();
  work.single_captures.clear();
  work.layers_pending = work.single_pending = false;
  work.build_ms += timer.milliseconds();
}

}  // namespace farfield::extract
