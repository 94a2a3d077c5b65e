// From-region visibility (section 3.1, observation 2.3): the objects seen from each minimum-size region, sampled
// in 360-degree item buffers from points over its floor plan or read from the visibility cache.
#include <filesystem>
#include <utility>
#include <vector>

#include "farfield/bake/place_steps.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/placement/visibility_cache.h"
#include "farfield/placement/view_space.h"
#include "farfield/store/impostor_store.h"
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

}  // namespace

RegionVisibility::RegionVisibility(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const Box3& space,
                                   const PlaceOptions& options, PlaceReport& report)
    : options(options),
      report(report),
      cache_key(placement::visibilityCacheKey(scene.objects.size(), space, options.min_region_size,
                                              options.visibility_face, options.far_plane, options.visibility_grid)) {
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
  }
}

std::vector<uint32_t> RegionVisibility::visibleSet(const Box3& region) {
  if (!placement::isPartitionLeaf(region, options.min_region_size))
    return {};  // big regions: every object counts (conservative)
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
}

void RegionVisibility::finish() {
  if (report.visibility_regions) report.mean_visible_objects /= double(report.visibility_regions);
  if (!options.visibility || options.visibility_cache.empty() || report.visibility_cached >= report.visibility_regions)
    return;
  placement::VisibilityCache cache;
  cache.key = cache_key;
  cache.regions = region_visible;
  store::writeFileAtomic(options.visibility_cache, cache.toJson().dump() + "\n");
}

}  // namespace farfield::bake
