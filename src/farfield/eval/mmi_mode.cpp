// The Table 1 modes of Decoret et al. 1999 over a pipeline store, and the dynamic updates of section 5.5.
#include "farfield/runtime/mmi_mode.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/timer.h"
#include "farfield/runtime/impostor_mode.h"

namespace fs = std::filesystem;

namespace farfield::runtime {

namespace {

constexpr size_t kDefaultCache = 16;

double numberOption(const eval::ModeContext& context, const std::string& key, double fallback, double lo) {
  const std::string text = context.option(key);
  if (text.empty()) return fallback;
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v) || v < lo) throw std::invalid_argument("range");
    return v;
  } catch (const std::exception&) {
    throw Error("--mode-option " + key, "expected a number >= " + std::to_string(lo) + ", got '" + text + "'");
  }
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

const char* mmiKindName(MmiKind kind) {
  switch (kind) {
    case MmiKind::Local: return "local";
    case MmiKind::Visible: return "visible";
    case MmiKind::Smi: return "smi";
    case MmiKind::Mmi: return "mmi";
    case MmiKind::MmiDynamic: return "mmi-dynamic";
  }
  return "?";
}

void registerMmiModes() {
  const auto add = [](MmiKind kind, const char* description) {
    eval::registerMode(mmiKindName(kind), description, [kind](const eval::ModeContext& c) {
      return std::make_unique<MmiMode>(kind, c);
    });
  };
  add(MmiKind::Local, "the cell's near geometry only, frustum-culled: upper bound of the frame rate (Decoret 1999); "
                      "--impostors DIR from bake --pipeline");
  add(MmiKind::Visible, "the cell's potentially visible set, frustum-culled (Decoret 1999); --impostors DIR");
  add(MmiKind::Smi, "near geometry + single-mesh impostor of the far objects (Decoret 1999); --impostors DIR");
  add(MmiKind::Mmi, "near geometry + multi-mesh impostor, one mesh per layer (Decoret 1999); --impostors DIR");
  add(MmiKind::MmiDynamic, "mmi with dynamic updates of the front-most layers under a frame budget "
                           "(Decoret 1999, 5.5); --impostors DIR, --mode-option frame_budget_ms=MS");
}

MmiMode::MmiMode(MmiKind kind, const eval::ModeContext& context) : kind_(kind) {
  dir_ = context.option("mmi_dir", context.option("impostor_dir"));
  if (dir_.empty())
    throw Error(std::string("mode '") + mmiKindName(kind_) + "'",
                "needs a pipeline store: farfield bench --impostors DIR (or --mode-option impostor_dir=DIR), baked "
                "with farfield bake --pipeline pvs,near-far,mmi");
  cache_capacity_ = positiveOption(context, "impostor_cache", kDefaultCache);
  const std::string ids = context.option("impostor_ids", "object");
  if (ids != "object" && ids != "layer")
    throw Error("--mode-option impostor_ids", "expected object or layer, got '" + ids + "'");
  object_ids_ = ids == "object";
  dynamic_options_.object_ids = object_ids_;
  lookup_option_ = context.option("cell_lookup");
  if (!lookup_option_.empty()) urban::parseCellLookup(lookup_option_, "--mode-option cell_lookup");
  budget_ms_ = numberOption(context, "frame_budget_ms", budget_ms_, 0.0);
  dynamic_error_px_ = numberOption(context, "dynamic_error_px", dynamic_error_px_, 0.0);
  dynamic_options_.resolution = int(numberOption(context, "dynamic_resolution", 0.0, 0.0));
  dynamic_options_.grid_px = int(numberOption(context, "dynamic_grid_px", dynamic_options_.grid_px, 1.0));
  max_updates_ = positiveOption(context, "dynamic_max_updates", max_updates_);
  min_lifetime_frames_ = numberOption(context, "dynamic_min_lifetime", min_lifetime_frames_, 0.0);
  error_px_ = numberOption(context, "error_px", 0.0, 0.0);
}

MmiMode::~MmiMode() = default;

void MmiMode::prepare(const eval::ModeContext& context) {
  context_ = &context;
  const scene::Scene& scene = *context.scene;
  OpenStore opened = openStore(dir_, scene, lookup_option_);
  index_ = std::move(opened.index);
  graph_ = std::move(opened.graph);
  locator_ = std::move(opened.locator);
  const std::string& index_file = opened.index_file;
  const std::string me = std::string("mode '") + mmiKindName(kind_) + "'";
  if (index_.pipeline.empty())
    throw Error(index_file, "holds no pipeline data (" + me + " needs a store baked with farfield bake --pipeline "
                            "pvs,near-far,mmi)");
  {
    // The stage lists must make a valid pipeline (known stages, in order, online a tail).
    std::string stages, online;
    for (const std::string& st : index_.pipeline) stages += (stages.empty() ? "" : ",") + st;
    for (const std::string& st : index_.online) online += (online.empty() ? "" : ",") + st;
    try {
      bake::parsePipeline(stages, online);
    } catch (const Error& e) {
      throw Error(index_file, std::string("bad \"pipeline\"/\"online\": ") + e.what());
    }
  }
  std::vector<std::string> baked;
  for (const std::string& s : index_.pipeline)
    if (!contains(index_.online, s)) baked.push_back(s);
  const char* needed = kind_ == MmiKind::Visible ? bake::kStagePvs
                       : kind_ == MmiKind::Local ? bake::kStageNearFar
                                                 : bake::kStageMmi;
  if (!contains(index_.pipeline, needed))
    throw Error(index_file, "its pipeline has no " + std::string(needed) + " stage, which " + me + " needs");
  if (kind_ == MmiKind::Visible && !contains(baked, bake::kStagePvs))
    throw Error(index_file, me + " needs the pvs stage baked");
  for (const std::string& s : index_.online) {
    // Stages this mode needs that the bake left to the runtime.
    const bool needs = kind_ == MmiKind::Local ? s == bake::kStageNearFar
                       : kind_ == MmiKind::Visible ? false
                                                   : true;
    if (needs) online_stages_.push_back(s);
  }
  const nlohmann::json stored_options =
      index_.options.contains("pipeline") ? index_.options["pipeline"] : nlohmann::json::object();
  const bake::PipelineOptions pipeline_options =
      bake::pipelineOptionsFromJson(stored_options, index_file + ": options.pipeline", index_.version);
  if (error_px_ <= 0.0) error_px_ = pipeline_options.error_px;
  if (!online_stages_.empty()) {
    urban::CellOptions cell_options;
    cell_options.local = urban::parseLocalModel(index_.local_model, index_file + ": local_model");
    if (index_.options.contains("block_margin") && index_.options["block_margin"].is_number())
      cell_options.block_margin = index_.options["block_margin"].get<float>();
    cell_map_ = std::make_unique<urban::CellMap>(graph_, scene, cell_options);
    runner_ = std::make_unique<bake::PipelineRunner>(scene, *context.gpu_scene, *cell_map_, pipeline_options);
  }
  invalid_object_.assign(scene.objects.size() + 1, 0);
  object_triangles_.assign(scene.objects.size() + 1, 0);
  for (const scene::Object& o : scene.objects)
    for (const scene::Part& p : o.parts) object_triangles_[o.id] += scene.meshes[p.mesh].triangleCount();
  layer_id_base_ = uint32_t(scene.objects.size() + 1);
  if (kind_ == MmiKind::MmiDynamic) {
    // A few tenths of a second on llvmpipe: cap the triangles per workload so big scenes calibrate as fast.
    CalibrationOptions calibration;
    calibration.max_triangles = 400000;
    // From where the walkthrough looks: the creation cameras of up to three stored cells (street level, along the
    // street). An overview of the city overdraws differently and mispredicted street frames by a factor of several.
    for (size_t k = 0; k < 3 && k < index_.cells.size(); ++k) {
      Camera view = index_.cells[k * (index_.cells.size() - 1) / 2].camera;
      view.width = context.width;
      view.height = context.height;
      calibration.views.push_back(view);
    }
    cost_ = calibrateCostModel(*context.renderer, *context.gpu_scene, calibration);
  }
}

std::unique_ptr<MmiMode::Cell> MmiMode::loadCell(const store::CellEntry& entry) {
  const scene::Scene& scene = *context_->scene;
  if (!entry.pipeline)
    throw Error(dir_, "cell " + std::to_string(entry.half_edge) + " has no pipeline record");
  store::CellPipeline record = *entry.pipeline;
  bake::CellWork work;
  auto cell = std::make_unique<Cell>();
  if (!online_stages_.empty()) {
    Stopwatch timer;
    work = runner_->resume(entry.half_edge, record);
    runner_->runStages(online_stages_, work);
    record = work.result;
    online_ms_total_ += timer.milliseconds();
    ++online_runs_;
    cell->online = true;
  }
  cell->geometry_mask.assign(scene.objects.size() + 1, 0);
  const std::vector<uint32_t>& geometry = kind_ == MmiKind::Visible ? record.pvs : record.near;
  for (uint32_t id : geometry) cell->geometry_mask[id] = 1;
  if (kind_ == MmiKind::Local || kind_ == MmiKind::Visible) return cell;

  impostor::GpuImpostorOptions gpu_options;
  gpu_options.id_texture = object_ids_;  // per-pixel object ids in item buffers, one draw call per view
  const bool single = kind_ == MmiKind::Smi;
  const std::vector<store::StoredLayer> layers = single ? std::vector<store::StoredLayer>{record.single}
                                                        : record.layers;
  for (size_t l = 0; l < layers.size(); ++l) {
    Layer layer;
    layer.objects = layers[l].objects;
    layer.validity = layers[l].validity;
    for (uint32_t id : layer.objects) {
      layer.bounds.expand(scene.objects[id - 1].world_bounds);
      layer.geometry_triangles += object_triangles_[id];
    }
    for (size_t v = 0; v < layers[l].views.size(); ++v) {
      impostor::DepthMeshImpostor imp;
      if (cell->online)
        imp = single ? std::move(work.single_views[v]) : std::move(work.layer_views[l][v]);
      else
        imp = store::loadLayerView(dir_, layers[l].views[v]);
      if (imp.empty()) continue;
      layer.view_eyes.push_back(imp.camera.eye);
      layer.view_station.push_back(layers[l].views[v].station);
      layer.views.push_back(std::make_unique<impostor::GpuImpostor>(imp, gpu_options));
      cell->impostor_triangles += layer.views.back()->triangleCount();
    }
    cell->layers.push_back(std::move(layer));
  }
  return cell;
}

MmiMode::Cell& MmiMode::cell(uint32_t half_edge) {
  const auto it = cells_.find(half_edge);
  if (it != cells_.end()) {
    order_.remove(half_edge);
    order_.push_front(half_edge);
    return *it->second;
  }
  const store::CellEntry* entry = index_.find(half_edge);
  FF_CHECK(entry != nullptr);
  Stopwatch timer;
  std::unique_ptr<Cell> loaded = loadCell(*entry);
  const double ms = timer.milliseconds();
  ++loads_;
  load_ms_total_ += ms;
  load_ms_max_ = std::max(load_ms_max_, ms);
  while (cells_.size() >= cache_capacity_ && !order_.empty()) {
    cells_.erase(order_.back());
    order_.pop_back();
    ++evictions_;
  }
  order_.push_front(half_edge);
  return *(cells_[half_edge] = std::move(loaded));
}

void MmiMode::frame(eval::FrameContext& frame) {
  const Camera& camera = frame.camera();
  ++frames_;
  const uint32_t half_edge = locator_.lookup(graph_, camera.eye, camera.at - camera.eye);
  const store::CellEntry* entry = half_edge == urban::kNone ? nullptr : index_.find(half_edge);
  ids_.clear();
  context_->bvh->queryFrustum(Frustum::fromMatrix(camera.viewProjection()), ids_);
  Cell* current = nullptr;
  // Layers whose validity region does not hold this viewpoint under the bound become geometry.
  const ErrorBound bound = ErrorBound::forCamera(error_px_, camera);
  bound_rad_ = bound.angle();
  // Per layer: the station drawn, kAllViews (no validity regions: every view, unchecked) or kGeometry.
  constexpr int kAllViews = -1, kGeometry = -2;
  std::vector<int>& layer_station = layer_station_;
  if (entry) {
    ++visited_[half_edge];
    current = &cell(half_edge);
    // Fast motion and stale dynamic impostors first: a layer that loses its dynamic impostor is judged by its
    // baked views' validity below.
    if (kind_ == MmiKind::MmiDynamic) dropStaleDynamic(camera, *current);
    layer_station.assign(current->layers.size(), kAllViews);
    bool any_invalid = false;
    for (size_t l = 0; l < current->layers.size(); ++l) {
      const Layer& layer = current->layers[l];
      if (layer.dynamic || layer.views.empty()) continue;
      if (layer.validity.empty()) {
        ++unchecked_layer_draws_;
        continue;
      }
      // The bound where the layer is drawn: a layer near the frame's centre may move by a larger angle per pixel.
      const double theta = bound.angleWithin(frameRadius(camera, layer.bounds));
      double best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < layer.validity.size(); ++j) {
        const double e = layer.validity[j].errorAt(camera.eye);
        if (e <= theta && e < best) {
          best = e;
          layer_station[l] = int(j);
        }
      }
      if (layer_station[l] >= 0) continue;
      layer_station[l] = kGeometry;
      any_invalid = true;
      ++invalid_layer_draws_;
      for (uint32_t id : layer.objects) invalid_object_[id] = 1;
    }
    if (any_invalid) ++invalid_frames_;
    uint64_t invalid_triangles = 0;
    ids_.erase(std::remove_if(ids_.begin(), ids_.end(),
                              [&](uint32_t id) {
                                if (current->geometry_mask[id]) return false;
                                if (!invalid_object_[id]) return true;
                                invalid_triangles += object_triangles_[id];
                                return false;
                              }),
               ids_.end());
    invalid_triangles_sum_ += double(invalid_triangles);
    if (any_invalid)
      for (size_t l = 0; l < current->layers.size(); ++l)
        if (layer_station[l] == kGeometry)
          for (uint32_t id : current->layers[l].objects) invalid_object_[id] = 0;
  } else {
    ++fallback_frames_;  // not baked: everything in the frustum, as the culled mode
  }
  std::sort(ids_.begin(), ids_.end());
  // GpuScene::appendDrawItems takes an empty list as "all objects".
  if (!ids_.empty()) context_->gpu_scene->appendDrawItems(ids_, frame.items());
  uint64_t geometry_triangles = 0;
  for (uint32_t id : ids_) geometry_triangles += object_triangles_[id];
  geometry_triangles_sum_ += double(geometry_triangles);
  if (!current || current->layers.empty()) return;

  if (kind_ == MmiKind::MmiDynamic) updateDynamic(frame, *current, geometry_triangles, frame.items().size());
  ++impostor_frames_;
  layers_sum_ += double(current->layers.size());
  for (size_t l = 0; l < current->layers.size(); ++l) {
    const Layer& layer = current->layers[l];
    const uint32_t id = layer_id_base_ + uint32_t(l);
    if (layer_station[l] == kGeometry) continue;  // drawn as geometry above
    if (layer.dynamic) {
      layer.dynamic->appendDrawItems(frame.items(), id);
      impostor_triangles_sum_ += double(layer.dynamic->triangleCount());
      dynamic_layers_sum_ += 1.0;
      continue;
    }
    for (size_t v = 0; v < layer.views.size(); ++v) {
      if (layer_station[l] >= 0 && layer.view_station[v] != uint32_t(layer_station[l])) continue;
      layer.views[v]->appendDrawItems(frame.items(), id);
      impostor_triangles_sum_ += double(layer.views[v]->triangleCount());
    }
  }
}

// Section 5.5. The order of the steps: fast motion first (it drops every dynamic impostor), then validity of the
// ones kept, then the prediction of this frame's cost, then updates in decreasing error angle while they fit.
void MmiMode::dropStaleDynamic(const Camera& camera, Cell& cell) {
  dynamic_threshold_rad_ = ErrorBound::forCamera(dynamic_error_px_, camera).angle();
  const double threshold = dynamic_threshold_rad_;

  // Fast motion: the error a fresh impostor of the nearest layer would gather per frame at this speed.
  bool fast = false;
  if (has_previous_) {
    double growth = 0.0;
    for (const Layer& layer : cell.layers) growth = std::max(growth, errorAngle(previous_eye_, camera.eye, layer.bounds));
    fast = growth * min_lifetime_frames_ > threshold;
  }
  previous_eye_ = camera.eye;
  has_previous_ = true;
  if (fast) {
    ++fast_frames_;
    for (Layer& layer : cell.layers) layer.dynamic.reset();
  }
  for (Layer& layer : cell.layers)
    if (layer.dynamic && (!layer.dynamic->covers(camera) || layer.dynamic->errorAngle(camera.eye) > threshold))
      layer.dynamic.reset();
  fast_ = fast;
}

void MmiMode::updateDynamic(eval::FrameContext& frame, Cell& cell, uint64_t frame_triangles, size_t frame_draws) {
  if (fast_) return;
  const Camera& camera = frame.camera();
  const double threshold = dynamic_threshold_rad_;

  // Predicted frame time of what would be drawn now.
  double triangles = double(frame_triangles);
  double draws = double(frame_draws);
  for (const Layer& layer : cell.layers) {
    if (layer.dynamic) {
      triangles += double(layer.dynamic->triangleCount());
      draws += 1.0;
    } else {
      for (const auto& view : layer.views) triangles += double(view->triangleCount());
      draws += double(layer.views.size());
    }
  }
  const double pixels = double(camera.width) * double(camera.height);
  const double predicted = cost_.predict(triangles, draws, pixels);
  predicted_ms_sum_ += predicted;
  ++predicted_frames_;
  double left = budget_ms_ - predicted;

  // Candidates: layers whose drawn representation is off by more than the threshold, worst first.
  std::vector<std::pair<double, size_t>> candidates;
  for (size_t l = 0; l < cell.layers.size(); ++l) {
    const Layer& layer = cell.layers[l];
    double error = 0.0;
    if (layer.dynamic) {
      error = layer.dynamic->errorAngle(camera.eye);
    } else {
      error = std::numeric_limits<double>::infinity();
      for (const Vec3& eye : layer.view_eyes) error = std::min(error, errorAngle(eye, camera.eye, layer.bounds));
      if (layer.view_eyes.empty()) error = 0.0;  // nothing of it in the baked views: nothing to refresh
    }
    if (error > threshold) candidates.emplace_back(error, l);
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first; });

  size_t updates = 0;
  const Camera capture = DynamicImpostor::captureCamera(camera, dynamic_options_);
  const Frustum frustum = Frustum::fromMatrix(capture.viewProjection());
  const double capture_pixels = double(capture.width) * double(capture.height);
  for (const auto& [error, l] : candidates) {
    if (updates >= max_updates_) break;
    Layer& layer = cell.layers[l];
    ids_.clear();
    uint64_t layer_triangles = 0;
    for (uint32_t id : layer.objects)
      if (frustum.intersects(context_->scene->objects[id - 1].world_bounds)) {
        ids_.push_back(id);
        layer_triangles += object_triangles_[id];
      }
    if (ids_.empty()) continue;
    std::vector<gpu::DrawItem> items;
    context_->gpu_scene->appendDrawItems(ids_, items);
    const double cost = cost_.predict(double(layer_triangles), double(items.size()), capture_pixels) +
                        update_overhead_ms_;
    if (cost > left) {
      ++skipped_for_budget_;
      continue;
    }
    frame.beginOwnPass();
    layer.dynamic = std::make_unique<DynamicImpostor>(frame.renderer(), items, camera, layer.bounds, dynamic_options_);
    const double actual = layer.dynamic->updateMs();
    // What the model does not see (readback, quantisation, meshing, upload), learnt as a running mean.
    const double render_part = cost - update_overhead_ms_;
    update_overhead_ms_ = updates_ == 0 ? std::max(0.0, actual - render_part)
                                        : 0.8 * update_overhead_ms_ + 0.2 * std::max(0.0, actual - render_part);
    predicted_update_error_ms_ += std::abs(actual - cost);
    left -= actual;
    ++updates;
    ++updates_;
    update_ms_total_ += actual;
    update_ms_max_ = std::max(update_ms_max_, actual);
    frame.addStats({layer_triangles, uint32_t(items.size()), uint32_t(ids_.size()), 0.0, 0.0});
  }
}

std::map<std::string, double> MmiMode::info() const {
  std::map<std::string, double> out;
  const double n = frames_ ? double(frames_) : 1.0;
  out["frames"] = double(frames_);
  out["fallback_frames"] = double(fallback_frames_);
  out["cells_visited"] = double(visited_.size());
  out["baked_cells"] = double(index_.cells.size());
  out["cell_loads"] = double(loads_);
  out["cell_load_ms_max"] = load_ms_max_;
  out["cell_load_ms_mean"] = loads_ ? load_ms_total_ / double(loads_) : 0.0;
  out["cache_evictions"] = double(evictions_);
  out["online_runs"] = double(online_runs_);
  out["online_ms_mean"] = online_runs_ ? online_ms_total_ / double(online_runs_) : 0.0;
  out["mean_geometry_triangles"] = geometry_triangles_sum_ / n;
  if (kind_ != MmiKind::Local && kind_ != MmiKind::Visible) {
    const double f = impostor_frames_ ? double(impostor_frames_) : 1.0;
    out["mean_impostor_triangles"] = impostor_triangles_sum_ / f;
    out["mean_layers"] = layers_sum_ / f;
    out["error_bound_px"] = error_px_;
    out["error_bound_rad"] = bound_rad_;
    out["invalid_layer_draws"] = double(invalid_layer_draws_);
    out["unchecked_layer_draws"] = double(unchecked_layer_draws_);
    out["frames_with_invalid_layers"] = double(invalid_frames_);
    out["mean_invalid_layer_triangles"] = invalid_triangles_sum_ / n;
  }
  if (kind_ == MmiKind::MmiDynamic) {
    out["frame_budget_ms"] = budget_ms_;
    out["dynamic_threshold_rad"] = dynamic_threshold_rad_;
    out["updates"] = double(updates_);
    out["update_ms_mean"] = updates_ ? update_ms_total_ / double(updates_) : 0.0;
    out["update_ms_max"] = update_ms_max_;
    out["update_prediction_error_ms_mean"] = updates_ ? predicted_update_error_ms_ / double(updates_) : 0.0;
    out["updates_skipped_for_budget"] = double(skipped_for_budget_);
    out["fast_motion_frames"] = double(fast_frames_);
    out["mean_dynamic_layers"] = impostor_frames_ ? dynamic_layers_sum_ / double(impostor_frames_) : 0.0;
    // Frames that were not fast motion (the prediction is made only where updates are considered).
    out["predicted_frame_ms_mean"] = predicted_frames_ ? predicted_ms_sum_ / double(predicted_frames_) : 0.0;
    out["cost_base_ms"] = cost_.base_ms;
    out["cost_ms_per_mtriangle"] = cost_.ms_per_mtriangle;
    out["cost_ms_per_draw"] = cost_.ms_per_draw;
    out["cost_ms_per_mpixel"] = cost_.ms_per_mpixel;
    out["cost_fit_r2"] = cost_.r2;
  }
  return out;
}

}  // namespace farfield::runtime
