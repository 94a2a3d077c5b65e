#include "farfield/placement/visibility_cache.h"

#include <fstream>

#include "farfield/core/error.h"

namespace farfield::placement {

nlohmann::json visibilityCacheKey(size_t scene_objects, const Box3& view_space, float min_region_size,
                                  int visibility_face, float far_plane) {
  return {{"scene_objects", scene_objects},
          {"view_space",
           {{"lo", {view_space.lo.x, view_space.lo.y, view_space.lo.z}},
            {"hi", {view_space.hi.x, view_space.hi.y, view_space.hi.z}}}},
          {"min_region_size", min_region_size},
          {"visibility_face", visibility_face},
          {"far_plane", far_plane}};
}

Box3 VisibilityCache::viewSpace() const {
  try {
    const nlohmann::json& v = key.at("view_space");
    const auto corner = [](const nlohmann::json& c) {
      return Vec3(c.at(0).get<float>(), c.at(1).get<float>(), c.at(2).get<float>());
    };
    return Box3::fromPoints(corner(v.at("lo")), corner(v.at("hi")));
  } catch (const nlohmann::json::exception& e) {
    throw Error("visibility cache", std::string("key has no view space: ") + e.what());
  }
}

float VisibilityCache::minRegionSize() const {
  if (!key.contains("min_region_size") || !key.at("min_region_size").is_number())
    throw Error("visibility cache", "key has no min_region_size");
  return key.at("min_region_size").get<float>();
}

std::optional<Box3> VisibilityCache::regionOf(const Vec3& eye) const {
  Box3 box = viewSpace();
  const float min_size = minRegionSize();
  if (!box.contains(eye) || !(min_size > 0.0f)) return std::nullopt;
  // The split of view_space.cpp: the midpoint of the longest axis, the same float arithmetic, down to the size.
  for (int depth = 0; depth < 64; ++depth) {
    const int axis = box.longestAxis();
    if (box.extent()[axis] <= min_size) return box;
    const float mid = 0.5f * (box.lo[axis] + box.hi[axis]);
    Box3 lower = box;
    lower.hi[axis] = mid;
    if (lower.contains(eye))  // on the plane: the lower half, as ViewSpace::lookup
      box = lower;
    else
      box.lo[axis] = mid;
  }
  return box;
}

const std::vector<uint32_t>* VisibilityCache::visibleFrom(const Vec3& eye) const {
  const std::optional<Box3> region = regionOf(eye);
  if (!region) return nullptr;
  const auto it = regions.find({region->lo.x, region->lo.y, region->lo.z});
  return it == regions.end() ? nullptr : &it->second;
}

nlohmann::json VisibilityCache::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [lo, visible] : regions) list.push_back({{"lo", {lo[0], lo[1], lo[2]}}, {"visible", visible}});
  return {{"key", key}, {"regions", list}};
}

VisibilityCache readVisibilityCache(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot read the visibility cache");
  VisibilityCache cache;
  try {
    nlohmann::json j;
    in >> j;
    cache.key = j.at("key");
    for (const nlohmann::json& r : j.at("regions"))
      cache.regions[{r.at("lo").at(0).get<float>(), r.at("lo").at(1).get<float>(), r.at("lo").at(2).get<float>()}] =
          r.at("visible").get<std::vector<uint32_t>>();
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("malformed visibility cache: ") + e.what());
  }
  return cache;
}

}  // namespace farfield::placement
