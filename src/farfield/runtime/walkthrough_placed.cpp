// Walkthrough over a placement database (Representation::Placed; Jeschke et al. 2005, section 5: "In the runtime
// system, the current CPV (if applicable) is looked up, and all impostors associated with this CPV are rendered instead
// of the original scene parts"). The impostors are read and uploaded when a CPV first needs them and stay resident
// under WalkthroughOptions::gpu_budget_bytes, least recently used evicted first.
#include <algorithm>
#include <cmath>
#include <list>
#include <unordered_map>

#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/layered.h"
#include "farfield/runtime/walkthrough_placed.h"
#include "farfield/store/placement_store.h"

namespace farfield::runtime {

void Walkthrough::openPlacement() {
  placed_ = std::make_unique<Placed>();
  Placed& p = *placed_;
  p.index = store::readPlacementIndex(options_.database);
  const std::string source = options_.database + "/" + store::kPlacementIndexFile;
  if (p.index.scene_objects != scene_.objects.size())
    throw Error(source, "was placed for a scene of " + std::to_string(p.index.scene_objects) +
                            " objects, this one has " + std::to_string(scene_.objects.size()));
  if (options_.error_px <= 0.0) {
    const nlohmann::json& o = p.index.options;
    if (!o.contains("error_px") || !o["error_px"].is_number())
      throw Error(source, "options.error_px is missing: give the walkthrough an error bound");
    options_.error_px = o["error_px"].get<double>();
  }
  p.hidden.assign(scene_.objects.size() + 1, 0);
  for (uint64_t t : object_triangles_) p.all_triangles += double(t);
  p.node_triangles.assign(p.index.nodes.size(), p.all_triangles);
  for (size_t n = 0; n < p.index.nodes.size(); ++n) {
    if (!p.index.nodes[n].has_visible) continue;
    double visible = 0.0;
    for (uint32_t id : p.index.nodes[n].visible) visible += double(object_triangles_[id]);
    p.node_triangles[n] = visible;
  }
  if (options_.read_ahead) {
    const WalkthroughOptions options = options_;
    const store::PlacementIndex& index = p.index;  // lives as long as the reader (Placed's member before it)
    p.reader = std::make_unique<store::BackgroundReader<Placed::Prepared>>(
        [options, &index](uint32_t id) {
          const store::StoredPlacedImpostor* record = index.find(id);
          if (!record) throw Error(options.database, "holds no impostor " + std::to_string(id));
          return Placed::prepare(options, *record);
        },
        [](const Placed::Prepared& prepared) { return prepared.atlases.cpuBytes(); }, options_.read_ahead_bytes);
  }
}

namespace {

// A fallback impostor: placed under a coarser bound than the walkthrough's (bake::PlaceOptions::fallback_bound_factors).
bool underCoarserBound(const store::StoredPlacedImpostor& record, double error_px) {
  return record.bound.pixels > error_px * (1.0 + 1e-9);
}

}  // namespace

Walkthrough::Placed::Prepared Walkthrough::Placed::prepare(const WalkthroughOptions& options,
                                                           const store::StoredPlacedImpostor& record) {
  const impostor::LayeredImpostor imp = store::loadPlacedImpostor(options.database, record);
  Prepared out;
  out.atlases = impostor::packLayeredAtlases(
      imp, options.layer_tiles ? impostor::LayerDraw::Tiles : impostor::LayerDraw::WholeQuads);
  out.error_rad = imp.plan.error_angle;
  return out;
}

std::unordered_map<uint32_t, Walkthrough::Placed::Resident>::iterator Walkthrough::Placed::makeResident(
    uint32_t id, const Prepared& prepared) {
  Resident r;
  Stopwatch upload;
  r.gpu = std::make_unique<impostor::GpuLayeredImpostor>(prepared.atlases);
  const double ms = upload.milliseconds();
  upload_time.add(ms, 1);
  stats.upload_ms_max = std::max(stats.upload_ms_max, ms);
  r.error_rad = prepared.error_rad;
  r.bytes = r.gpu->gpuBytes();
  resident_bytes += r.bytes;
  lru.push_front(id);
  r.lru = lru.begin();
  ++stats.loads;
  return resident.emplace(id, std::move(r)).first;
}

std::unordered_map<uint32_t, Walkthrough::Placed::Resident>::iterator Walkthrough::Placed::load(
    const WalkthroughOptions& options, uint32_t id, const store::StoredPlacedImpostor& record) {
  Stopwatch timer;
  const auto placed = reader ? makeResident(id, *reader->take(id)) : makeResident(id, prepare(options, record));
  const double ms = timer.milliseconds();
  stats.load_ms_total += ms;
  stats.load_ms_max = std::max(stats.load_ms_max, ms);
  return placed;
}

bool Walkthrough::Placed::wanted(const WalkthroughOptions& options, uint32_t id) const {
  return !resident.count(id) && (options.coarser_impostors || !underCoarserBound(*index.find(id), options.error_px));
}

void Walkthrough::Placed::prefetchCpv(const WalkthroughOptions& options, uint32_t cpv) {
  for (uint32_t id : index.cpvs[cpv].impostors)
    if (wanted(options, id)) reader->prefetch(id);
}

double Walkthrough::expectedTriangles(const Vec3& eye) const {
  if (!placed_) return 0.0;
  const std::optional<uint32_t> leaf = store::lookupLeaf(placed_->index, eye);
  return leaf ? placed_->node_triangles[*leaf] : placed_->all_triangles;
}

double Walkthrough::loadPlacedAhead(const Camera& camera, double budget_ms) {
  if (!placed_ || !(budget_ms > 0.0) || options_.placed_read_ahead_frames == 0) return 0.0;
  Placed& p = *placed_;
  if (!p.has_eye) return 0.0;
  Stopwatch timer;
  // Where the eye will be, moving on as over the last frame, and looking as now.
  const Vec3 ahead = camera.eye + p.motion * float(options_.placed_read_ahead_frames);
  const std::optional<uint32_t> cpv = store::lookupCpv(p.index, ahead, camera.forward());
  if (!cpv) return 0.0;
  for (uint32_t id : p.index.cpvs[*cpv].impostors) {
    if (!p.wanted(options_, id)) continue;
    // Nothing is evicted for a load: a read-ahead that would push the residents over the budget waits until the frame
    // needs it.
    if (p.resident_bytes >= options_.gpu_budget_bytes) break;
    const double left = budget_ms - timer.milliseconds();
    // One read and packed already on the reader's thread is uploaded when the expected upload (the 90th percentile
    // of the recent ones: not the slowest, which one preempted upload would set for good) fits in what is left (the
    // first on trust).
    if (p.reader) {
      if (p.upload_time.known() && p.upload_time.predictMs(1) > left) break;
      if (const std::shared_ptr<Placed::Prepared> ready = p.reader->takeIfReady(id)) {
        p.makeResident(id, *ready);
        ++p.stats.read_ahead_loads;
        continue;
      }
    }
    // Else one is read (or waited for) when the slowest load so far fits (the first on trust); otherwise it is left
    // to the reader, which the frame's plan queued it for.
    if (p.stats.loads > 0 && p.stats.load_ms_max > left) continue;
    p.load(options_, id, *p.index.find(id));
    ++p.stats.read_ahead_loads;
  }
  p.stats.resident_bytes_max = std::max(p.stats.resident_bytes_max, p.resident_bytes);
  const double ms = timer.milliseconds();
  p.stats.read_ahead_ms += ms;
  return ms;
}

const FramePlan& Walkthrough::planPlaced(const Camera& camera) {
  Placed& p = *placed_;
  p.motion = p.has_eye ? camera.eye - p.last_eye : Vec3(0.0f);
  p.last_eye = camera.eye;
  p.has_eye = true;
  // The impostors of the CPVs the eye will be in over the next placed_read_ahead_frames frames, moving on as over
  // the last frame and looking as now, are queued for the reader (no work of this frame's but the lookups).
  if (p.reader && options_.placed_read_ahead_frames > 0 && p.motion != Vec3(0.0f)) {
    // At a third, two thirds and all of them (the last where loadAhead looks).
    for (size_t part = 1; part <= 3; ++part) {
      const size_t k = options_.placed_read_ahead_frames * part / 3;
      if (k == 0) continue;
      if (const std::optional<uint32_t> ahead =
              store::lookupCpv(p.index, camera.eye + p.motion * float(k), camera.forward()))
        p.prefetchCpv(options_, *ahead);
    }
  }
  FramePlan& plan = plan_;
  plan.items.clear();
  plan.geometry_bounds.clear();
  plan.geometry_items = 0;
  plan.layers.clear();
  plan.report = {};
  FrameReport& report = plan.report;
  ++p.stats.frames;
  const ErrorBound bound = ErrorBound::forCamera(options_.error_px, camera);
  report.bound_px = options_.error_px;
  report.bound_rad = bound.angle();
  // From-region visibility: where placement sampled what the region sees, only that is drawn (its times assumed it).
  const std::optional<uint32_t> leaf = store::lookupLeaf(p.index, camera.eye);
  const store::StoredViewSpaceNode* visible =
      leaf && p.index.nodes[*leaf].has_visible ? &p.index.nodes[*leaf] : nullptr;
  if (visible) ++p.stats.visibility_frames;
  // A GPU-driven frame (geometry as objects) culls by the frustum itself: its objects are the region's visible set, or
  // every object, with no frustum query here, so that the list changes only when the region or the impostors drawn
  // do. Geometry items are culled here: the objects in the frustum (and in the visible set).
  const bool listed = !options_.geometry_items;
  ids_.clear();
  if (!listed) {
    bvh_.queryFrustum(Frustum::fromMatrix(camera.viewProjection()), ids_);
    std::sort(ids_.begin(), ids_.end());
    if (visible)
      ids_.erase(std::remove_if(ids_.begin(), ids_.end(),
                                [&](uint32_t id) {
                                  return !std::binary_search(visible->visible.begin(), visible->visible.end(), id);
                                }),
                 ids_.end());
  }
  const auto drawable = [&](uint32_t id) {
    if (!listed) return std::binary_search(ids_.begin(), ids_.end(), id);
    return !visible || std::binary_search(visible->visible.begin(), visible->visible.end(), id);
  };

  const std::optional<uint32_t> cpv =
      leaf ? store::cpvInLeaf(p.index, *leaf, camera.eye, camera.forward()) : std::nullopt;
  std::vector<uint32_t> drawn;  // impostor ids drawn this frame
  if (cpv) {
    ++p.stats.cpv_frames;
    const store::StoredCpv& c = p.index.cpvs[*cpv];
    report.cpv = *cpv;
    report.cpv_t_after_ms = c.t_after;
    // An impostor of the CPV not drawn: its objects in view are geometry (reported with their triangles).
    const auto leaveToGeometry = [&](uint32_t id, const store::StoredPlacedImpostor& record) {
      ClusterAsGeometry g{id, 0};
      for (uint32_t o : record.objects)
        if (drawable(o)) g.triangles += object_triangles_[o];
      plan.layers.push_back(g);
      ++report.layers_as_geometry;
    };
    for (uint32_t id : c.impostors) {
      const store::StoredPlacedImpostor& record = *p.index.find(id);
      // A fallback impostor (placed under a coarser bound for a CPV the bound could not bring under t_max, see
      // bake::PlaceOptions::fallback_bound_factors) is held to its own bound, and counted; or, without
      // coarser_impostors, left to geometry (and not loaded).
      const bool coarse = underCoarserBound(record, options_.error_px);
      if (coarse && !options_.coarser_impostors) {
        leaveToGeometry(id, record);
        ++p.stats.coarse_left_to_geometry;
        continue;
      }
      auto it = p.resident.find(id);
      if (it == p.resident.end()) {
        it = p.load(options_, id, record);
        report.loaded = true;
      } else {
        p.lru.splice(p.lru.begin(), p.lru, it->second.lru);  // most recent first, in constant time
      }
      // The impostor keeps this frame's bound where the eye is in its shaft and its plan's error fits the frame's
      // pixel (a camera narrower or larger than the placement's frames has smaller pixels).
      const double radius = frameRadius(camera, record.box);
      const double theta = coarse ? ErrorBound::forCamera(record.bound.pixels, camera).angleWithin(radius)
                                  : bound.angleWithin(radius);
      if (record.shaft.contains(camera.eye) && it->second.error_rad <= theta) {
        if (coarse) ++p.stats.coarse_draws;
        plan.layers.push_back(ClusterAsImpostor{id, uint32_t(record.objects.size()), it->second.error_rad, theta});
        for (uint32_t o : record.objects) p.hidden[o] = 1;
        drawn.push_back(id);
      } else {
        leaveToGeometry(id, record);
        ++p.stats.geometry_fallbacks;
      }
    }
  }
  // Geometry: every object in the frustum (or, listed, in the region) that no impostor of this frame stands for.
  if (listed) {
    // The region's visible set (or every object) less the impostors' objects; remade when either changes.
    if (!listedUnchanged(plan, visible ? uint64_t(*leaf) : ~uint64_t(0), drawn)) {
      ids_.clear();
      if (visible) {
        for (uint32_t id : visible->visible)
          if (!p.hidden[id]) ids_.push_back(id);
      } else {
        for (uint32_t id = 1; id <= uint32_t(scene_.objects.size()); ++id)
          if (!p.hidden[id]) ids_.push_back(id);
      }
      setListed(plan);
    }
  } else {
    ids_.erase(std::remove_if(ids_.begin(), ids_.end(), [&](uint32_t id) { return p.hidden[id] != 0; }), ids_.end());
    // The geometry items come first, with their bounds, so an engine can occlusion-cull them (gpu::OcclusionCuller).
    setGeometry(plan, camera);
  }
  for (uint32_t id : drawn) {
    const Placed::Resident& r = p.resident.at(id);
    r.gpu->appendDrawItems(plan.items);
    report.impostor_triangles += 2u * r.gpu->quads();
    p.stats.impostor_quads += double(r.gpu->quads());
    ++p.stats.impostor_draws;
    for (uint32_t o : p.index.find(id)->objects) p.hidden[o] = 0;
  }
  p.stats.geometry_triangles += double(report.geometry_triangles);

  // Residency: least recently used impostors leave the GPU beyond the budget (never one drawn this frame).
  while (p.resident_bytes > options_.gpu_budget_bytes && !p.lru.empty()) {
    const uint32_t victim = p.lru.back();
    if (std::find(drawn.begin(), drawn.end(), victim) != drawn.end()) break;
    p.resident_bytes -= p.resident.at(victim).bytes;
    p.resident.erase(victim);
    p.lru.pop_back();
    ++p.stats.evictions;
  }
  report.resident_bytes = p.resident_bytes;
  report.over_gpu_budget = p.resident_bytes > options_.gpu_budget_bytes;
  if (report.over_gpu_budget) ++p.stats.over_gpu_budget_frames;
  p.stats.resident_bytes_max = std::max(p.stats.resident_bytes_max, p.resident_bytes);
  return plan;
}

std::map<std::string, double> Walkthrough::placedStatistics() const {
  const Placed& p = *placed_;
  const auto& s = p.stats;
  const double n = s.frames ? double(s.frames) : 1.0;
  std::map<std::string, double> out;
  out["frames"] = double(s.frames);
  out["frames_culled_by_region_visibility"] = double(s.visibility_frames);
  out["cpv_frames"] = double(s.cpv_frames);
  out["cpvs"] = double(p.index.cpvs.size());
  out["impostors_in_database"] = double(p.index.impostors.size());
  out["impostor_draws"] = double(s.impostor_draws);
  out["mean_impostor_quads"] = s.impostor_quads / n;
  out["mean_geometry_triangles"] = s.geometry_triangles / n;
  out["impostors_drawn_as_geometry"] = double(s.geometry_fallbacks);
  out["impostors_drawn_at_a_coarser_bound"] = double(s.coarse_draws);
  out["coarser_impostors_left_to_geometry"] = double(s.coarse_left_to_geometry);
  out["impostor_loads"] = double(s.loads);
  out["impostor_load_ms_mean"] = s.loads ? s.load_ms_total / double(s.loads) : 0.0;
  out["impostor_load_ms_max"] = s.load_ms_max;
  out["impostors_read_ahead"] = double(s.read_ahead_loads);
  out["impostor_read_ahead_ms"] = s.read_ahead_ms;
  out["impostor_upload_ms_max"] = s.upload_ms_max;
  if (p.reader) {
    const store::BackgroundReaderStats r = p.reader->stats();
    out["impostors_queued_for_the_reader"] = double(r.prefetch_requests);
    out["impostors_read_in_the_background"] = double(r.read_ahead);
    out["impostors_taken_ready"] = double(r.taken_ready);
    out["impostors_taken_while_read"] = double(r.taken_waited);
    out["impostors_read_by_the_frame"] = double(r.taken_cold);
    out["impostor_reader_wait_ms"] = r.wait_ms_total;
    out["impostor_reader_bytes_max"] = double(r.held_bytes_max);
  }
  out["cache_evictions"] = double(s.evictions);
  out["gpu_budget_bytes"] = double(options_.gpu_budget_bytes);
  out["resident_bytes_max"] = double(s.resident_bytes_max);
  out["frames_over_gpu_budget"] = double(s.over_gpu_budget_frames);
  out["error_bound_px"] = options_.error_px;
  return out;
}

}  // namespace farfield::runtime
