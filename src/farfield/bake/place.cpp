// The placement driver (Jeschke et al. 2005, sections 3-5): see place.h.
// Its steps are in the files that place_steps.h lists.
#include "farfield/bake/place.h"

#include <algorithm>
#include <vector>

#include "farfield/bake/place_steps.h"
#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/placement/candidates.h"
#include "farfield/placement/object_hierarchy.h"
#include "farfield/placement/view_space.h"
#include "farfield/scene/bvh.h"

namespace farfield::bake {

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
  if (space.empty() || !isFinite(space.lo) || !isFinite(space.hi))
    throw Error("--view-min/--view-max", "empty view space");
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

  // Per object: its triangles and draw calls (the GPU scene's clusters: what a frame draws for it, uncut).
  const std::vector<gpu::ObjectDrawCost> cost = gpu_scene.objectDrawCosts();

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
  RegionVisibility visibility(scene, gpu_scene, space, options, report);
  if (options.visibility)
    callbacks.visible_set = [&](const Box3& region) { return visibility.visibleSet(region); };
  if (options.visibility_only) {
    if (!options.visibility || options.visibility_cache.empty())
      throw Error("--visibility-only", "needs the visibility on and a --visibility-cache file to write");
    for (const Box3& region : placement::partitionLeaves(space, options.min_region_size)) callbacks.visible_set(region);
    visibility.finish();
    report.wall_s = wall.seconds();
    return report;
  }
  PlaceEstimates est(scene, bvh, profile, cost, hierarchy, visibility.region_visible, options, lens, bound);
  callbacks.estimate = [&](const Box3& region, const Vdi& vdi, const std::vector<uint32_t>* visible) {
    return est.estimate(region, vdi, visible);
  };
  const placement::ViewSpace view_space = placement::approximateProblemViewSpace(vs_options, callbacks);
  report.regions = view_space.counts.regions;
  report.problem_regions = view_space.counts.problem_regions;
  report.cpvs = view_space.cpvs.size();
  report.estimates = view_space.counts.estimates;
  for (const placement::Cpv& c : view_space.cpvs) report.t_enc_max_ms = std::max(report.t_enc_max_ms, c.t_enc);
  report.view_space_s = step.seconds();
  visibility.finish();
  FF_INFO("place: " << report.regions << " regions visited, " << report.cpvs << " CPVs over t_max "
                    << options.t_max_ms << " ms (slowest " << report.t_enc_max_ms << " ms) in "
                    << report.view_space_s << " s");

  // 3-4. Candidates with their layered plans, estimates and the greedy, once at the bound and then, for the CPVs it
  // leaves over t_max, once per fallback bound (coarser impostors: fewer layers and texels, a larger parallax).
  step = Stopwatch();
  const placement::CandidateSet all = placement::generateCandidates(hierarchy, view_space, lens, options.candidates);
  report.candidate_counts = all.counts;
  report.candidates_s = step.seconds();
  est.prepareCpvs(view_space);
  PlacedImpostors placed;
  placed.placeInPasses(scene, gpu_scene, renderer, hierarchy, view_space, all, bound, est, options, out_dir, report);

  // 5. The database: the kept impostors with their candidate numbers as ids.
  placed.writeDatabase(scene, space, view_space, visibility.region_visible, options, out_dir, report);
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake
