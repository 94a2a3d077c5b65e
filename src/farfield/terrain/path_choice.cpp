// Per-frame choice between the high LOD and the LOD-sprite path (Chen et al. 1999 section 3) from calibrated costs.
#include "farfield/terrain/path_choice.h"

#include <algorithm>
#include <vector>

namespace farfield::terrain {

const char* terrainPathName(TerrainPath path) { return path == TerrainPath::High ? "high" : "sprite"; }

TerrainPath choosePath(const PathCosts& costs, bool sprite_valid, double expected_lifetime) {
  if (sprite_valid) return costs.sprite_ms < costs.high_ms ? TerrainPath::Sprite : TerrainPath::High;
  // Over L frames: one keyframe frame and L - 1 sprite frames against L high frames. Ties go to the high LOD (the
  // better image for the same time).
  const double life = std::max(expected_lifetime, 1.0);
  const double sprite_total = costs.keyframe_ms + (life - 1.0) * costs.sprite_ms;
  return sprite_total < life * costs.high_ms ? TerrainPath::Sprite : TerrainPath::High;
}

double spriteLifetimeEstimate(const std::deque<uint64_t>& recent, double fallback) {
  if (recent.empty()) return fallback;
  std::vector<uint64_t> v(recent.begin(), recent.end());
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? double(v[n / 2]) : 0.5 * double(v[n / 2 - 1] + v[n / 2]);
}

}  // namespace farfield::terrain
