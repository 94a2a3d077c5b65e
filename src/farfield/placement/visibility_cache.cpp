#include "farfield/placement/visibility_cache.h"

#include <fstream>

#include "farfield/core/error.h"
#include "farfield/placement/view_space.h"

namespace farfield::placement {

nlohmann::json visibilityCacheKey(size_t scene_objects, const Box3& view_space, float min_region_size,
                                  int visibility_face, float far_plane, int visibility_grid) {
  nlohmann::json key = {{"scene_objects", scene_objects},
                        {"view_space",
                         {{"lo", {view_space.lo.x, view_space.lo.y, view_space.lo.z}},
                          {"hi", {view_space.hi.x, view_space.hi.y, view_space.hi.z}}}},
                        {"min_region_size", min_region_size},
                        {"visibility_face", visibility_face},
                        {"far_plane", far_plane}};
  if (visibility_grid != 2) key["visibility_grid"] = visibility_grid;  // caches of before the grid have none
  return key;
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
  return partitionLeafOf(viewSpace(), minRegionSize(), eye);
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
