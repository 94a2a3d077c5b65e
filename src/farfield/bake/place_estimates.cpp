// The estimates supplied to the placement algorithm: a view's time over what its enclosing frustum meets (the
// problem view space), and in each CPV a cluster's time as geometry and as its layered impostor (the greedy).
#include <algorithm>
#include <cmath>
#include <vector>

#include "farfield/bake/place_steps.h"
#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/object_fill.h"
#include "farfield/impostor/layered_fill.h"
#include "farfield/placement/candidates.h"

namespace farfield::bake {

namespace {

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

PlaceEstimates::PlaceEstimates(const scene::Scene& scene, const scene::Bvh& bvh, const gpu::CostProfile& profile,
                               const std::vector<gpu::ObjectDrawCost>& cost,
                               const placement::ObjectHierarchy& hierarchy, const VisibleSets& region_visible,
                               const PlaceOptions& options, const Lens& lens, const ErrorBound& bound)
    : scene(scene),
      bvh(bvh),
      profile(profile),
      cost(cost),
      hierarchy(hierarchy),
      region_visible(region_visible),
      options(options),
      lens(lens),
      bound(bound),
      pixels(double(options.width) * double(options.height)),
      fill_lens(FillLens::of(options.width, options.height, degToRad(double(options.fov_deg)))),
      max_pitch(degToRad(double(options.max_pitch_deg))) {}

double PlaceEstimates::geometryMs(uint64_t triangles, uint64_t draws, double fill) const {
  return (profile.model.ms_per_mtriangle * double(triangles) * 1e-6 + profile.model.ms_per_draw * double(draws) +
          profile.model.ms_per_mfill * fill * 1e-6) *
         profile.safety_factor;
}

void PlaceEstimates::addObject(Workload& w, uint32_t id, const Box3& region) const {
  w.triangles += cost[id].triangles;
  w.draws += cost[id].draws;
  if (profile.model.ms_per_mfill > 0.0) w.fill += fill_lens.objectPixels(scene.objects[id - 1].world_bounds, region);
}

PlaceEstimates::Workload PlaceEstimates::workloadIn(const Frustum& frustum, const Box3& region,
                                                    const std::vector<uint32_t>* visible) {
  Workload w;
  ids.clear();
  bvh.queryFrustum(frustum, ids);
  const bool culled = visible && !visible->empty();
  for (uint32_t id : ids)
    if (!culled || std::binary_search(visible->begin(), visible->end(), id)) addObject(w, id, region);
  return w;
}

const std::vector<uint32_t>* PlaceEstimates::visibleFrom(const Box3& region) const {
  const auto it = region_visible.find({region.lo.x, region.lo.y, region.lo.z});
  return it == region_visible.end() || it->second.empty() ? nullptr : &it->second;
}

double PlaceEstimates::estimate(const Box3& region, const Vdi& vdi, const std::vector<uint32_t>* visible) {
  if (options.max_pitch_deg < 90.0f && minAbsPitch(vdi) > max_pitch) return 0.0;  // no view of the walkthrough
  const Workload w = workloadIn(enclosingFrustum(region, vdi, lens), region, visible);
  return profile.boundMs(double(w.triangles), double(w.draws), pixels, w.fill);
}

void PlaceEstimates::prepareCpvs(const placement::ViewSpace& problem) {
  view_space = &problem;
  frusta = placement::cpvFrusta(problem, lens);
  // What a cluster's fill saves when an impostor replaces it: what the CPV's estimate stops counting without it
  // (CostModel::fillCredit against the CPV's whole fill, summed over the objects its enclosing frustum meets as the
  // estimate sums them): all of it where the term is linear or the CPV is under the cap, only what takes the CPV back
  // under the cap above it. Credits of several clusters in one CPV, each against the CPV's fill without any impostor,
  // add up to at most their joint credit, so t_after stays an upper bound.
  const bool fill_saves = profile.model.ms_per_mfill > 0.0;
  cpv_fill.assign(problem.cpvs.size(), 0.0);
  if (fill_saves)
    for (size_t c = 0; c < problem.cpvs.size(); ++c) {
      const Box3& region = problem.cpvs[c].region;
      cpv_fill[c] = workloadIn(frusta[c], region, visibleFrom(region)).fill;
    }
}

double PlaceEstimates::tObject(int node, uint32_t cpv) {
  const uint64_t key = (uint64_t(uint32_t(node)) << 32) | cpv;
  const auto it = t_object_memo.find(key);
  if (it != t_object_memo.end()) return it->second;
  const Box3& region = view_space->cpvs[cpv].region;
  const std::vector<uint32_t>* visible = visibleFrom(region);
  Workload w;
  for (uint32_t id : hierarchy.objects(node))
    if ((!visible || std::binary_search(visible->begin(), visible->end(), id)) &&
        frusta[cpv].intersects(scene.objects[id - 1].world_bounds))
      addObject(w, id, region);
  return t_object_memo[key] = geometryMs(w.triangles, w.draws, profile.model.fillCredit(cpv_fill[cpv], w.fill));
}

// An impostor's time: its quads and draw calls as geometry, plus what its alpha-tested layers fill (the profile's
// layered draw term over the plan's quads seen from the nearest viewpoint on the axis; 0 for a profile without it).
// The fill is estimated from the CPV's region's nearest point to the shaft's apex (impostor::layeredFillPixels).
double PlaceEstimates::tImpostor(const impostor::LayeredPlan& plan, uint32_t cpv) const {
  const Box3& region = view_space->cpvs[cpv].region;
  const Vec3 nearest = glm::clamp(plan.shaft.apex, region.lo, region.hi);
  const double fill = impostor::layeredFillPixels(plan, double(glm::length(nearest - plan.shaft.apex)), bound);
  return geometryMs(2 * uint64_t(plan.quads()), plan.draws(), 0.0) +
         profile.layered.drawBoundMs(double(plan.quads()), fill);
}

}  // namespace farfield::bake
