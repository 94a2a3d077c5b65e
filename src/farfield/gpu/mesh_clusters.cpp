#include "farfield/gpu/mesh_clusters.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::gpu {
namespace {

// Facing classes: up, down, eight horizontal sectors, no area. The sectors make groups whose triangles turn their
// back to the eye together (the facades on one side of a street); the last class holds triangles without a normal,
// which never count as facing away.
constexpr int kUp = 0, kDown = 1, kSectors = 8, kNoArea = 2 + kSectors, kClasses = kNoArea + 1;
static_assert(kNoArea == kNoFacing);
// Normals closer than this (|n - normal|) share a facing group; more groups than kMaxGroups make a cluster that is
// never tested for facing (it would rarely face away as a whole, and the test would cost more than it saves).
constexpr double kGroupSpread = 1e-3;
constexpr size_t kMaxGroups = 8;
// Margins of facesAway: relative to the distance (a minimum angle between the view ray and a triangle's plane) and to
// the size of the coordinates (float rounding of positions far from the origin), far above the rounding of the
// vertex transform and far below a visible angle.
constexpr float kFacingMargin = 1e-3f;
constexpr float kCoordinateMargin = 1e-4f;

struct Triangle {
  Vec3 centroid;
  Vec3 normal;  // unit; zero without area
  int facing_class = kNoArea;
};

Triangle describe(const Vec3& a, const Vec3& b, const Vec3& c) {
  Triangle t;
  t.centroid = (a + b + c) / 3.0f;
  const glm::dvec3 da(a), db(b), dc(c);
  const glm::dvec3 n = glm::cross(db - da, dc - da);
  const double len = glm::length(n);
  if (!(len > 0.0) || !std::isfinite(len)) return t;
  const glm::dvec3 u = n / len;
  t.normal = Vec3(u);
  if (u.z > 0.7) {
    t.facing_class = kUp;
  } else if (u.z < -0.7) {
    t.facing_class = kDown;
  } else {
    const double sector = (std::atan2(u.y, u.x) + M_PI) / (2.0 * M_PI) * kSectors;
    t.facing_class = 2 + std::clamp(int(sector), 0, kSectors - 1);
  }
  return t;
}

}  // namespace

int facingClass(const Vec3& a, const Vec3& b, const Vec3& c) { return describe(a, b, c).facing_class; }

ClusteredIndices clusterTriangles(const scene::Mesh& mesh, uint32_t max_triangles, uint32_t min_facing_triangles) {
  if (max_triangles == 0) throw Error("clusterTriangles", "max_triangles must be at least 1");
  if (mesh.indices.size() % 3 != 0)
    throw Error("mesh", std::to_string(mesh.indices.size()) + " indices, expected a multiple of 3");
  const size_t n = mesh.positions.size();
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= n)
      throw Error("mesh", "index " + std::to_string(i) + " is " + std::to_string(mesh.indices[i]) + ", only " +
                              std::to_string(n) + " vertices");
  ClusteredIndices out;
  const uint32_t triangles = uint32_t(mesh.indices.size() / 3);
  if (triangles == 0) {
    out.vertex_order.resize(n);
    for (uint32_t v = 0; v < n; ++v) out.vertex_order[v] = v;
    return out;
  }

  auto vertex = [&](uint32_t t, int k) -> const Vec3& { return mesh.positions[mesh.indices[size_t(t) * 3 + k]]; };
  std::vector<Triangle> tri(triangles);
  for (uint32_t t = 0; t < triangles; ++t) tri[t] = describe(vertex(t, 0), vertex(t, 1), vertex(t, 2));
  std::vector<uint32_t> order(triangles);
  for (uint32_t t = 0; t < triangles; ++t) order[t] = t;
  out.indices.reserve(mesh.indices.size());

  // One cluster of the triangles order[lo, hi) (already in emission order): indices, bounds, facing groups.
  auto emit = [&](uint32_t lo, uint32_t hi, bool testable) {
    MeshCluster cluster;
    cluster.first_index = uint32_t(out.indices.size());
    cluster.first_facing = uint32_t(out.facing.size());
    std::vector<std::pair<FacingGroup, glm::dvec3>> groups;  // with the exact normal the spread is measured from
    for (uint32_t i = lo; i < hi; ++i) {
      const uint32_t t = order[i];
      for (int k = 0; k < 3; ++k) {
        out.indices.push_back(mesh.indices[size_t(t) * 3 + k]);
        cluster.bounds.expand(vertex(t, k));
      }
      if (!testable) continue;
      if (tri[t].facing_class == kNoArea) {
        testable = false;
        continue;
      }
      const glm::dvec3 normal(tri[t].normal);
      auto it = std::find_if(groups.begin(), groups.end(),
                             [&](const auto& g) { return glm::length(normal - g.second) <= kGroupSpread; });
      if (it == groups.end()) {
        if (groups.size() == kMaxGroups) {
          testable = false;
          continue;
        }
        FacingGroup g;
        g.normal = tri[t].normal;
        g.offset = -std::numeric_limits<float>::max();
        groups.push_back({g, normal});
        it = groups.end() - 1;
      }
      FacingGroup& g = it->first;
      g.spread = std::max(g.spread, float(glm::length(normal - glm::dvec3(g.normal))));
      for (int k = 0; k < 3; ++k) g.offset = std::max(g.offset, -glm::dot(g.normal, vertex(t, k)));
    }
    cluster.index_count = uint32_t(out.indices.size()) - cluster.first_index;
    if (testable) {
      // Rounding of the stored float normal and offset is covered by kFacingMargin; nudge them outwards anyway.
      for (auto& [g, exact] : groups) {
        g.spread = std::nextafter(g.spread + 1e-6f, 1.0f);
        g.offset = std::nextafter(g.offset, std::numeric_limits<float>::max());
        out.facing.push_back(g);
      }
      cluster.facing_count = uint32_t(groups.size());
    }
    out.clusters.push_back(cluster);
  };

  // Depth-first over ranges of `order`: the right half is pushed first so the left one is split (and emitted) first.
  std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, triangles}};
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    if (hi - lo > max_triangles) {
      Box3 box;
      for (uint32_t i = lo; i < hi; ++i) box.expand(tri[order[i]].centroid);
      const int axis = box.longestAxis();
      const uint32_t mid = lo + (hi - lo) / 2;
      // Ties broken by triangle index, so the split does not depend on the order nth_element leaves them in.
      std::nth_element(order.begin() + lo, order.begin() + mid, order.begin() + hi, [&](uint32_t a, uint32_t b) {
        const float ca = tri[a].centroid[axis], cb = tri[b].centroid[axis];
        return ca < cb || (ca == cb && a < b);
      });
      stack.push_back({mid, hi});
      stack.push_back({lo, mid});
      continue;
    }
    // A spatial leaf: its facing classes in class order (small ones pooled last), each in original triangle order
    // (the submission order a single draw of the mesh had).
    std::array<uint32_t, kClasses> count{};
    for (uint32_t i = lo; i < hi; ++i) ++count[tri[order[i]].facing_class];
    auto rank = [&](uint32_t t) {
      const int c = tri[t].facing_class;
      return c != kNoArea && count[c] >= min_facing_triangles ? c : kClasses;  // kClasses: the mixed pool
    };
    std::sort(order.begin() + lo, order.begin() + hi, [&](uint32_t a, uint32_t b) {
      const int ra = rank(a), rb = rank(b);
      return ra < rb || (ra == rb && a < b);
    });
    for (uint32_t i = lo; i < hi;) {
      uint32_t j = i;
      const int r = rank(order[i]);
      while (j < hi && rank(order[j]) == r) ++j;
      emit(i, j, true);
      i = j;
    }
  }
  // Each cluster's vertices in order of first use, as a block of its own: a vertex several clusters use is repeated
  // in each, so that a cluster's draw spans no other cluster's vertices.
  constexpr uint32_t kUnset = ~0u;
  std::vector<uint32_t> new_of_old(n, kUnset), owner(n, kUnset), used(n, 0);
  out.vertex_order.reserve(n);
  for (uint32_t c = 0; c < uint32_t(out.clusters.size()); ++c) {
    const MeshCluster& cluster = out.clusters[c];
    for (uint32_t i = cluster.first_index; i < cluster.first_index + cluster.index_count; ++i) {
      uint32_t& index = out.indices[i];
      used[index] = 1;
      if (owner[index] != c) {
        owner[index] = c;
        new_of_old[index] = uint32_t(out.vertex_order.size());
        out.vertex_order.push_back(index);
      }
      index = new_of_old[index];
    }
  }
  for (uint32_t v = 0; v < n; ++v)
    if (!used[v]) out.vertex_order.push_back(v);
  return out;
}

scene::Mesh reorderedMesh(const scene::Mesh& mesh, const ClusteredIndices& clustered) {
  scene::Mesh out;
  const size_t n = mesh.positions.size();
  const size_t m = clustered.vertex_order.size();
  auto permute = [&](const auto& values, auto& into) {
    if (values.size() != n) {
      into = values;
      return;
    }
    into.resize(m);
    for (size_t v = 0; v < m; ++v) into[v] = values[clustered.vertex_order[v]];
  };
  permute(mesh.positions, out.positions);
  permute(mesh.normals, out.normals);
  permute(mesh.uvs, out.uvs);
  out.indices = clustered.indices;
  out.bounds = mesh.bounds;
  return out;
}

bool facesAway(const MeshCluster& cluster, std::span<const FacingGroup> facing, const Vec3& eye) {
  if (cluster.facing_count == 0) return false;
  const Vec3 center = cluster.bounds.center();
  const float distance = glm::length(eye - center) + 0.5f * glm::length(cluster.bounds.extent());
  const float margin = kCoordinateMargin * (glm::length(eye) + glm::length(center));
  for (uint32_t k = 0; k < cluster.facing_count; ++k) {
    const FacingGroup& g = facing[cluster.first_facing + k];
    if (!(glm::dot(g.normal, eye) + g.offset + (g.spread + kFacingMargin) * distance + margin < 0.0f)) return false;
  }
  return true;
}

}  // namespace farfield::gpu
