// The placement driver (Jeschke et al. 2005, sections 3-5): see place.h.
#include "farfield/bake/place.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <array>
#include <map>
#include <unordered_map>
#include <set>

#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/error.h"
#include "farfield/core/object_fill.h"
#include "farfield/core/log.h"
#include "farfield/core/strict_json.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/layered_fill.h"
#include "farfield/placement/greedy.h"
#include "farfield/placement/placement_problem.h"
#include "farfield/placement/view_space.h"
#include "farfield/placement/visibility_cache.h"
#include "farfield/scene/bvh.h"
#include "farfield/store/placement_store.h"
#include "farfield/urban/pvs.h"

namespace fs = std::filesystem;

namespace farfield::bake {

namespace {

// A region's visibility sample points at mid height: an n x n grid over its floor plan, and for n = 2 its centre too.
std::vector<Vec3> visibilityPoints(const Box3& region, int n) {
  const float z = 0.5f * (region.lo.z + region.hi.z);
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      points.emplace_back(region.lo.x + float(i) / float(n - 1) * (region.hi.x - region.lo.x),
                          region.lo.y + float(j) / float(n - 1) * (region.hi.y - region.lo.y), z);
  if (n == 2) points.emplace_back(region.center().x, region.center().y, z);
  return points;
}

void validate(const PlaceOptions& o) {
  if (!(o.t_max_ms > 0.0) || !std::isfinite(o.t_max_ms)) throw Error("--tmax", "must be a positive number of ms");
  if (!(o.error_px > 0.0) || !std::isfinite(o.error_px)) throw Error("--error-px", "must be a positive number");
  if (o.width < 8 || o.height < 8 || o.width > 8192 || o.height > 8192)
    throw Error("--size", "must be 8..8192 pixels per side");
  if (!(o.fov_deg > 1.0f && o.fov_deg < 170.0f)) throw Error("--fov", "must be in (1, 170) degrees");
  if (!(o.min_region_size > 0.0f)) throw Error("--cpv-size", "must be a positive number of metres");
  if (!(o.min_vdi_deg > 0.0f && o.min_vdi_deg <= 90.0f)) throw Error("--vdi-deg", "must be in (0, 90] degrees");
  if (!(o.max_pitch_deg > 0.0f && o.max_pitch_deg <= 90.0f)) throw Error("--max-pitch", "must be in (0, 90] degrees");
  if (!(o.max_object_share > 0.0f)) throw Error("place options", "max_object_share must be positive");
  if (!(o.near_plane > 0.0f && o.far_plane > o.near_plane)) throw Error("--near/--far", "need 0 < near < far");
  if (o.visibility_grid < 2 || o.visibility_grid > 16)
    throw Error("--visibility-grid", "must be 2..16 sample points per side, got " + std::to_string(o.visibility_grid));
  for (double f : o.fallback_bound_factors)
    if (!(f > 1.0) || !std::isfinite(f)) throw Error("--fallback-bounds", "each factor must be a number > 1");
}

// The smallest |pitch| (radians) of the directions of a VDI, from its boundary sampled densely (0 when it crosses
// the horizon), less a degree for what the samples miss.
double minAbsPitch(const Vdi& vdi) {
  constexpr int kSteps = 16;
  double lo = 1e9, hi = -1e9, least = 1e9;
  for (int i = 0; i <= kSteps; ++i)
    for (int j = 0; j <= kSteps; ++j) {
      if (i != 0 && i != kSteps && j != 0 && j != kSteps) continue;
      const float u = vdi.u0 + (vdi.u1 - vdi.u0) * float(i) / kSteps;
      const float v = vdi.v0 + (vdi.v1 - vdi.v0) * float(j) / kSteps;
      const double pitch = std::asin(std::clamp(double(vdi.direction(u, v).z), -1.0, 1.0));
      lo = std::min(lo, pitch);
      hi = std::max(hi, pitch);
      least = std::min(least, std::abs(pitch));
    }
  if (lo <= 0.0 && hi >= 0.0) return 0.0;
  return std::max(0.0, least - degToRad(1.0));
}

}  // namespace

Box3 defaultPlaceViewSpace(const scene::Scene& scene) {
  const Box3 b = scene.bounds();
  if (b.empty()) throw Error("view space", "the scene is empty");
  return Box3::fromPoints(Vec3(b.lo.x, b.lo.y, b.lo.z + 1.2f), Vec3(b.hi.x, b.hi.y, b.lo.z + 1.7f));
}

nlohmann::json PlaceReport::toJson() const {
  return {{"regions", regions},
          {"problem_regions", problem_regions},
          {"cpvs", cpvs},
          {"estimates", estimates},
          {"hierarchy_nodes", hierarchy_nodes},
          {"visibility_regions", visibility_regions},
          {"visibility_points", visibility_points},
          {"visibility_cached", visibility_cached},
          {"mean_visible_objects", mean_visible_objects},
          {"visibility_s", visibility_s},
          {"serves_dropped", serves_dropped},
          {"clustered_objects", clustered_objects},
          {"geometry_objects", geometry_objects},
          {"candidates_considered", candidate_counts.considered},
          {"candidates_intersecting", candidate_counts.intersecting},
          {"candidates_no_cpv", candidate_counts.no_cpv},
          {"candidates_identical", candidate_counts.identical},
          {"candidates_kept", candidate_counts.kept},
          {"candidates_unplannable", candidates_unplannable},
          {"impostors", impostors},
          {"impostors_generated", impostors_generated},
          {"impostors_freed", impostors_freed},
          {"unsolved_cpvs", unsolved_cpvs},
          {"unsolved_at_bound", unsolved_at_bound},
          {"fallback_impostors", fallback_impostors},
          {"fallback_cpv_impostors", fallback_cpv_impostors},
          {"layered_fill_in_model", layered_fill_in_model},
          {"safety_factor", safety_factor},
          {"memory_bytes", memory_bytes},
          {"id_texture_bytes", id_texture_bytes},
          {"layer_texels", layer_texels},
          {"covered_texels", covered_texels},
          {"stored_texels", stored_texels},
          {"estimated_bytes", estimated_bytes},
          {"written_bytes", written_bytes},
          {"t_enc_max_ms", t_enc_max_ms},
          {"t_after_max_ms", t_after_max_ms},
          {"view_space_s", view_space_s},
          {"candidates_s", candidates_s},
          {"estimates_s", estimates_s},
          {"greedy_s", greedy_s},
          {"capture_s", capture_s},
          {"write_s", write_s},
          {"wall_s", wall_s}};
}

PlaceReport placeImpostors(gpu::Context& context, const scene::Scene& scene, const gpu::CostProfile& given_profile,
                           const PlaceOptions& options, const std::string& out_dir) {
  validate(options);
  // The profile's bound, min(prediction x factor, prediction + margin), as one factor at t_max: linear, so the objects'
  // and impostors' times below add up, with the bound's own verdict on every CPV.
  const gpu::CostProfile profile = given_profile.atBudget(options.t_max_ms);
  if (scene.objects.empty()) throw Error("place", "the scene has no objects");
  Stopwatch wall;
  PlaceReport report;
  report.dir = out_dir;
  context.makeCurrent();
  const Box3 space = options.view_space.empty() ? defaultPlaceViewSpace(scene) : options.view_space;
  if (space.empty() || !isFinite(space.lo) || !isFinite(space.hi)) throw Error("--view-min/--view-max", "empty view space");
  if (!profile.layered.calibrated && !options.visibility_only)
    FF_WARN("place: the cost profile has no layered impostor terms (a version-1 profile): the layers' fill is not in "
            "the estimates, so the frame-time guarantee does not cover it; run farfield calibrate again");
  report.layered_fill_in_model = profile.layered.calibrated;
  report.safety_factor = profile.safety_factor;
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  const ErrorBound bound{options.error_px, options.width, options.height, degToRad(double(options.fov_deg))};
  bound.validate("--error-px");
  Lens lens;
  lens.fov_y = float(degToRad(double(options.fov_deg)));
  lens.aspect = float(options.width) / float(options.height);
  lens.near_plane = options.near_plane;
  lens.far_plane = options.far_plane;
  const double pixels = double(options.width) * double(options.height);
  // The objects' fill (core/object_fill.h), from the nearest point of a region: at least what any view in it covers.
  const FillLens fill_lens = FillLens::of(options.width, options.height, degToRad(double(options.fov_deg)));

  // Per object: its triangles and draw calls (the GPU scene's clusters: what a frame draws for it, uncut).
  const std::vector<gpu::ObjectDrawCost> cost = gpu_scene.objectDrawCosts();
  const auto geometryMs = [&](uint64_t triangles, uint64_t draws, double fill) {
    return (profile.model.ms_per_mtriangle * double(triangles) * 1e-6 + profile.model.ms_per_draw * double(draws) +
            profile.model.ms_per_mfill * fill * 1e-6) *
           profile.safety_factor;
  };

  // 1. The object hierarchy, without the objects too big to be a cluster's part.
  const float widest = std::max(space.extent().x, space.extent().y) * options.max_object_share;
  std::vector<placement::HierarchyItem> items;
  for (const scene::Object& o : scene.objects) {
    const Vec3 e = o.world_bounds.extent();
    if (o.world_bounds.empty() || std::max(e.x, e.y) > widest) {
      ++report.geometry_objects;
      continue;
    }
    items.push_back({o.id, o.world_bounds, cost[o.id].triangles});
  }
  report.clustered_objects = items.size();
  const placement::ObjectHierarchy hierarchy = placement::ObjectHierarchy::build(items, options.hierarchy);
  report.hierarchy_nodes = hierarchy.nodes().size();

  // 2. The problem view space.
  Stopwatch step;
  placement::ViewSpaceOptions vs_options;
  vs_options.box = space;
  vs_options.min_region_size = options.min_region_size;
  vs_options.min_vdi_angle = float(degToRad(double(options.min_vdi_deg)));
  vs_options.t_max = options.t_max_ms;
  placement::ViewSpaceCallbacks callbacks;
  std::vector<uint32_t> ids;
  // From-region visibility of the minimum-size regions, by their lower corner; sample points shared by neighbouring
  // regions are rendered once.
  std::unique_ptr<urban::PvsSampler> sampler;
  std::map<std::array<float, 3>, std::vector<uint32_t>> region_visible;
  std::map<std::array<float, 3>, std::vector<uint32_t>> point_visible;
  const auto isLeafSized = [&](const Box3& region) {
    return placement::isPartitionLeaf(region, options.min_region_size);
  };
  // The cache's identity: what the visible sets depend on.
  const nlohmann::json cache_key =
      placement::visibilityCacheKey(scene.objects.size(), space, options.min_region_size, options.visibility_face,
                                    options.far_plane, options.visibility_grid);
  // Once the visible sets are known: their mean size, and the cache written when some were sampled anew.
  const auto finishVisibility = [&] {
    if (report.visibility_regions) report.mean_visible_objects /= double(report.visibility_regions);
    if (!options.visibility || options.visibility_cache.empty() || report.visibility_cached >= report.visibility_regions)
      return;
    placement::VisibilityCache cache;
    cache.key = cache_key;
    cache.regions = region_visible;
    store::writeFileAtomic(options.visibility_cache, cache.toJson().dump() + "\n");
  };
  std::map<std::array<float, 3>, std::vector<uint32_t>> cached;
  if (options.visibility && !options.visibility_cache.empty() && fs::exists(options.visibility_cache)) {
    try {
      placement::VisibilityCache read = placement::readVisibilityCache(options.visibility_cache);
      if (read.key == cache_key)
        cached = std::move(read.regions);
      else
        FF_WARN(options.visibility_cache << ": made for another scene or view space; sampling again");
    } catch (const Error& e) {
      FF_WARN(e.what() << "; sampling again");
    }
  }
  if (options.visibility) {
    urban::PvsOptions pvs;
    pvs.face_size = options.visibility_face;
    pvs.far_plane = options.far_plane;
    sampler = std::make_unique<urban::PvsSampler>(gpu_scene, pvs);
    callbacks.visible_set = [&](const Box3& region) -> std::vector<uint32_t> {
      if (!isLeafSized(region)) return {};  // big regions: every object counts (conservative)
      if (const auto hit = cached.find({region.lo.x, region.lo.y, region.lo.z}); hit != cached.end()) {
        ++report.visibility_cached;
        ++report.visibility_regions;
        report.mean_visible_objects += double(hit->second.size());
        return region_visible[hit->first] = hit->second;
      }
      Stopwatch timer;
      std::vector<uint8_t> seen;
      for (const Vec3& p : visibilityPoints(region, options.visibility_grid)) {
        auto [it, fresh] = point_visible.try_emplace({p.x, p.y, p.z});
        if (fresh) {
          std::vector<uint8_t> here;
          sampler->sampleViewpoint(p, here);
          for (size_t id = 1; id < here.size(); ++id)
            if (here[id]) it->second.push_back(uint32_t(id));
          ++report.visibility_points;
        }
        for (uint32_t id : it->second) {
          if (seen.size() <= id) seen.resize(id + 1, 0);
          seen[id] = 1;
        }
      }
      std::vector<uint32_t> out;
      for (size_t id = 1; id < seen.size(); ++id)
        if (seen[id]) out.push_back(uint32_t(id));
      ++report.visibility_regions;
      report.mean_visible_objects += double(out.size());
      report.visibility_s += timer.seconds();
      region_visible[{region.lo.x, region.lo.y, region.lo.z}] = out;
      return out;
    };
  }
  if (options.visibility_only) {
    if (!options.visibility || options.visibility_cache.empty())
      throw Error("--visibility-only", "needs the visibility on and a --visibility-cache file to write");
    for (const Box3& region : placement::partitionLeaves(space, options.min_region_size)) callbacks.visible_set(region);
    finishVisibility();
    report.wall_s = wall.seconds();
    return report;
  }
  const double max_pitch = degToRad(double(options.max_pitch_deg));
  // What the objects an enclosing frustum meets (of the visible set, when there is one) cost as geometry, and their
  // fill from the region's nearest point: the view space's estimates and the CPVs' fill sums count the same objects.
  struct Workload {
    uint64_t triangles = 0, draws = 0;
    double fill = 0.0;
  };
  const auto addObject = [&](Workload& w, uint32_t id, const Box3& region) {
    w.triangles += cost[id].triangles;
    w.draws += cost[id].draws;
    if (profile.model.ms_per_mfill > 0.0) w.fill += fill_lens.objectPixels(scene.objects[id - 1].world_bounds, region);
  };
  const auto workloadIn = [&](const Frustum& frustum, const Box3& region, const std::vector<uint32_t>* visible) {
    Workload w;
    ids.clear();
    bvh.queryFrustum(frustum, ids);
    const bool culled = visible && !visible->empty();
    for (uint32_t id : ids)
      if (!culled || std::binary_search(visible->begin(), visible->end(), id)) addObject(w, id, region);
    return w;
  };
  callbacks.estimate = [&](const Box3& region, const Vdi& vdi, const std::vector<uint32_t>* visible) {
    if (options.max_pitch_deg < 90.0f && minAbsPitch(vdi) > max_pitch) return 0.0;  // no view of the walkthrough
    const Workload w = workloadIn(enclosingFrustum(region, vdi, lens), region, visible);
    return profile.boundMs(double(w.triangles), double(w.draws), pixels, w.fill);
  };
  const placement::ViewSpace view_space = placement::approximateProblemViewSpace(vs_options, callbacks);
  report.regions = view_space.counts.regions;
  report.problem_regions = view_space.counts.problem_regions;
  report.cpvs = view_space.cpvs.size();
  report.estimates = view_space.counts.estimates;
  for (const placement::Cpv& c : view_space.cpvs) report.t_enc_max_ms = std::max(report.t_enc_max_ms, c.t_enc);
  report.view_space_s = step.seconds();
  finishVisibility();
  const auto visibleFrom = [&](const Box3& region) -> const std::vector<uint32_t>* {
    const auto it = region_visible.find({region.lo.x, region.lo.y, region.lo.z});
    return it == region_visible.end() || it->second.empty() ? nullptr : &it->second;
  };
  FF_INFO("place: " << report.regions << " regions visited, " << report.cpvs << " CPVs over t_max "
                    << options.t_max_ms << " ms (slowest " << report.t_enc_max_ms << " ms) in "
                    << report.view_space_s << " s");

  // 3-4. Candidates with their layered plans, estimates and the greedy, once at the bound and then, for the CPVs it
  // leaves over t_max, once per fallback bound (coarser impostors: fewer layers and texels, a larger parallax).
  step = Stopwatch();
  const placement::CandidateSet all = placement::generateCandidates(hierarchy, view_space, lens, options.candidates);
  report.candidate_counts = all.counts;
  report.candidates_s = step.seconds();
  const std::vector<Frustum> frusta = placement::cpvFrusta(view_space, lens);
  const std::vector<int> parents = hierarchy.parents();
  const auto related = [&](int a, int b) {
    for (int at = a; at >= 0; at = parents[size_t(at)])
      if (at == b) return true;
    for (int at = b; at >= 0; at = parents[size_t(at)])
      if (at == a) return true;
    return false;
  };
  // What a cluster's fill saves when an impostor replaces it: what the CPV's estimate stops counting without it
  // (CostModel::fillCredit against the CPV's whole fill, summed over the objects its enclosing frustum meets as the
  // estimate sums them): all of it where the term is linear or the CPV is under the cap, only what takes the CPV back
  // under the cap above it. Credits of several clusters in one CPV, each against the CPV's fill without any impostor,
  // add up to at most their joint credit, so t_after stays an upper bound.
  const bool fill_saves = profile.model.ms_per_mfill > 0.0;
  std::vector<double> cpv_fill(view_space.cpvs.size(), 0.0);
  if (fill_saves)
    for (size_t c = 0; c < view_space.cpvs.size(); ++c) {
      const Box3& region = view_space.cpvs[c].region;
      cpv_fill[c] = workloadIn(frusta[c], region, visibleFrom(region)).fill;
    }
  std::unordered_map<uint64_t, double> t_object_memo;
  const auto tObject = [&](int node, uint32_t cpv) {
    const uint64_t key = (uint64_t(uint32_t(node)) << 32) | cpv;
    const auto it = t_object_memo.find(key);
    if (it != t_object_memo.end()) return it->second;
    const Box3& region = view_space.cpvs[cpv].region;
    const std::vector<uint32_t>* visible = visibleFrom(region);
    Workload w;
    for (uint32_t id : hierarchy.objects(node))
      if ((!visible || std::binary_search(visible->begin(), visible->end(), id)) &&
          frusta[cpv].intersects(scene.objects[id - 1].world_bounds))
        addObject(w, id, region);
    return t_object_memo[key] = geometryMs(w.triangles, w.draws, profile.model.fillCredit(cpv_fill[cpv], w.fill));
  };
  // An impostor's time: its quads and draw calls as geometry, plus what its alpha-tested layers fill (the profile's
  // layered draw term over the plan's quads seen from the nearest viewpoint on the axis; 0 for a profile without it).
  // The fill is estimated from the CPV's region's nearest point to the shaft's apex (impostor::layeredFillPixels).
  const auto tImpostor = [&](const impostor::LayeredPlan& plan, uint32_t cpv) {
    const Box3& region = view_space.cpvs[cpv].region;
    const Vec3 nearest = glm::clamp(plan.shaft.apex, region.lo, region.hi);
    const double fill = impostor::layeredFillPixels(plan, double(glm::length(nearest - plan.shaft.apex)), bound);
    return geometryMs(2 * uint64_t(plan.quads()), plan.draws(), 0.0) +
           profile.layered.drawBoundMs(double(plan.quads()), fill);
  };

  fs::create_directories(out_dir);
  const uint64_t generation = store::nextPlacementGeneration(out_dir);
  std::map<uint32_t, store::StoredPlacedImpostor> written;  // impostor id -> record
  std::map<uint32_t, double> id_bytes;                      // impostor id -> bytes of its id textures
  std::map<uint32_t, impostor::LayeredPlan> chosen_plans;   // impostor id -> its plan (uncropped)
  std::vector<double> cpv_t;                                // per CPV: its time with the impostors shown so far
  for (const placement::Cpv& c : view_space.cpvs) cpv_t.push_back(c.t_enc);
  std::vector<std::vector<std::pair<uint32_t, int>>> cpv_shown(view_space.cpvs.size());  // (impostor id, node)
  std::map<uint32_t, size_t> uses;  // impostor id -> CPVs showing it
  uint32_t next_id = 0;
  double capture_s = 0.0, greedy_total_s = 0.0;
  std::vector<double> factors{1.0};
  for (double f : options.fallback_bound_factors) factors.push_back(f);
  for (size_t pass = 0; pass < factors.size(); ++pass) {
    std::vector<uint8_t> open(view_space.cpvs.size(), 0);
    size_t open_count = 0;
    for (size_t c = 0; c < cpv_t.size(); ++c)
      if (cpv_t[c] > options.t_max_ms) open[c] = 1, ++open_count;
    if (pass == 1) report.unsolved_at_bound = open_count;
    if (open_count == 0) break;
    ErrorBound pass_bound = bound;
    pass_bound.pixels *= factors[pass];
    Stopwatch plan_clock;
    placement::CandidateSet kept;
    kept.counts = all.counts;
    std::vector<impostor::LayeredPlan> plans;
    std::vector<Box3> parts;  // the candidate's objects: each layer's cover planned from them
    for (const placement::Candidate& original : all.candidates) {
      const std::optional<Shaft> shaft = placement::planningShaft(original, hierarchy);
      if (!shaft) {
        if (pass == 0) ++report.candidates_unplannable;  // a box cell no shaft from the cluster's centre holds
        continue;
      }
      placement::Candidate c = original;
      // Later passes: only the CPVs still over t_max, and not where an impostor of a related node is shown already.
      if (pass > 0)
        c.cpvs.erase(std::remove_if(c.cpvs.begin(), c.cpvs.end(),
                                    [&](uint32_t cpv) {
                                      if (!open[cpv]) return true;
                                      for (const auto& [id, node] : cpv_shown[cpv])
                                        if (related(node, c.node)) return true;
                                      return false;
                                    }),
                     c.cpvs.end());
      if (c.cpvs.empty()) continue;
      try {
        parts.clear();
        if (options.layer_tiles)
          for (uint32_t id : hierarchy.objects(c.node)) parts.push_back(scene.objects[id - 1].world_bounds);
        impostor::LayeredPlan plan = impostor::planLayered(hierarchy.nodes()[size_t(c.node)].bounds, *shaft,
                                                           pass_bound, options.layered, parts);
        if (!plan.keepsBound()) {
          if (pass == 0) ++report.candidates_unplannable;
          continue;
        }
        // A CPV where the node's visible geometry costs no more than its impostor gains nothing from it.
        const size_t before = c.cpvs.size();
        c.cpvs.erase(std::remove_if(c.cpvs.begin(), c.cpvs.end(),
                                    [&](uint32_t cpv) { return tObject(c.node, cpv) <= tImpostor(plan, cpv); }),
                     c.cpvs.end());
        report.serves_dropped += before - c.cpvs.size();
        if (c.cpvs.empty()) continue;
        plans.push_back(std::move(plan));
        kept.candidates.push_back(std::move(c));
      } catch (const Error&) {
        if (pass == 0) ++report.candidates_unplannable;  // the shaft does not clear the cluster
      }
    }
    if (pass == 0) report.candidates_s += plan_clock.seconds();
    FF_INFO("place: pass at " << pass_bound.pixels << " px: " << kept.candidates.size()
                              << " candidates with a layered plan serve " << open_count << " CPVs over t_max");
    const placement::Candidate* first = kept.candidates.empty() ? nullptr : &kept.candidates.front();
    placement::PlacementEstimates estimates;
    estimates.t_object = tObject;
    estimates.t_impostor = [&](const placement::Candidate& c, uint32_t cpv) {
      return tImpostor(plans[size_t(&c - first)], cpv);
    };
    estimates.memory = [&](const placement::Candidate& c) { return double(plans[size_t(&c - first)].bytes()); };
    Stopwatch estimate_clock;
    placement::GreedyProblem problem = placement::makeGreedyProblem(view_space, hierarchy, kept, estimates);
    problem.cpv_times = cpv_t;
    report.estimates_s += estimate_clock.seconds();

    Stopwatch greedy_clock;
    std::map<size_t, uint32_t> id_of;  // candidate of this pass -> impostor id
    const double capture_before = capture_s;
    const placement::GreedyResult result = placement::placeGreedy(problem, [&](size_t k) {
      Stopwatch capture;
      const placement::Candidate& c = kept.candidates[k];
      std::vector<uint32_t> objects(hierarchy.objects(c.node).begin(), hierarchy.objects(c.node).end());
      std::sort(objects.begin(), objects.end());
      // Each layer keeps only the rectangle its slab's objects cover (cropLayered: the same image, fewer texels).
      const impostor::LayeredImpostor imp =
          impostor::cropLayered(impostor::captureLayered(renderer, gpu_scene, objects, plans[k]));
      const uint32_t id = next_id++;
      id_of[k] = id;
      written[id] = store::writePlacedImpostor(out_dir, generation, id, uint32_t(c.node), objects, imp,
                                               hierarchy.nodes()[size_t(c.node)].bounds, plans[k].shaft,
                                               pass_bound, options.layered);
      id_bytes[id] = imp.plan.id_textures ? 0.5 * double(imp.plan.texture_bytes) : 0.0;
      chosen_plans[id] = plans[k];
      capture_s += capture.seconds();
      ++report.impostors_generated;
      if (options.progress && report.impostors_generated % 25 == 0)
        FF_INFO("place: " << report.impostors_generated << " impostors generated");
      // Measured after generation (section 5.3): the memory of the cropped layers, and in each served CPV the time of
      // the quads as cropped (smaller than the plan's: fill falls with them), so a CPV's t_after is what the runtime
      // will draw, still bounded from the region's nearest point.
      placement::GeneratedImpostor made{double(imp.plan.bytes()), {}};
      made.t_impostor.reserve(c.cpvs.size());
      impostor::LayeredPlan charged = imp.plan;  // the cropped quads, over their tiles or (without) whole
      if (!options.layer_tiles) impostor::coverWholeQuads(charged);
      for (uint32_t cpv : c.cpvs) made.t_impostor.push_back(tImpostor(charged, cpv));
      return made;
    });
    greedy_total_s += greedy_clock.seconds() - (capture_s - capture_before);
    for (size_t c = 0; c < cpv_t.size(); ++c) {
      cpv_t[c] = result.cpv_times[c];
      for (uint32_t i : result.cpv_impostors[c]) {
        const uint32_t id = id_of.at(result.impostors[i].candidate);
        cpv_shown[c].push_back({id, kept.candidates[result.impostors[i].candidate].node});
        ++uses[id];
        if (pass > 0) ++report.fallback_cpv_impostors;
      }
    }
    if (pass > 0) report.fallback_impostors += result.impostors.size();
  }
  if (factors.size() == 1) report.unsolved_at_bound = 0;
  report.greedy_s = greedy_total_s;
  report.capture_s = capture_s;

  // 5. The database: the kept impostors with their candidate numbers as ids.
  step = Stopwatch();
  store::PlacementIndex index;
  index.generation = generation;
  index.scene = options.scene_label;
  index.scene_objects = scene.objects.size();
  index.options = placeOptionsToJson(options);
  index.view_space = space;
  for (const placement::ViewSpaceNode& n : view_space.nodes) {
    store::StoredViewSpaceNode s;
    s.box = n.box;
    s.children[0] = n.children[0];
    s.children[1] = n.children[1];
    s.cpv_first = n.cpv_first;
    s.cpv_count = n.cpv_count;
    if (n.children[0] < 0) {
      const auto it = region_visible.find({n.box.lo.x, n.box.lo.y, n.box.lo.z});
      if (it != region_visible.end() && !it->second.empty()) {
        s.has_visible = true;
        s.visible = it->second;
      }
    }
    index.nodes.push_back(s);
  }
  for (const auto& [id, n] : uses) {  // ascending ids, as the index lists them
    if (n == 0) continue;
    index.impostors.push_back(written.at(id));
    const impostor::LayeredPlan& plan = chosen_plans.at(id);
    report.layer_texels += plan.texels;
    for (const store::StoredImpostorLayer& layer : written.at(id).layers) {
      report.stored_texels += uint64_t(layer.crop.width) * uint64_t(layer.crop.height);
      report.covered_texels += layer.data_texels;
    }
    report.id_texture_bytes += id_bytes.at(id);
    report.estimated_bytes += double(plan.bytes());
    report.memory_bytes += double(written.at(id).bytes);
    ++report.impostors;
  }
  for (size_t c = 0; c < view_space.cpvs.size(); ++c) {
    store::StoredCpv s;
    s.region = view_space.cpvs[c].region;
    s.vdi = view_space.cpvs[c].vdi;
    s.t_enc = view_space.cpvs[c].t_enc;
    s.t_after = cpv_t[c];
    for (const auto& [id, node] : cpv_shown[c]) s.impostors.push_back(id);
    std::sort(s.impostors.begin(), s.impostors.end());
    if (s.t_after > options.t_max_ms) ++report.unsolved_cpvs;
    report.t_after_max_ms = std::max(report.t_after_max_ms, s.t_after);
    index.cpvs.push_back(std::move(s));
  }
  report.impostors_freed = report.impostors_generated - report.impostors;
  for (const store::StoredPlacedImpostor& imp : index.impostors)  // the data files (the index comes on top)
    for (const store::StoredImpostorLayer& l : imp.layers) report.written_bytes += l.texture_check.bytes + l.ids_check.bytes;
  index.summary = report.toJson();
  store::writePlacementIndex(out_dir, index);
  // writePlacementIndex removed the files of the impostors the greedy freed (no longer named by the index).
  report.written_bytes = store::placementBytes(out_dir, index);
  report.write_s = step.seconds();
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake

namespace farfield::bake {

nlohmann::json placeOptionsToJson(const PlaceOptions& o) {
  nlohmann::json space = nullptr;
  if (!o.view_space.empty())
    space = {{"lo", {o.view_space.lo.x, o.view_space.lo.y, o.view_space.lo.z}},
             {"hi", {o.view_space.hi.x, o.view_space.hi.y, o.view_space.hi.z}}};
  const placement::CandidateOptions& c = o.candidates;
  const impostor::LayeredOptions& l = o.layered;
  return {{"view_space", space},
          {"t_max_ms", o.t_max_ms},
          {"error_px", o.error_px},
          {"width", o.width},
          {"height", o.height},
          {"fov_deg", o.fov_deg},
          {"near_plane", o.near_plane},
          {"far_plane", o.far_plane},
          {"min_region_size", o.min_region_size},
          {"min_vdi_deg", o.min_vdi_deg},
          {"max_pitch_deg", o.max_pitch_deg},
          {"max_object_share", o.max_object_share},
          {"visibility", o.visibility},
          {"visibility_face", o.visibility_face},
          {"visibility_grid", o.visibility_grid},
          {"seed", o.seed},
          {"fallback_bound_factors", o.fallback_bound_factors},
          {"layer_tiles", o.layer_tiles},
          {"hierarchy", {{"max_levels", o.hierarchy.max_levels},
                         {"min_objects_to_split", o.hierarchy.min_objects_to_split}}},
          {"candidates", {{"shafts", c.shafts},
                          {"apex_angles", c.apex_angles},
                          {"direction_step", c.direction_step},
                          {"elevations", c.elevations},
                          {"first_distance_factor", c.first_distance_factor},
                          {"distance_steps", c.distance_steps},
                          {"drop_identical", c.drop_identical},
                          {"rectangular_cells", c.rectangular_cells},
                          {"box_leaves_only", c.box_leaves_only}}},
          {"layered", {{"texel_pixels", l.texel_pixels},
                       {"max_texture_size", l.max_texture_size},
                       {"max_layers", l.max_layers},
                       {"layer_count", l.layer_count},
                       {"bound_cracks", l.bound_cracks},
                       {"id_textures", l.id_textures},
                       {"solid_slices", l.solid_slices},
                       {"dilate_texels", l.dilate_texels}}}};
}

PlaceOptions placeOptionsFromJson(const nlohmann::json& j, const std::string& source) {
  StrictJson r(j, source, "placement option");
  PlaceOptions o;
  const nlohmann::json& space = r.at("view_space");
  if (!space.is_null()) {
    StrictJson s(space, source + ".view_space", "placement option");
    std::vector<float> lo, hi;
    s.numbers("lo", lo);
    s.numbers("hi", hi);
    s.rejectUnknown();
    if (lo.size() != 3 || hi.size() != 3) throw Error(source + ".view_space", "lo and hi need three numbers each");
    o.view_space = Box3::fromPoints(Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2]));
  }
  r.number("t_max_ms", o.t_max_ms);
  r.number("error_px", o.error_px);
  r.number("width", o.width);
  r.number("height", o.height);
  r.number("fov_deg", o.fov_deg);
  r.number("near_plane", o.near_plane);
  r.number("far_plane", o.far_plane);
  r.number("min_region_size", o.min_region_size);
  r.number("min_vdi_deg", o.min_vdi_deg);
  r.number("max_pitch_deg", o.max_pitch_deg);
  r.number("max_object_share", o.max_object_share);
  o.visibility = r.boolean("visibility");
  r.number("visibility_face", o.visibility_face);
  // Databases placed before the grid was an option sampled the corners and the centre.
  o.visibility_grid = 2;
  if (r.has("visibility_grid")) r.number("visibility_grid", o.visibility_grid);
  r.number("seed", o.seed);
  r.numbers("fallback_bound_factors", o.fallback_bound_factors);
  // Databases placed before layers were drawn as their tiles charged whole quads.
  o.layer_tiles = r.has("layer_tiles") ? r.boolean("layer_tiles") : false;
  StrictJson h = r.object("hierarchy");
  h.number("max_levels", o.hierarchy.max_levels);
  h.number("min_objects_to_split", o.hierarchy.min_objects_to_split);
  h.rejectUnknown();
  StrictJson c = r.object("candidates");
  o.candidates.shafts = c.boolean("shafts");
  c.numbers("apex_angles", o.candidates.apex_angles);
  c.number("direction_step", o.candidates.direction_step);
  c.numbers("elevations", o.candidates.elevations);
  c.number("first_distance_factor", o.candidates.first_distance_factor);
  c.number("distance_steps", o.candidates.distance_steps);
  o.candidates.drop_identical = c.boolean("drop_identical");
  o.candidates.rectangular_cells = c.boolean("rectangular_cells");
  // Databases placed before per-cell boxes existed say nothing of them: boxes from every region then.
  o.candidates.box_leaves_only = c.has("box_leaves_only") && c.boolean("box_leaves_only");
  c.rejectUnknown();
  StrictJson l = r.object("layered");
  l.number("texel_pixels", o.layered.texel_pixels);
  l.number("max_texture_size", o.layered.max_texture_size);
  l.number("max_layers", o.layered.max_layers);
  l.number("layer_count", o.layered.layer_count);
  o.layered.bound_cracks = l.boolean("bound_cracks");
  o.layered.id_textures = l.boolean("id_textures");
  o.layered.solid_slices = l.boolean("solid_slices");
  l.number("dilate_texels", o.layered.dilate_texels);
  l.rejectUnknown();
  r.rejectUnknown();
  validate(o);
  return o;
}

}  // namespace farfield::bake
