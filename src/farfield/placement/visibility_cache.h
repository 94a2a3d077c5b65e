// The from-region visible sets of a view space's minimum-size regions, as `farfield place --visibility-cache FILE`
// keeps them between runs: {"key": {...}, "regions": [{"lo": [x, y, z], "visible": [ids]}, ...]}. The key says what
// the sets depend on (the scene's object count, the view space, the minimum region size, the sampling's face size
// and far plane); a region is named by its lower corner, exactly as the view space's regular binary space partition
// (view_space.h) computes it, so an eye's region is found by repeating that partition.
//
// Used by placement (to sample each region once) and by `farfield calibrate --visibility-cache`, which times views
// drawn the way the placed walkthrough draws them: the region's visible set, occlusion-culled.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/bounds.h"

namespace farfield::placement {

struct VisibilityCache {
  nlohmann::json key = nlohmann::json::object();
  std::map<std::array<float, 3>, std::vector<uint32_t>> regions;  // by lower corner; ids ascending

  // The key's view space and minimum region size. Throws farfield::Error when the key lacks them.
  Box3 viewSpace() const;
  float minRegionSize() const;
  // The minimum-size region of the view space's partition that holds `eye` (placement::partitionLeafOf); none outside
  // the view space.
  std::optional<Box3> regionOf(const Vec3& eye) const;
  // Its visible set; nullptr outside the view space or for a region the cache does not hold.
  const std::vector<uint32_t>* visibleFrom(const Vec3& eye) const;
  nlohmann::json toJson() const;  // the file's content
};

// The key placement writes for these inputs (visibility_grid: sample points per side of a region; 2, the corners and
// the centre, is left out, as in caches written before it was an option).
nlohmann::json visibilityCacheKey(size_t scene_objects, const Box3& view_space, float min_region_size,
                                  int visibility_face, float far_plane, int visibility_grid);

// Throws farfield::Error naming the file for a missing, unreadable or malformed cache.
VisibilityCache readVisibilityCache(const std::string& path);

}  // namespace farfield::placement
