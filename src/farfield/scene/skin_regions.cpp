#include "farfield/scene/skin_regions.h"

#include <algorithm>

#include "farfield/core/error.h"

namespace farfield::scene {

std::vector<uint8_t> colorRegions(const SkinnedModel& model, std::span<const uint32_t> primitive_of_triangle) {
  const size_t triangles = model.mesh.triangleCount();
  std::vector<uint8_t> regions(triangles, 0);
  if (!primitive_of_triangle.empty() && primitive_of_triangle.size() != triangles)
    throw Error(model.name, "colour regions: " + std::to_string(primitive_of_triangle.size()) +
                                " primitive indices for " + std::to_string(triangles) + " triangles");
  const bool several = !primitive_of_triangle.empty() &&
                       std::any_of(primitive_of_triangle.begin(), primitive_of_triangle.end(),
                                   [&](uint32_t p) { return p != primitive_of_triangle[0]; });
  if (several) {
    for (size_t t = 0; t < triangles; ++t) regions[t] = uint8_t(primitive_of_triangle[t] % uint32_t(kColorRegions));
    return regions;
  }
  const size_t joints = model.skeleton.joints.size();
  if (joints == 0 || model.joints.size() != model.mesh.positions.size() ||
      model.weights.size() != model.mesh.positions.size())
    throw Error(model.name, "colour regions: the skin's joints and weights are missing");
  std::vector<uint32_t> dominant(triangles);
  std::vector<float> sum(joints);
  std::vector<bool> used(joints, false);
  for (size_t t = 0; t < triangles; ++t) {
    std::fill(sum.begin(), sum.end(), 0.0f);
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = model.mesh.indices[3 * t + size_t(c)];
      for (int k = 0; k < 4; ++k) {
        const uint16_t j = model.joints[v][size_t(k)];
        if (j < joints) sum[j] += model.weights[v][k];
      }
    }
    dominant[t] = uint32_t(std::max_element(sum.begin(), sum.end()) - sum.begin());  // first maximum
    used[dominant[t]] = true;
  }
  std::vector<uint32_t> rank(joints, 0);
  uint32_t n = 0;
  for (size_t j = 0; j < joints; ++j)
    if (used[j]) rank[j] = n++;
  for (size_t t = 0; t < triangles; ++t)
    regions[t] = uint8_t(uint64_t(rank[dominant[t]]) * uint64_t(kColorRegions) / std::max<uint32_t>(n, 1));
  return regions;
}

}  // namespace farfield::scene
