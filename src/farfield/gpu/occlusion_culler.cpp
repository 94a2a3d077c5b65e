#include "farfield/gpu/occlusion_culler.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/check.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/render_target.h"

namespace farfield::gpu {

ScreenBox projectBox(const Box3& box, const Mat4& mvp, int width, int height) {
  ScreenBox out;
  out.nearest = -std::numeric_limits<float>::infinity();
  float min_x = std::numeric_limits<float>::infinity(), min_y = min_x, max_x = -min_x, max_y = -min_x;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    const Vec4 clip = mvp * Vec4(corner, 1.0f);
    // w is the distance in front of the eye plane; a corner on or behind it projects nowhere useful.
    if (!(clip.w > 1e-6f)) {
      out.reaches_eye = true;
      out.x0 = 0, out.y0 = 0, out.x1 = width - 1, out.y1 = height - 1;
      out.nearest = std::numeric_limits<float>::infinity();
      return out;
    }
    const float x = (clip.x / clip.w * 0.5f + 0.5f) * float(width);
    const float y = (clip.y / clip.w * 0.5f + 0.5f) * float(height);
    min_x = std::min(min_x, x), max_x = std::max(max_x, x);
    min_y = std::min(min_y, y), max_y = std::max(max_y, y);
    // Window depth falls with w, and w is linear over the box: its nearest point is a corner.
    out.nearest = std::max(out.nearest, clip.z / clip.w);
  }
  // Pixels whose centre lies in [min, max] have indices in [floor(min), floor(max)]; one more pixel on each side
  // keeps the rasterizer's snapping and rounding inside the footprint.
  out.x0 = std::max(0, int(std::floor(std::max(min_x, -2.0f))) - 1);
  out.y0 = std::max(0, int(std::floor(std::max(min_y, -2.0f))) - 1);
  out.x1 = std::min(width - 1, int(std::floor(std::min(max_x, float(width) + 1.0f))) + 1);
  out.y1 = std::min(height - 1, int(std::floor(std::min(max_y, float(height) + 1.0f))) + 1);
  return out;
}

// ---------------------------------------------------------------------------------------------------------------

void DepthPyramid::build(std::span<const float> depth, int width, int height) {
  FF_CHECK(width > 0 && height > 0 && depth.size() == size_t(width) * size_t(height));
  width_ = width, height_ = height;
  size_t count = 1;
  for (int w = width, h = height; w > 1 || h > 1; w = (w + 1) / 2, h = (h + 1) / 2) ++count;
  levels_.resize(count);
  sizes_.resize(count);
  levels_[0].assign(depth.begin(), depth.end());
  sizes_[0] = {width, height};
  for (size_t k = 1; k < count; ++k) {
    const auto [pw, ph] = sizes_[k - 1];
    const int w = (pw + 1) / 2, h = (ph + 1) / 2;
    sizes_[k] = {w, h};
    const std::vector<float>& below = levels_[k - 1];
    std::vector<float>& level = levels_[k];
    level.resize(size_t(w) * size_t(h));
    for (int y = 0; y < h; ++y) {
      const float* r0 = below.data() + size_t(2 * y) * size_t(pw);
      const float* r1 = 2 * y + 1 < ph ? r0 + pw : r0;
      float* out = level.data() + size_t(y) * size_t(w);
      for (int x = 0; x < w; ++x) {
        const int a = 2 * x, b = std::min(2 * x + 1, pw - 1);
        out[x] = std::min(std::min(r0[a], r0[b]), std::min(r1[a], r1[b]));
      }
    }
  }
}

float DepthPyramid::farthest(int x0, int y0, int x1, int y1) const {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0);
  x1 = std::min(x1, width_ - 1), y1 = std::min(y1, height_ - 1);
  if (x0 > x1 || y0 > y1) return 1.0f;
  // The finest level where the rectangle spans at most two texels each way.
  size_t k = 0;
  while (k + 1 < levels_.size() && ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1)) ++k;
  const int w = sizes_[k].first;
  const std::vector<float>& level = levels_[k];
  float result = std::numeric_limits<float>::infinity();
  for (int y = y0 >> k; y <= (y1 >> k); ++y)
    for (int x = x0 >> k; x <= (x1 >> k); ++x) result = std::min(result, level[size_t(y) * size_t(w) + size_t(x)]);
  return result;
}

bool DepthPyramid::hides(const ScreenBox& box) const {
  if (box.reaches_eye) return false;
  if (!box.onScreen()) return true;  // every corner in front of the eye and no pixel centre covered
  const float stored = farthest(box.x0, box.y0, box.x1, box.y1);
  return box.nearest * (1.0f + 1e-5f) + 1e-12f < stored;
}

// ---------------------------------------------------------------------------------------------------------------

size_t splitNearestFirst(std::vector<uint32_t>& order, std::span<const ScreenBox> boxes,
                         const std::function<uint64_t(uint32_t)>& triangles, double share,
                         uint64_t also_triangles) {
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return boxes[a].nearest != boxes[b].nearest ? boxes[a].nearest > boxes[b].nearest : a < b;
  });
  uint64_t total = also_triangles;
  for (uint32_t i : order) total += triangles(i);
  const double wanted = share * double(total);
  uint64_t drawn = 0;
  size_t split = 0;
  while (split < order.size() && (double(drawn) < wanted || boxes[order[split]].reaches_eye)) {
    drawn += triangles(order[split]);
    ++split;
  }
  return split;
}

OcclusionCuller::OcclusionCuller(double occluder_share) : occluder_share_(occluder_share) {
  FF_CHECK(occluder_share >= 0.0 && occluder_share <= 1.0);
}

OcclusionStats OcclusionCuller::cull(const Camera& camera, std::span<const DrawItem> items,
                                     std::span<const Box3> bounds, const RenderTarget& target,
                                     const std::function<void(std::span<const DrawItem>)>& draw_occluders,
                                     std::vector<DrawItem>& rest, uint64_t also_triangles) {
  FF_CHECK(items.size() == bounds.size());
  OcclusionStats stats;
  stats.items = uint32_t(items.size());
  const int width = target.width(), height = target.height();
  const Mat4 view_proj = camera.viewProjection();
  view_proj_ = view_proj;
  target_ = &target;
  pyramid_built_ = false;
  boxes_.resize(items.size());
  order_.resize(items.size());
  for (size_t i = 0; i < items.size(); ++i) {
    boxes_[i] = projectBox(bounds[i], view_proj * items[i].transform, width, height);
    order_[i] = uint32_t(i);
  }
  const size_t split = splitNearestFirst(
      order_, boxes_, [&](uint32_t i) { return items[i].triangleCount(); }, occluder_share_, also_triangles);
  occluders_.clear();
  for (size_t k = 0; k < split; ++k) occluders_.push_back(items[order_[k]]);
  stats.occluders = uint32_t(occluders_.size());
  draw_occluders(occluders_);
  if (split == order_.size()) return stats;

  buildPyramid(&stats);
  Stopwatch test;
  for (size_t k = split; k < order_.size(); ++k) {
    const uint32_t i = order_[k];
    if (pyramid_.hides(boxes_[i])) {
      ++stats.hidden;
      stats.hidden_triangles += items[i].triangleCount();
    } else {
      rest.push_back(items[i]);
    }
  }
  stats.pyramid_ms += test.milliseconds();
  return stats;
}

void OcclusionCuller::buildPyramid(OcclusionStats* stats) {
  FF_CHECK(target_ != nullptr);
  Stopwatch wait;
  target_->readDepthRows(depth_);
  if (stats) stats->readback_ms = wait.milliseconds();
  Stopwatch build;
  pyramid_.build(depth_, target_->width(), target_->height());
  pyramid_built_ = true;
  if (stats) stats->pyramid_ms = build.milliseconds();
}

bool OcclusionCuller::hidesBox(const Box3& box, const Mat4& model) {
  if (!pyramid_built_) buildPyramid(nullptr);
  return pyramid_.hides(projectBox(box, view_proj_ * model, pyramid_.width(), pyramid_.height()));
}

OcclusionStats OcclusionCuller::appendNotHidden(std::span<const DrawItem> items, std::span<const Box3> bounds,
                                                std::vector<DrawItem>& out) {
  FF_CHECK(items.size() == bounds.size());
  OcclusionStats stats;
  stats.items = uint32_t(items.size());
  for (size_t i = 0; i < items.size(); ++i) {
    if (hidesBox(bounds[i], items[i].transform)) {
      ++stats.hidden;
      stats.hidden_triangles += items[i].triangleCount();
    } else {
      out.push_back(items[i]);
    }
  }
  return stats;
}

OcclusionStats OcclusionCuller::draw(Renderer& renderer, const Camera& camera, std::span<const DrawItem> items,
                                     std::span<const Box3> bounds, RenderTarget& target,
                                     std::span<const DrawItem> also, RenderMode mode) {
  rest_.clear();
  const OcclusionStats stats = cull(
      camera, items, bounds, target,
      [&](std::span<const DrawItem> occluders) { renderer.draw(camera, occluders, target, mode); }, rest_);
  rest_.insert(rest_.end(), also.begin(), also.end());
  renderer.draw(camera, rest_, target, mode);
  return stats;
}

}  // namespace farfield::gpu
