#include "farfield/runtime/walkthrough.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/timer.h"
#include "farfield/runtime/database.h"
#include "farfield/runtime/prefetch.h"
#include "farfield/runtime/walkthrough_cells.h"
#include "farfield/runtime/walkthrough_placed.h"

namespace farfield::runtime {

namespace {

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

const char* representationName(Representation representation) {
  switch (representation) {
    case Representation::Local: return "local";
    case Representation::Visible: return "visible";
    case Representation::Smi: return "smi";
    case Representation::Mmi: return "mmi";
    case Representation::MmiDynamic: return "mmi-dynamic";
    case Representation::Placed: return "placed";
  }
  return "?";
}

std::optional<Representation> representationFromName(const std::string& name) {
  using R = Representation;
  for (R r : {R::Local, R::Visible, R::Smi, R::Mmi, R::MmiDynamic, R::Placed})
    if (name == representationName(r)) return r;
  return std::nullopt;
}

std::string missingStage(const store::StoreIndex& index, Representation kind) {
  const std::string me = std::string("walkthrough '") + representationName(kind) + "'";
  if (kind == Representation::Placed) return me + " needs a placement database (farfield place), not a pipeline store";
  // Smi draws the single stage's mesh (version 2 and 3 stores read with the stage where their mmi stage built it).
  const char* needed = kind == Representation::Visible ? extract::kStagePvs
                       : kind == Representation::Local ? extract::kStageNearFar
                       : kind == Representation::Smi   ? extract::kStageSingle
                                                       : extract::kStageMmi;
  if (!contains(index.pipeline, needed))
    return "its pipeline has no " + std::string(needed) + " stage, which " + me + " needs";
  if (kind == Representation::Visible && contains(index.online, extract::kStagePvs))
    return me + " needs the pvs stage baked";
  return "";
}

Walkthrough::Walkthrough(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const scene::Bvh& bvh,
                         gpu::Renderer& renderer, WalkthroughOptions options)
    : scene_(scene), gpu_scene_(gpu_scene), bvh_(bvh), renderer_(renderer), options_(std::move(options)) {
  const Representation kind = options_.representation;
  const std::string me = std::string("walkthrough '") + representationName(kind) + "'";
  if (options_.database.empty())
    throw Error(me, "needs an impostor database: a directory written by farfield bake --pipeline pvs,near-far,single,mmi (or farfield place for the placed mode)");
  if (!(options_.error_px >= 0.0) || !std::isfinite(options_.error_px))
    throw Error(me, "error bound must be a finite number of pixels >= 0");
  object_triangles_.assign(scene.objects.size() + 1, 0);
  for (const scene::Object& o : scene.objects)
    for (const scene::Part& p : o.parts) object_triangles_[o.id] += scene.meshes[p.mesh].triangleCount();
  // One budget for the database in memory: a quarter for what is read ahead, the rest for the resident impostors.
  if (options_.memory_budget_bytes > 0) {
    options_.read_ahead_bytes = options_.memory_budget_bytes / 4;
    options_.gpu_budget_bytes = options_.memory_budget_bytes - options_.read_ahead_bytes;
  }
  if (kind == Representation::Placed) {
    openPlacement();
    return;
  }
  OpenStore opened = openStore(options_.database, scene, options_.cell_lookup);
  index_ = std::move(opened.index);
  graph_ = std::move(opened.graph);
  locator_ = std::move(opened.locator);
  const std::string& index_file = opened.index_file;
  if (index_.pipeline.empty())
    throw Error(index_file, "holds no pipeline data (" + me + " needs a store baked with farfield bake --pipeline "
                            "pvs,near-far,single,mmi)");
  {
    // The stage lists must make a valid pipeline (known stages, in order, online a tail).
    std::string stages, online;
    for (const std::string& st : index_.pipeline) stages += (stages.empty() ? "" : ",") + st;
    for (const std::string& st : index_.online) online += (online.empty() ? "" : ",") + st;
    try {
      extract::parsePipeline(stages, online);
    } catch (const Error& e) {
      throw Error(index_file, std::string("bad \"pipeline\"/\"online\": ") + e.what());
    }
  }
  if (const std::string missing = missingStage(index_, kind); !missing.empty()) throw Error(index_file, missing);
  for (const std::string& s : index_.online) {
    // Stages this representation needs that the bake left to the runtime.
    const bool needs = kind == Representation::Local     ? s == extract::kStageNearFar
                       : kind == Representation::Visible ? false
                       : kind == Representation::Smi     ? s != extract::kStageMmi
                                                         : s != extract::kStageSingle;
    if (needs) online_stages_.push_back(s);
  }
  const nlohmann::json stored_options =
      index_.options.contains("pipeline") ? index_.options["pipeline"] : nlohmann::json::object();
  const extract::PipelineOptions pipeline_options =
      extract::pipelineOptionsFromJson(stored_options, index_file + ": options.pipeline", index_.version);
  if (options_.error_px <= 0.0) options_.error_px = pipeline_options.error_px;
  if (!online_stages_.empty()) {
    urban::CellOptions cell_options;
    cell_options.local = urban::parseLocalModel(index_.local_model, index_file + ": local_model");
    if (index_.options.contains("block_margin") && index_.options["block_margin"].is_number())
      cell_options.block_margin = index_.options["block_margin"].get<float>();
    cell_map_ = std::make_unique<urban::CellMap>(graph_, scene, cell_options);
    runner_ = std::make_unique<extract::PipelineRunner>(scene, gpu_scene, *cell_map_, pipeline_options);
  }
  streaming_ = StreamingLog(options_.memory_budget_bytes);
  if (!options_.streaming_csv.empty()) StreamingLog().writeCsv(options_.streaming_csv);  // writable: fail now
  const bool draws_impostors = kind != Representation::Local && kind != Representation::Visible;
  if (online_stages_.empty() && draws_impostors) {
    store::CellReader::Options reader;
    reader.layers = kind != Representation::Smi;
    reader.single = kind == Representation::Smi;
    reader.budget_bytes = options_.read_ahead_bytes;
    reader_ = std::make_unique<store::CellReader>(options_.database, index_, reader);
  }
  invalid_object_.assign(scene.objects.size() + 1, 0);
  layer_id_base_ = uint32_t(scene.objects.size() + 1);
  if (kind == Representation::MmiDynamic) {
    // A few tenths of a second on llvmpipe: cap the triangles per workload so big scenes calibrate as fast.
    gpu::CalibrationOptions calibration;
    calibration.max_triangles = 400000;
    // From where the walkthrough looks: the creation cameras of up to three stored cells (street level, along the
    // street). An overview of the city overdraws differently and mispredicted street frames by a factor of several.
    for (size_t k = 0; k < 3 && k < index_.cells.size(); ++k) {
      Camera view = index_.cells[k * (index_.cells.size() - 1) / 2].camera;
      view.width = options_.width;
      view.height = options_.height;
      calibration.views.push_back(view);
    }
    cost_ = gpu::calibrateCostModel(renderer_, gpu_scene_, calibration);
  }
}

Walkthrough::~Walkthrough() {
  if (options_.streaming_csv.empty()) return;
  try {
    streaming_.writeCsv(options_.streaming_csv);
  } catch (const Error& e) {
    std::fprintf(stderr, "warning: %s\n", e.what());  // checked writable at construction; a destructor cannot throw
  }
}

void Walkthrough::setGeometry(FramePlan& plan, const Camera& camera) {
  if (options_.geometry_items) {
    // GpuScene::appendDrawItems takes an empty list as "all objects".
    if (!ids_.empty()) gpu_scene_.appendDrawItems(ids_, plan.items, camera, &plan.geometry_bounds);
    plan.geometry_items = plan.items.size();
    for (const gpu::DrawItem& item : plan.items) plan.report.geometry_triangles += item.triangleCount();
    return;
  }
  if (ids_ != plan.geometry_objects) {
    plan.geometry_objects.assign(ids_.begin(), ids_.end());
    ++plan.geometry_version;
  }
  for (uint32_t id : ids_) plan.report.geometry_triangles += object_triangles_[id];
}

bool Walkthrough::listedUnchanged(FramePlan& plan, uint64_t base, const std::vector<uint32_t>& extra) {
  if (listed_.valid && listed_.base == base && listed_.extra == extra) {
    plan.report.geometry_triangles = listed_.triangles;
    return true;
  }
  listed_.valid = true;
  listed_.base = base;
  listed_.extra = extra;
  return false;
}

void Walkthrough::setListed(FramePlan& plan) {
  listed_.triangles = 0;
  for (uint32_t id : ids_) listed_.triangles += object_triangles_[id];
  plan.report.geometry_triangles = listed_.triangles;
  if (ids_ != plan.geometry_objects) {
    plan.geometry_objects.assign(ids_.begin(), ids_.end());
    ++plan.geometry_version;
  }
}

const FramePlan& Walkthrough::plan(const Camera& camera, const std::function<void()>& before_gpu_work) {
  if (placed_) return planPlaced(camera);
  FramePlan& plan = plan_;
  plan.items.clear();
  plan.geometry_bounds.clear();
  plan.geometry_items = 0;
  plan.layers.clear();
  plan.report = {};
  FrameReport& report = plan.report;
  ++stats_.frames;
  const uint32_t half_edge = locator_.lookup(graph_, camera.eye, camera.at - camera.eye);
  const store::CellEntry* entry = half_edge == urban::kNone ? nullptr : index_.find(half_edge);
  report.cell = half_edge;
  report.baked = entry != nullptr;
  const ErrorBound bound = ErrorBound::forCamera(options_.error_px, camera);
  report.bound_px = options_.error_px;
  report.bound_rad = bound.angle();
  // A GPU-driven frame (geometry as objects) culls by the frustum itself: its list is the cell's geometry and the
  // objects of its layers drawn as geometry, with no frustum query here (but for MmiDynamic, whose budget predicts
  // from the frustum's triangles), remade only when the cell or those layers change.
  const bool listed = !options_.geometry_items && options_.representation != Representation::MmiDynamic;
  bool listed_unchanged = false;
  ids_.clear();
  if (!listed) bvh_.queryFrustum(Frustum::fromMatrix(camera.viewProjection()), ids_);
  Cell* current = nullptr;
  if (entry) {
    ++stats_.visited[half_edge];
    current = &cell(half_edge, &report.loaded);
    queueCellsAhead(half_edge, camera.eye);
    // Fast motion and stale dynamic impostors first: a layer that loses its dynamic impostor is judged by its
    // baked views' validity below.
    if (options_.representation == Representation::MmiDynamic) dropStaleDynamic(camera, *current);
    for (size_t l = 0; l < current->layers.size(); ++l) {
      const Layer& layer = current->layers[l];
      const uint32_t index = uint32_t(l);
      if (layer.dynamic) {
        plan.layers.push_back(LayerAsDynamic{index});
        continue;
      }
      if (layer.validity.empty()) {
        plan.layers.push_back(LayerUnchecked{index});
        ++report.layers_unchecked;
        continue;
      }
      // The bound where the layer is drawn: a layer near the frame's centre may move by a larger angle per pixel.
      const double theta = bound.angleWithin(frameRadius(camera, layer.bounds));
      LayerAsImpostor best{index, 0, std::numeric_limits<double>::infinity(), theta};
      for (size_t j = 0; j < layer.validity.size(); ++j) {
        const double e = layer.validity[j].errorAt(camera.eye);
        if (e <= theta && e < best.error_rad) {
          best.error_rad = e;
          best.station = uint32_t(j);
        }
      }
      if (best.error_rad <= theta) {
        plan.layers.push_back(best);
        continue;
      }
      plan.layers.push_back(LayerAsGeometry{index, 0});
      ++report.layers_as_geometry;
      for (uint32_t id : layer.objects) invalid_object_[id] = 1;
    }
    // Geometry: the cell's near objects and the objects of layers drawn as geometry, in the frustum (or listed).
    if (listed) {
      listed_extra_.clear();
      for (const LayerDecision& decision : plan.layers)
        if (const auto* g = std::get_if<LayerAsGeometry>(&decision)) listed_extra_.push_back(g->layer);
      listed_unchanged = listedUnchanged(plan, half_edge, listed_extra_);
      if (!listed_unchanged) {
        ids_ = current->geometry;
        for (const LayerDecision& decision : plan.layers)
          if (const auto* g = std::get_if<LayerAsGeometry>(&decision))
            for (uint32_t id : current->layers[g->layer].objects)
              if (!current->geometry_mask[id]) ids_.push_back(id);
        std::sort(ids_.begin(), ids_.end());
        ids_.erase(std::unique(ids_.begin(), ids_.end()), ids_.end());
      }
    } else {
      ids_.erase(std::remove_if(ids_.begin(), ids_.end(),
                                [&](uint32_t id) { return !current->geometry_mask[id] && !invalid_object_[id]; }),
                 ids_.end());
      std::sort(ids_.begin(), ids_.end());
    }
    for (LayerDecision& decision : plan.layers)
      if (auto* g = std::get_if<LayerAsGeometry>(&decision)) {
        for (uint32_t id : current->layers[g->layer].objects) {
          if (invalid_object_[id] && (listed || std::binary_search(ids_.begin(), ids_.end(), id)))
            g->triangles += object_triangles_[id];
          invalid_object_[id] = 0;
        }
      }
  } else {
    ++stats_.fallback_frames;  // not baked: everything in the frustum, as the culled mode
    if (listed) {
      listed_extra_.clear();
      listed_unchanged = listedUnchanged(plan, ~uint64_t(0), listed_extra_);
      if (!listed_unchanged)
        for (uint32_t id = 1; id <= uint32_t(scene_.objects.size()); ++id) ids_.push_back(id);
    }
  }
  report.resident_bytes = resident_bytes_;
  report.read_ahead_bytes = reader_ ? reader_->heldBytes() : 0;
  {
    StreamingFrame f;
    f.cell = half_edge;
    if (report.loaded) f.read = report.read;
    f.load_ms = report.load_ms;
    f.gpu_bytes = report.resident_bytes;
    f.read_ahead_bytes = report.read_ahead_bytes;
    streaming_.add(f);
  }
  report.over_gpu_budget = resident_bytes_ > options_.gpu_budget_bytes;
  stats_.resident_bytes_max = std::max(stats_.resident_bytes_max, resident_bytes_);
  if (report.over_gpu_budget) ++stats_.over_gpu_budget_frames;
  if (!listed) {
    std::sort(ids_.begin(), ids_.end());
    setGeometry(plan, camera);
  } else if (!listed_unchanged) {
    setListed(plan);
  }
  stats_.geometry_triangles += double(report.geometry_triangles);
  if (report.layers_as_geometry > 0) ++stats_.invalid_frames;
  stats_.invalid_layer_draws += report.layers_as_geometry;
  stats_.unchecked_layer_draws += report.layers_unchecked;
  for (const LayerDecision& decision : plan.layers)
    if (const auto* g = std::get_if<LayerAsGeometry>(&decision)) stats_.invalid_triangles += double(g->triangles);
  if (!current || current->layers.empty()) return plan;

  if (options_.representation == Representation::MmiDynamic) {
    updateDynamic(camera, *current, before_gpu_work);
    // A layer re-rendered in this frame is drawn so at once (one drawn as geometry keeps its geometry this frame).
    for (LayerDecision& decision : plan.layers) {
      if (std::holds_alternative<LayerAsGeometry>(decision)) continue;
      const uint32_t l = layerOf(decision);
      if (current->layers[l].dynamic) decision = LayerAsDynamic{l};
    }
  }
  ++stats_.impostor_frames;
  stats_.layers += double(current->layers.size());
  for (const LayerDecision& decision : plan.layers) {
    const auto draw_views = [&](uint32_t l, const LayerAsImpostor* station) {
      const Layer& layer = current->layers[l];
      for (size_t v = 0; v < layer.views.size(); ++v) {
        if (station && layer.view_station[v] != station->station) continue;
        layer.views[v]->appendDrawItems(plan.items, layer_id_base_ + l);
        report.impostor_triangles += layer.views[v]->triangleCount();
      }
    };
    if (const auto* i = std::get_if<LayerAsImpostor>(&decision)) draw_views(i->layer, i);
    if (const auto* u = std::get_if<LayerUnchecked>(&decision)) draw_views(u->layer, nullptr);
    if (const auto* d = std::get_if<LayerAsDynamic>(&decision)) {
      const Layer& layer = current->layers[d->layer];
      layer.dynamic->appendDrawItems(plan.items, layer_id_base_ + d->layer);
      report.impostor_triangles += layer.dynamic->triangleCount();
      stats_.dynamic_layers += 1.0;
    }
  }
  stats_.impostor_triangles += double(report.impostor_triangles);
  return plan;
}

std::map<std::string, double> Walkthrough::statistics() const {
  if (placed_) return placedStatistics();
  std::map<std::string, double> out;
  const Statistics& s = stats_;
  const double n = s.frames ? double(s.frames) : 1.0;
  out["frames"] = double(s.frames);
  out["fallback_frames"] = double(s.fallback_frames);
  out["cells_visited"] = double(s.visited.size());
  out["baked_cells"] = double(index_.cells.size());
  out["cell_loads"] = double(s.loads);
  out["cell_load_ms_max"] = s.load_ms_max;
  out["cell_load_ms_mean"] = s.loads ? s.load_ms_total / double(s.loads) : 0.0;
  out["cache_evictions"] = double(s.evictions);
  out["gpu_budget_bytes"] = double(options_.gpu_budget_bytes);
  out["resident_bytes_max"] = double(s.resident_bytes_max);
  out["frames_over_gpu_budget"] = double(s.over_gpu_budget_frames);
  if (reader_) {
    const store::CellReader::Stats r = reader_->stats();
    out["cells_read_ahead"] = double(r.read_ahead);
    out["cells_entered_ready"] = double(r.taken_ready);
    out["cells_entered_waiting"] = double(r.taken_waited);
    out["cells_entered_cold"] = double(r.taken_cold);
    out["read_ahead_dropped"] = double(r.dropped);
    out["read_ahead_wait_ms_total"] = r.wait_ms_total;
    out["read_ahead_held_bytes_max"] = double(r.held_bytes_max);
    out["read_ahead_budget_bytes"] = double(options_.read_ahead_bytes);
    out["cells_uploaded_ahead"] = double(s.cells_uploaded_ahead);
    out["views_uploaded_ahead"] = double(s.views_uploaded_ahead);
    out["cells_entered_uploaded"] = double(s.entered_uploaded);
    out["cells_entered_partly_uploaded"] = double(s.entered_partly);
    out["uploads_ahead_dropped"] = double(s.uploads_dropped);
    out["upload_ahead_ms_total"] = s.ahead_ms_total;
    out["view_upload_ms_max"] = s.view_upload_ms_max;
  }
  for (const auto& [key, value] : streaming_.summary()) out[key] = value;
  out["online_runs"] = double(s.online_runs);
  out["online_ms_mean"] = s.online_runs ? s.online_ms_total / double(s.online_runs) : 0.0;
  out["mean_geometry_triangles"] = s.geometry_triangles / n;
  const Representation kind = options_.representation;
  if (kind != Representation::Local && kind != Representation::Visible) {
    const double f = s.impostor_frames ? double(s.impostor_frames) : 1.0;
    out["mean_impostor_triangles"] = s.impostor_triangles / f;
    out["mean_layers"] = s.layers / f;
    out["error_bound_px"] = options_.error_px;
    out["invalid_layer_draws"] = double(s.invalid_layer_draws);
    out["unchecked_layer_draws"] = double(s.unchecked_layer_draws);
    out["frames_with_invalid_layers"] = double(s.invalid_frames);
    out["mean_invalid_layer_triangles"] = s.invalid_triangles / n;
  }
  if (kind == Representation::MmiDynamic) {
    out["frame_budget_ms"] = options_.frame_budget_ms;
    out["dynamic_threshold_rad"] = dynamic_threshold_rad_;
    out["updates"] = double(s.updates);
    out["update_ms_mean"] = s.updates ? s.update_ms_total / double(s.updates) : 0.0;
    out["update_ms_max"] = s.update_ms_max;
    out["update_prediction_error_ms_mean"] = s.updates ? s.predicted_update_error_ms / double(s.updates) : 0.0;
    out["updates_skipped_for_budget"] = double(s.skipped_for_budget);
    out["fast_motion_frames"] = double(s.fast_frames);
    out["frames_predicted_over_budget"] = double(s.over_budget_frames);
    out["mean_dynamic_layers"] = s.impostor_frames ? s.dynamic_layers / double(s.impostor_frames) : 0.0;
    // Frames that were not fast motion (the prediction is made only where updates are considered).
    out["predicted_frame_ms_mean"] = s.predicted_frames ? s.predicted_ms / double(s.predicted_frames) : 0.0;
    out["cost_base_ms"] = cost_.base_ms;
    out["cost_ms_per_mtriangle"] = cost_.ms_per_mtriangle;
    out["cost_ms_per_draw"] = cost_.ms_per_draw;
    out["cost_ms_per_mpixel"] = cost_.ms_per_mpixel;
    out["cost_fit_r2"] = cost_.r2;
  }
  return out;
}

}  // namespace farfield::runtime
