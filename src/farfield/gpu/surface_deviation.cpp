#include "farfield/gpu/surface_deviation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/bounds.h"
#include "farfield/core/closest_point.h"

namespace farfield::gpu {
namespace {

// Triangles bucketed by the grid cells their boxes overlap; about one cell per triangle.
class TriangleGrid {
 public:
  TriangleGrid(std::span<const Vec3> positions, std::span<const uint32_t> indices)
      : positions_(positions), indices_(indices) {
    for (uint32_t i : indices) bounds_.expand(positions[i]);
    const size_t triangles = indices.size() / 3;
    const Vec3 extent = glm::max(bounds_.hi - bounds_.lo, Vec3(1e-6f));
    const float volume_cell = std::cbrt(extent.x * extent.y * extent.z / float(std::max<size_t>(triangles, 1)));
    // Flat meshes have no volume: a cell no smaller than the longest extent over sqrt(triangles).
    cell_ = std::max(volume_cell, std::max({extent.x, extent.y, extent.z}) /
                                      std::sqrt(float(std::max<size_t>(triangles, 1))));
    for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(int(std::ceil(extent[a] / cell_)), 1, 256);
    cells_.assign(size_t(dims_[0]) * size_t(dims_[1]) * size_t(dims_[2]), {});
    for (uint32_t t = 0; t < triangles; ++t) {
      Box3 box;
      for (int k = 0; k < 3; ++k) box.expand(positions[indices[3 * t + k]]);
      const auto lo = cellOf(box.lo), hi = cellOf(box.hi);
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) cells_[index(x, y, z)].push_back(t);
    }
  }

  // The distance from p to the nearest triangle: rings of cells around p's cell until the ring's own distance from
  // p exceeds the best found.
  double distance(const Vec3& p) const {
    if (indices_.empty()) return std::numeric_limits<double>::infinity();
    const auto c = cellOf(p);
    // How far p lies outside the grid: rings start counting from there.
    const Vec3 outside = glm::max(glm::max(bounds_.lo - p, p - bounds_.hi), Vec3(0.0f));
    const double offset = glm::length(outside);
    double best = std::numeric_limits<double>::infinity();
    const int max_ring = std::max({dims_[0], dims_[1], dims_[2]});
    for (int r = 0; r <= max_ring; ++r) {
      if (best <= offset + double(r - 1) * cell_) break;  // every cell of ring r is farther than best
      for (int z = c[2] - r; z <= c[2] + r; ++z)
        for (int y = c[1] - r; y <= c[1] + r; ++y)
          for (int x = c[0] - r; x <= c[0] + r; ++x) {
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
            if (x < 0 || y < 0 || z < 0 || x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) continue;
            const std::vector<uint32_t>& cell = cells_[index(x, y, z)];
            if (cell.empty()) continue;
            // The cell's own distance from p: none of its triangles is nearer.
            const Vec3 lo = bounds_.lo + Vec3(float(x), float(y), float(z)) * cell_;
            const Vec3 gap = glm::max(glm::max(lo - p, p - (lo + Vec3(cell_))), Vec3(0.0f));
            if (double(glm::length(gap)) >= best) continue;
            for (uint32_t t : cell) {
              const Vec3 q = closestOnTriangle(p, positions_[indices_[3 * t]], positions_[indices_[3 * t + 1]],
                                               positions_[indices_[3 * t + 2]]);
              best = std::min(best, double(glm::length(q - p)));
            }
          }
    }
    return best;
  }

 private:
  std::array<int, 3> cellOf(const Vec3& p) const {
    std::array<int, 3> c{};
    for (int a = 0; a < 3; ++a) c[size_t(a)] = std::clamp(int(std::floor((p[a] - bounds_.lo[a]) / cell_)), 0, dims_[a] - 1);
    return c;
  }
  size_t index(int x, int y, int z) const { return (size_t(z) * size_t(dims_[1]) + size_t(y)) * size_t(dims_[0]) + size_t(x); }

  std::span<const Vec3> positions_;
  std::span<const uint32_t> indices_;
  Box3 bounds_;
  float cell_ = 1.0f;
  int dims_[3] = {1, 1, 1};
  std::vector<std::vector<uint32_t>> cells_;
};

}  // namespace

double surfaceDeviation(std::span<const Vec3> positions, std::span<const uint32_t> full,
                        std::span<const uint32_t> simplified) {
  if (full.empty() && simplified.empty()) return 0.0;
  if (full.empty() || simplified.empty()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  {
    const TriangleGrid grid(positions, simplified);
    std::vector<uint8_t> seen(positions.size(), 0);
    for (uint32_t v : full) {
      if (seen[v]) continue;
      seen[v] = 1;
      worst = std::max(worst, grid.distance(positions[v]));
    }
  }
  const TriangleGrid grid(positions, full);
  for (size_t i = 0; i + 2 < simplified.size(); i += 3) {
    const Vec3 a = positions[simplified[i]], b = positions[simplified[i + 1]], c = positions[simplified[i + 2]];
    for (const Vec3& p : {a, b, c, (a + b) * 0.5f, (b + c) * 0.5f, (a + c) * 0.5f, (a + b + c) / 3.0f,
                          a * (2.0f / 3.0f) + (b + c) / 6.0f, b * (2.0f / 3.0f) + (a + c) / 6.0f,
                          c * (2.0f / 3.0f) + (a + b) / 6.0f})
      worst = std::max(worst, grid.distance(p));
  }
  return worst;
}

}  // namespace farfield::gpu
