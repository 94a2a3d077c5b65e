// Vertex depth for impostor reprojection (Sillion et al. 1997, section 4.2, "Triangulation and 3D reprojection").
//
// Why extrapolate instead of reading the pixel: contour vertices are pixel corners and the depth image holds
// values at pixel centres. Reading the centre's depth would put a corner vertex of a slanted facade up to half a
// pixel's depth change off the surface; with the gradient the error is that of the depth buffer itself for planes.
//
// Why the nearer pixel on a step: a vertex on the boundary between a near and a far surface must pick one. The near
// side is the occluder; putting its boundary vertices on it keeps its outline where the geometry has it when the
// viewer moves, and the one-pixel strip of triangles between the two discrepancy chains takes up the step.
#include "farfield/impostor/depth_sampler.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include "farfield/core/check.h"

namespace farfield::impostor {

DepthSampler::DepthSampler(const image::DepthImage& window_depth, const image::Image<uint8_t>& mask,
                           const image::DepthImage& linear_depth, const DiscrepancyOptions& continuity)
    : window_(window_depth), mask_(mask), linear_(linear_depth), continuity_(continuity) {
  FF_CHECK(window_.width() == mask_.width() && window_.height() == mask_.height());
  FF_CHECK(linear_.width() == mask_.width() && linear_.height() == mask_.height());
}

void DepthSampler::buildNearestMap() const {
  if (!nearest_.empty()) return;
  const int w = mask_.width(), h = mask_.height();
  nearest_.assign(size_t(w) * size_t(h), -1);
  nearest_distance_.assign(size_t(w) * size_t(h), -1);
  // Multi-source breadth-first search from all data pixels (8-connected), ring by ring; a pixel reached from
  // several pixels of the previous ring keeps the source nearest to it in Euclidean distance.
  std::deque<int32_t> queue;
  for (int i = 0; i < w * h; ++i)
    if (mask_.pixels()[size_t(i)]) {
      nearest_[size_t(i)] = i;
      nearest_distance_[size_t(i)] = 0;
      queue.push_back(i);
    }
  while (!queue.empty()) {
    const int32_t i = queue.front();
    queue.pop_front();
    const int x = i % w, y = i / w;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const int32_t j = ny * w + nx;
        const int32_t source = nearest_[size_t(i)];
        if (nearest_[size_t(j)] < 0) {
          nearest_[size_t(j)] = source;
          nearest_distance_[size_t(j)] = nearest_distance_[size_t(i)] + 1;
          queue.push_back(j);
        } else if (nearest_distance_[size_t(j)] == nearest_distance_[size_t(i)] + 1) {
          auto d2 = [&](int32_t s) {
            const int sx = s % w - nx, sy = s / w - ny;
            return sx * sx + sy * sy;
          };
          if (d2(source) < d2(nearest_[size_t(j)])) nearest_[size_t(j)] = source;
        }
      }
  }
}

std::optional<IVec2> DepthSampler::sourcePixel(const DVec2& p, int max_search_px) const {
  const int w = mask_.width(), h = mask_.height();
  if (w == 0 || h == 0 || !std::isfinite(p.x) || !std::isfinite(p.y)) return std::nullopt;
  const int x0 = int(std::floor(p.x)), y0 = int(std::floor(p.y));
  // Pixels whose closed square contains p: on an integer coordinate the pixel before it touches p too.
  const int xs[2] = {x0, p.x == double(x0) ? x0 - 1 : x0};
  const int ys[2] = {y0, p.y == double(y0) ? y0 - 1 : y0};
  std::optional<IVec2> best;
  float best_depth = -1.0f;
  for (int y : ys)
    for (int x : xs) {
      if (x < 0 || y < 0 || x >= w || y >= h || !mask_.at(x, y)) continue;
      if (window_.at(x, y) > best_depth) {
        best_depth = window_.at(x, y);
        best = IVec2(x, y);
      }
    }
  if (best || max_search_px == 0) return best;
  buildNearestMap();
  const int cx = std::clamp(x0, 0, w - 1), cy = std::clamp(y0, 0, h - 1);
  const size_t i = size_t(cy) * size_t(w) + size_t(cx);
  if (nearest_[i] < 0) return std::nullopt;  // no data at all
  if (max_search_px > 0 && nearest_distance_[i] > max_search_px) return std::nullopt;
  return IVec2(nearest_[i] % w, nearest_[i] / w);
}

std::optional<DepthSampler::Sample> DepthSampler::sample(const DVec2& p, int max_search_px) const {
  const std::optional<IVec2> source = sourcePixel(p, max_search_px);
  if (!source) return std::nullopt;
  const int w = mask_.width(), h = mask_.height();
  const int x = source->x, y = source->y;
  const float z = window_.at(x, y);
  const float d = linear_.at(x, y);
  auto continuous = [&](int nx, int ny) {
    return nx >= 0 && ny >= 0 && nx < w && ny < h && mask_.at(nx, ny) &&
           depthContinuous(d, linear_.at(nx, ny), continuity_);
  };
  auto gradient = [&](int dx, int dy) {
    const bool fwd = continuous(x + dx, y + dy), back = continuous(x - dx, y - dy);
    if (fwd && back) return 0.5 * (double(window_.at(x + dx, y + dy)) - double(window_.at(x - dx, y - dy)));
    if (fwd) return double(window_.at(x + dx, y + dy)) - double(z);
    if (back) return double(z) - double(window_.at(x - dx, y - dy));
    return 0.0;
  };
  const double offset_x = p.x - (x + 0.5), offset_y = p.y - (y + 0.5);
  double value = double(z) + gradient(1, 0) * offset_x + gradient(0, 1) * offset_y;
  // Far from the source (a vertex found by the nearest-data search) or past the planes' range: keep the pixel's.
  if (std::abs(offset_x) > 1.0 || std::abs(offset_y) > 1.0 || !(value > 0.0 && value <= 1.0)) value = z;
  return Sample{float(value), *source};
}

}  // namespace farfield::impostor
