// Deviation of a depth mesh from the 2.5D surface of its capture (see the header). Both nearest-neighbour searches
// walk square rings of a uniform grid over x, y outwards from the query's cell and stop once the best distance found
// is no larger than the ring's inner radius: every later ring lies farther away in x, y alone.
#include "farfield/store/export_tiles_deviation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "farfield/core/closest_point.h"
#include "farfield/core/error.h"
#include "farfield/impostor/contour.h"

namespace farfield::store {
namespace {

// Items (points or triangles) bucketed by the cells of a uniform x, y grid their x, y bounds overlap (CSR layout).
class Grid {
 public:
  Grid(const Box2& bounds, float cell, const std::vector<Box2>& items) : lo_(bounds.lo), cell_(cell) {
    nx_ = std::max(1, int(std::ceil((bounds.hi.x - bounds.lo.x) / cell)) + 1);
    ny_ = std::max(1, int(std::ceil((bounds.hi.y - bounds.lo.y) / cell)) + 1);
    start_.assign(size_t(nx_) * size_t(ny_) + 1, 0);
    auto forCells = [&](const Box2& b, auto&& fn) {
      const IVec2 c0 = cellOf(b.lo), c1 = cellOf(b.hi);
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) fn(size_t(y) * size_t(nx_) + size_t(x));
    };
    for (const Box2& b : items) forCells(b, [&](size_t c) { ++start_[c + 1]; });
    for (size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
    entries_.resize(start_.back());
    std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < items.size(); ++i) forCells(items[i], [&](size_t c) { entries_[fill[c]++] = uint32_t(i); });
  }

  // Smallest dist(p, item) over the items, dist giving the 3D distance of an item; +infinity when there is none.
  template <class Dist>
  double nearest(const Vec3& p, Dist&& dist) const {
    const IVec2 c = cellOf(Vec2(p));
    double best = std::numeric_limits<double>::infinity();
    const int rings = std::max(nx_, ny_);
    for (int k = 0; k <= rings; ++k) {
      for (int y = c.y - k; y <= c.y + k; ++y) {
        if (y < 0 || y >= ny_) continue;
        const bool edge_row = y == c.y - k || y == c.y + k;
        for (int x = c.x - k; x <= c.x + k; x += (edge_row ? 1 : 2 * k)) {
          if (x >= 0 && x < nx_) {
            const size_t cell = size_t(y) * size_t(nx_) + size_t(x);
            for (uint32_t e = start_[cell]; e < start_[cell + 1]; ++e) best = std::min(best, dist(entries_[e]));
          }
          if (k == 0) break;
        }
      }
      // Items in ring k + 1 or beyond are at least k cells away in x, y.
      if (best <= double(k) * cell_) break;
    }
    return best;
  }

 private:
  IVec2 cellOf(const Vec2& p) const {
    return IVec2(std::clamp(int(std::floor((p.x - lo_.x) / cell_)), 0, nx_ - 1),
                 std::clamp(int(std::floor((p.y - lo_.y) / cell_)), 0, ny_ - 1));
  }

  Vec2 lo_;
  float cell_;
  int nx_ = 1, ny_ = 1;
  std::vector<uint32_t> start_, entries_;
};

}  // namespace

Deviation measureDeviation(const scene::Mesh& mesh, const impostor::ImpostorCapture& capture) {
  const Camera& cam = capture.camera;
  if (cam.forward().z > -0.9f) throw Error("deviation", "the capture does not look down");
  if (mesh.indices.size() < 3) throw Error("deviation", "the depth mesh has no triangles");
  const int w = capture.depth.width(), h = capture.depth.height();

  // The capture's visible points (Camera::unproject with the inverse view computed once).
  const Mat4 inv_view = glm::inverse(cam.view());
  const float t = std::tan(cam.fov_y * 0.5f);
  std::vector<Vec3> top(size_t(w) * size_t(h));
  std::vector<uint8_t> data(top.size(), 0);
  float farthest = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float depth = capture.depth.at(x, y);
      if (!impostor::isImpostorData(capture.color.at(x, y), depth)) continue;
      const float d = cam.linearDepth(depth);
      const float ndc_x = ((float(x) + 0.5f) / float(w)) * 2.0f - 1.0f;
      const float ndc_y = 1.0f - ((float(y) + 0.5f) / float(h)) * 2.0f;
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      top[i] = Vec3(inv_view * Vec4(ndc_x * t * cam.aspect() * d, ndc_y * t * d, -d, 1.0f));
      data[i] = 1;
      farthest = std::max(farthest, d);
    }
  if (farthest <= 0.0f) throw Error("deviation", "the capture has no data pixel");
  Deviation out;
  const float s = 2.0f * farthest * t / float(h);  // the largest texel (square pixels)
  out.texel = s;

  // Surface samples: the visible points and the walls at depth steps below them.
  std::vector<Vec3> surface;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (!data[i]) continue;
      surface.push_back(top[i]);
      float lowest = top[i].z;
      for (const IVec2 d : {IVec2(1, 0), IVec2(-1, 0), IVec2(0, 1), IVec2(0, -1)}) {
        const int nx = x + d.x, ny = y + d.y;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const size_t j = size_t(ny) * size_t(w) + size_t(nx);
        if (data[j]) lowest = std::min(lowest, top[j].z);
      }
      for (float z = top[i].z - s; z > lowest; z -= s) surface.emplace_back(top[i].x, top[i].y, z);
      if (lowest < top[i].z) surface.emplace_back(top[i].x, top[i].y, lowest);
    }
  out.surface_samples = surface.size();

  Box2 bounds;
  for (const Vec3& p : surface) bounds.expand(Vec2(p));
  for (const Vec3& p : mesh.positions) bounds.expand(Vec2(p));
  const size_t triangles = mesh.indices.size() / 3;
  auto corner = [&](size_t tri, int k) { return mesh.positions[mesh.indices[tri * 3 + size_t(k)]]; };

  // Surface -> mesh: exact point-triangle distances.
  {
    std::vector<Box2> boxes(triangles);
    for (size_t i = 0; i < triangles; ++i)
      for (int k = 0; k < 3; ++k) boxes[i].expand(Vec2(corner(i, k)));
    const Grid grid(bounds, 4.0f * s, boxes);
    for (const Vec3& p : surface) {
      const double d = grid.nearest(p, [&](uint32_t tri) {
        return double(glm::distance(p, closestOnTriangle(p, corner(tri, 0), corner(tri, 1), corner(tri, 2))));
      });
      if (d > out.surface_to_mesh) out.worst_surface = p;
      out.surface_to_mesh = std::max(out.surface_to_mesh, d);
    }
  }
  // Mesh -> surface: a barycentric grid on every triangle to the nearest surface sample.
  {
    std::vector<Box2> points(surface.size());
    for (size_t i = 0; i < surface.size(); ++i) points[i].expand(Vec2(surface[i]));
    const Grid grid(bounds, 2.0f * s, points);
    for (size_t tri = 0; tri < triangles; ++tri) {
      const Vec3 a = corner(tri, 0), b = corner(tri, 1), c = corner(tri, 2);
      const float longest = std::max({glm::distance(a, b), glm::distance(b, c), glm::distance(c, a)});
      const int n = std::clamp(int(std::ceil(longest / s)), 1, 4096);
      for (int i = 0; i <= n; ++i)
        for (int j = 0; i + j <= n; ++j) {
          const Vec3 p = a + (b - a) * (float(i) / float(n)) + (c - a) * (float(j) / float(n));
          const double d =
              grid.nearest(p, [&](uint32_t k) { return double(glm::distance(p, surface[k])); });
          if (d > out.mesh_to_surface) out.worst_mesh = p;
          out.mesh_to_surface = std::max(out.mesh_to_surface, d);
          ++out.mesh_samples;
        }
    }
  }
  out.metres = std::max(out.surface_to_mesh, out.mesh_to_surface) + double(s) / std::sqrt(2.0);
  return out;
}

}  // namespace farfield::store
