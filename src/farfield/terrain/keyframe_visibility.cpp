// Keyframe visibility, Chen et al. 1999 section 3.3, equation 3.
#include "farfield/terrain/keyframe_visibility.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "farfield/core/check.h"

namespace farfield::terrain {

bool vertexVisible(const Camera& keyframe, const image::DepthImage& depth, const Vec3& p, const Vec3& n,
                   const VisibilityOptions& options) {
  float w = 0.0f;
  const Vec3 s = keyframe.project(p, &w);
  if (!(w > 0.0f)) return false;  // behind the keyframe camera
  if (!(s.x >= 0.0f && s.y >= 0.0f && s.x < float(depth.width()) && s.y < float(depth.height()))) return false;
  if (!(s.z >= 0.0f && s.z <= 1.0f)) return false;  // outside the near/far range
  const float buffer = depth.at(int(s.x), int(s.y));  // the closest pixel (centre at +0.5)
  if (!(buffer > 0.0f)) return false;                 // background
  const float z_vertex = w;                           // clip w = distance along the view axis
  const float z_buffer = keyframe.linearDepth(buffer);
  float footprint = 0.0f;
  if (options.footprint_pixels > 0.0f) {
    const Vec3 to_eye = glm::normalize(keyframe.eye - p);
    const float sin_a = std::abs(glm::dot(n, to_eye));
    const float cot_a = std::min(std::sqrt(std::max(1.0f - sin_a * sin_a, 0.0f)) / std::max(sin_a, 1e-6f), 20.0f);
    const float beta = keyframe.fovX() / float(keyframe.width);
    footprint = options.footprint_pixels * beta * cot_a;
  }
  return std::abs(z_vertex - z_buffer) < options.thickness_m + (options.thickness_rel + footprint) * z_vertex;
}

void KeyframeVisibility::reset(const QuadtreeLod& lod, const Camera& keyframe, const image::DepthImage* depth,
                               const VisibilityOptions& options, const GridRect* region) {
  FF_CHECK(depth && depth->width() == keyframe.width && depth->height() == keyframe.height);
  lod_ = &lod;
  depth_ = depth;
  camera_ = keyframe;
  options_ = options;
  has_region_ = region != nullptr;
  if (region) region_ = *region;
  visible_.clear();
  classified_ = 0;
}

bool KeyframeVisibility::vertexVisible(uint32_t v) {
  FF_CHECK(lod_ && v < lod_->positions().size());
  const auto [it, fresh] = visible_.try_emplace(v, false);
  if (fresh) {
    const Heightfield& hf = lod_->heightfield();
    const int i = int(v % uint32_t(hf.width)), j = int(v / uint32_t(hf.width));
    it->second = (!has_region_ || region_.contains(i, j)) &&
                 terrain::vertexVisible(camera_, *depth_, lod_->position(v), hf.normal(i, j), options_);
    ++classified_;
  }
  return it->second;
}

size_t KeyframeVisibility::partition(std::vector<uint32_t>& indices) {
  const size_t n = indices.size() / 3;
  scratch_.clear();
  size_t visible = 0;
  // Visible triangles are compacted in place at the front; the others go to scratch and are appended after.
  for (size_t t = 0; t < n; ++t) {
    const uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
    if (triangleVisible(a, b, c)) {
      indices[3 * visible] = a, indices[3 * visible + 1] = b, indices[3 * visible + 2] = c;
      ++visible;
    } else {
      scratch_.push_back(a), scratch_.push_back(b), scratch_.push_back(c);
    }
  }
  std::copy(scratch_.begin(), scratch_.end(), indices.begin() + std::ptrdiff_t(3 * visible));
  return visible;
}

double KeyframeVisibility::visibleShare(std::span<const uint32_t> indices) {
  const size_t n = indices.size() / 3;
  if (n == 0) return 0.0;
  size_t visible = 0;
  for (size_t t = 0; t < n; ++t)
    visible += triangleVisible(indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]) ? 1 : 0;
  return double(visible) / double(n);
}

}  // namespace farfield::terrain
