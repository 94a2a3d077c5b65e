// Ground height queries for the bake's creation cameras: a uniform grid over the ground's upward-facing triangles,
// counting sort into flat arrays (the city's ground is one large mesh of a few thousand to a few hundred thousand
// triangles; a cell is queried twice per baked impostor).
#include "farfield/extract/ground_height.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace farfield::extract {

GroundHeight::GroundHeight(const scene::Scene& scene, std::span<const uint32_t> object_ids) {
  for (uint32_t id : object_ids) {
    if (id == 0 || id > scene.objects.size()) continue;
    const scene::Object& object = scene.object(id);
    for (const scene::Part& part : object.parts) {
      if (part.mesh >= scene.meshes.size()) continue;
      const scene::Mesh& mesh = scene.meshes[part.mesh];
      for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        Triangle tri;
        tri.a = Vec3(object.transform * Vec4(mesh.positions[mesh.indices[t]], 1.0f));
        tri.b = Vec3(object.transform * Vec4(mesh.positions[mesh.indices[t + 1]], 1.0f));
        tri.c = Vec3(object.transform * Vec4(mesh.positions[mesh.indices[t + 2]], 1.0f));
        const Vec3 n = glm::cross(tri.b - tri.a, tri.c - tri.a);
        const float len = glm::length(n);
        if (!(len > 0.0f) || std::abs(n.z) / len <= 0.2f) continue;  // vertical or degenerate: not walkable
        triangles_.push_back(tri);
        box_.expand(Vec2(tri.a));
        box_.expand(Vec2(tri.b));
        box_.expand(Vec2(tri.c));
      }
    }
  }
  if (triangles_.empty()) return;
  const Vec2 extent = glm::max(box_.extent(), Vec2(1.0f));
  cell_ = std::max(1.0f, float(std::sqrt(double(extent.x) * double(extent.y) / double(triangles_.size()))) * 2.0f);
  nx_ = std::clamp(int(std::ceil(extent.x / cell_)), 1, 2048);
  ny_ = std::clamp(int(std::ceil(extent.y / cell_)), 1, 2048);
  start_.assign(size_t(nx_) * size_t(ny_) + 1, 0);
  auto for_cells = [&](const Triangle& t, auto&& fn) {
    const float x0 = std::min({t.a.x, t.b.x, t.c.x}), x1 = std::max({t.a.x, t.b.x, t.c.x});
    const float y0 = std::min({t.a.y, t.b.y, t.c.y}), y1 = std::max({t.a.y, t.b.y, t.c.y});
    for (int y = cellY(y0); y <= cellY(y1); ++y)
      for (int x = cellX(x0); x <= cellX(x1); ++x) fn(size_t(y) * size_t(nx_) + size_t(x));
  };
  for (const Triangle& t : triangles_) for_cells(t, [&](size_t c) { ++start_[c + 1]; });
  for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  items_.resize(start_.back());
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (uint32_t i = 0; i < triangles_.size(); ++i) for_cells(triangles_[i], [&](size_t c) { items_[fill[c]++] = i; });
}

int GroundHeight::cellX(float x) const { return std::clamp(int((x - box_.lo.x) / cell_), 0, nx_ - 1); }
int GroundHeight::cellY(float y) const { return std::clamp(int((y - box_.lo.y) / cell_), 0, ny_ - 1); }

float GroundHeight::at(float x, float y, float fallback) const {
  if (triangles_.empty() || !box_.contains(Vec2(x, y))) return fallback;
  const size_t c = size_t(cellY(y)) * size_t(nx_) + size_t(cellX(x));
  float best = std::numeric_limits<float>::infinity();
  const DVec2 p(x, y);
  for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
    const Triangle& t = triangles_[items_[k]];
    const DVec2 a(t.a), b(t.b), cc(t.c);
    const double area = cross2(b - a, cc - a);
    if (area == 0.0) continue;
    // Barycentric coordinates; a small tolerance so points on shared edges are not missed.
    const double wa = cross2(b - p, cc - p) / area, wb = cross2(cc - p, a - p) / area, wc = 1.0 - wa - wb;
    constexpr double kEps = -1e-6;
    if (wa < kEps || wb < kEps || wc < kEps) continue;
    best = std::min(best, float(wa * t.a.z + wb * t.b.z + wc * t.c.z));
  }
  return std::isfinite(best) ? best : fallback;
}

}  // namespace farfield::extract
