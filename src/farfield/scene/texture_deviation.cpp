#include "farfield/scene/texture_deviation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/closest_point.h"

namespace farfield::scene {

namespace {

constexpr float kInside = -1e-5f;  // barycentric tolerance: a texel on a shared edge is held by both triangles

// Grid coordinate g (in cells) as a cell of 0..n - 1; not a number (uvs near the float range's ends, whose span
// overflows) as cell 0, where the lookup of such a uv finds nothing and falls back to the nearest triangle.
int clampCell(float g, int n) { return g >= 0.0f ? (g < float(n) ? int(g) : n - 1) : 0; }

}  // namespace

Vec3 barycentric2(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  const glm::dvec2 v0 = glm::dvec2(b) - glm::dvec2(a), v1 = glm::dvec2(c) - glm::dvec2(a);
  const glm::dvec2 v2 = glm::dvec2(p) - glm::dvec2(a);
  const double den = v0.x * v1.y - v1.x * v0.y;
  if (den == 0.0) return Vec3(std::numeric_limits<float>::quiet_NaN());
  const double v = (v2.x * v1.y - v1.x * v2.y) / den;
  const double w = (v0.x * v2.y - v2.x * v0.y) / den;
  return Vec3(float(1.0 - v - w), float(v), float(w));
}

Vec3 nearestBarycentric2(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  const Vec3 q = closestOnTriangle(Vec3(p, 0.0f), Vec3(a, 0.0f), Vec3(b, 0.0f), Vec3(c, 0.0f));
  Vec3 w = barycentric2(Vec2(q), a, b, c);
  w = glm::clamp(w, Vec3(0.0f), Vec3(1.0f));
  return w / (w.x + w.y + w.z);
}

UvLocator::UvLocator(std::span<const uint32_t> indices, std::span<const Vec2> uvs) : indices_(indices), uvs_(uvs) {
  Vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (uint32_t t = 0; size_t(t) * 3 + 2 < indices.size(); ++t) {
    const Vec2 &a = uvs[indices[3 * t]], &b = uvs[indices[3 * t + 1]], &c = uvs[indices[3 * t + 2]];
    const float area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (!(std::abs(area) > 0.0f)) continue;
    usable_.push_back(t);
    lo = glm::min(lo, glm::min(a, glm::min(b, c)));
    hi = glm::max(hi, glm::max(a, glm::max(b, c)));
  }
  if (usable_.empty()) return;
  // About two triangles a cell.
  n_ = std::clamp(int(std::ceil(std::sqrt(double(usable_.size()) / 2.0))), 1, 1024);
  lo_ = lo;
  size_ = glm::max(hi - lo, Vec2(1e-12f));
  auto cellRange = [&](uint32_t t, int& x0, int& y0, int& x1, int& y1) {
    const Vec2 &a = uvs[indices[3 * t]], &b = uvs[indices[3 * t + 1]], &c = uvs[indices[3 * t + 2]];
    const Vec2 l = (glm::min(a, glm::min(b, c)) - lo_) / size_ * float(n_);
    const Vec2 h = (glm::max(a, glm::max(b, c)) - lo_) / size_ * float(n_);
    x0 = clampCell(l.x, n_);
    y0 = clampCell(l.y, n_);
    x1 = std::max(x0, clampCell(h.x, n_));
    y1 = std::max(y0, clampCell(h.y, n_));
  };
  first_.assign(size_t(n_) * size_t(n_) + 1, 0);
  int x0, y0, x1, y1;
  for (uint32_t t : usable_) {
    cellRange(t, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) ++first_[cell(x, y) + 1];
  }
  for (size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
  items_.resize(first_.back());
  std::vector<uint32_t> fill(first_.begin(), first_.end() - 1);
  for (uint32_t t : usable_) {
    cellRange(t, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) items_[fill[cell(x, y)]++] = t;
  }
}

void UvLocator::locate(const Vec2& uv, std::vector<Hit>& out) const {
  out.clear();
  if (usable_.empty()) return;
  const Vec2 g = (uv - lo_) / size_ * float(n_);
  if (g.x >= 0.0f && g.y >= 0.0f && g.x <= float(n_) && g.y <= float(n_)) {
    const size_t c = cell(std::min(int(g.x), n_ - 1), std::min(int(g.y), n_ - 1));
    for (uint32_t k = first_[c]; k < first_[c + 1]; ++k) {
      const uint32_t t = items_[k];
      const Vec3 w = barycentric2(uv, uvs_[indices_[3 * t]], uvs_[indices_[3 * t + 1]], uvs_[indices_[3 * t + 2]]);
      if (w.x >= kInside && w.y >= kInside && w.z >= kInside) out.push_back({t, w});
    }
  }
  if (out.empty()) nearest(uv, out);
}

// Outside every chart: the nearest triangle over all of them (rare enough, and exact).
void UvLocator::nearest(const Vec2& uv, std::vector<Hit>& out) const {
  float best = std::numeric_limits<float>::infinity();
  Hit hit{0, Vec3(1.0f, 0.0f, 0.0f)};
  for (uint32_t t : usable_) {
    const Vec2 &a = uvs_[indices_[3 * t]], &b = uvs_[indices_[3 * t + 1]], &c = uvs_[indices_[3 * t + 2]];
    const Vec3 w = nearestBarycentric2(uv, a, b, c);
    const Vec2 q = a * w.x + b * w.y + c * w.z;
    const float d = glm::dot(q - uv, q - uv);
    if (d < best) {
      best = d;
      hit = {t, w};
    }
  }
  out.push_back(hit);
}

double textureDeviation(std::span<const uint32_t> full, std::span<const uint32_t> level,
                        std::span<const std::vector<Vec3>> poses, std::span<const Vec2> uvs, int n) {
  const UvLocator locator(full, uvs);
  std::vector<UvLocator::Hit> hits;
  double worst = 0.0;
  n = std::max(n, 1);
  for (size_t t = 0; t + 2 < level.size(); t += 3) {
    const uint32_t l[3] = {level[t], level[t + 1], level[t + 2]};
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const int k = n - i - j;
        if (i == n || j == n || k == n) continue;  // a corner: the mesh's own vertex
        const Vec3 b(float(i) / float(n), float(j) / float(n), float(k) / float(n));
        const Vec2 uv = uvs[l[0]] * b.x + uvs[l[1]] * b.y + uvs[l[2]] * b.z;
        locator.locate(uv, hits);
        double nearest = std::numeric_limits<double>::infinity();
        for (const UvLocator::Hit& h : hits) {
          const uint32_t f[3] = {full[3 * h.triangle], full[3 * h.triangle + 1], full[3 * h.triangle + 2]};
          double far = 0.0;
          for (const std::vector<Vec3>& pose : poses) {
            const Vec3 shown = pose[l[0]] * b.x + pose[l[1]] * b.y + pose[l[2]] * b.z;
            const Vec3 home = pose[f[0]] * h.barycentric.x + pose[f[1]] * h.barycentric.y +
                              pose[f[2]] * h.barycentric.z;
            far = std::max(far, double(glm::length(shown - home)));
            if (far >= nearest) break;
          }
          nearest = std::min(nearest, far);
        }
        if (std::isfinite(nearest)) worst = std::max(worst, nearest);
      }
  }
  return worst;
}

}  // namespace farfield::scene
