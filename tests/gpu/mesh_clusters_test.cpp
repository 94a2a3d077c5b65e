// Clusters of a mesh's triangles (no GL): every triangle in exactly one cluster, sizes, bounds, and facesAway
// against a brute-force facing test of every triangle.
#include "farfield/gpu/mesh_clusters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"

namespace farfield::gpu {
namespace {

// Boxes scattered over a block, turned to a few directions (as buildings follow the streets), as one mesh.
scene::Mesh blockOfBoxes(int count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  scene::Mesh mesh;
  for (int i = 0; i < count; ++i) {
    const Vec3 lo(u(rng) * 60.0f, u(rng) * 60.0f, 0.0f);
    const Vec3 size(1.0f + u(rng) * 6.0f, 1.0f + u(rng) * 6.0f, 2.0f + u(rng) * 20.0f);
    const float angles[] = {0.0f, 0.3f, 1.2f, 2.0f};
    const float angle = angles[std::min(int(u(rng) * 4.0f), 3)];
    const Mat4 m = glm::rotate(glm::translate(Mat4(1.0f), lo), angle, Vec3(0, 0, 1));
    mesh.append(scene::makeBox(Vec3(0.0f), size), m);
  }
  mesh.computeBounds();
  return mesh;
}

using Tri = std::array<uint32_t, 3>;

std::vector<Tri> triangles(const std::vector<uint32_t>& indices, uint32_t first, uint32_t count) {
  std::vector<Tri> out;
  for (uint32_t i = first; i < first + count; i += 3) out.push_back({indices[i], indices[i + 1], indices[i + 2]});
  return out;
}

TEST(MeshClusters, EveryTriangleInExactlyOneClusterOfBoundedSize) {
  const scene::Mesh mesh = blockOfBoxes(300, 1);  // 3600 triangles
  for (uint32_t max : {1u, 7u, 64u, 500u, 5000u}) {
    const ClusteredIndices c = clusterTriangles(mesh, max, 8);
    ASSERT_EQ(c.indices.size(), mesh.indices.size()) << max;
    // The ranges tile the index list in order.
    uint32_t next = 0;
    uint64_t triangle_sum = 0;
    for (const MeshCluster& cluster : c.clusters) {
      ASSERT_EQ(cluster.first_index, next) << max;
      ASSERT_GT(cluster.index_count, 0u);
      ASSERT_EQ(cluster.index_count % 3, 0u);
      ASSERT_LE(cluster.index_count / 3, max);
      next += cluster.index_count;
      triangle_sum += cluster.index_count / 3;
      for (uint32_t i = cluster.first_index; i < cluster.first_index + cluster.index_count; ++i)
        ASSERT_TRUE(cluster.bounds.contains(mesh.positions[c.vertex_order[c.indices[i]]]));
      ASSERT_LE(size_t(cluster.first_facing) + cluster.facing_count, c.facing.size());
    }
    EXPECT_EQ(next, c.indices.size());
    EXPECT_EQ(triangle_sum, mesh.triangleCount());
    // The same triangles (with their winding), each exactly once.
    std::vector<Tri> want = triangles(mesh.indices, 0, uint32_t(mesh.indices.size()));
    // Every vertex at least once in the new order; the triangles map back to the same ones.
    std::vector<uint32_t> order = c.vertex_order;
    std::sort(order.begin(), order.end());
    order.erase(std::unique(order.begin(), order.end()), order.end());
    for (uint32_t v = 0; v < order.size(); ++v) ASSERT_EQ(order[v], v);
    ASSERT_EQ(order.size(), mesh.positions.size());
    std::vector<Tri> got = triangles(c.indices, 0, uint32_t(c.indices.size()));
    for (Tri& t : got)
      for (uint32_t& v : t) v = c.vertex_order[v];
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, want) << max;
  }
  // A small mesh is one cluster with its indices as they were.
  const scene::Mesh cube = scene::makeUnitCube();
  const ClusteredIndices one = clusterTriangles(cube, 100, 1000);
  ASSERT_EQ(one.clusters.size(), 1u);
  std::vector<uint32_t> original;
  for (uint32_t v : one.indices) original.push_back(one.vertex_order[v]);
  EXPECT_EQ(original, cube.indices);
}

TEST(MeshClusters, EachClusterHasItsOwnBlockOfVertices) {
  // The vertices a cluster uses are one block, the blocks follow each other in cluster order, and the reordered mesh
  // draws the same triangles at the same places.
  const scene::Mesh mesh = blockOfBoxes(300, 4);
  const ClusteredIndices c = clusterTriangles(mesh, 64, 8);
  uint32_t next = 0;
  for (const MeshCluster& cluster : c.clusters) {
    std::vector<uint32_t> used(c.indices.begin() + cluster.first_index,
                               c.indices.begin() + cluster.first_index + cluster.index_count);
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    ASSERT_EQ(used.front(), next) << "cluster at index " << cluster.first_index;
    ASSERT_EQ(used.back() - used.front() + 1, used.size()) << "cluster at index " << cluster.first_index;
    next += uint32_t(used.size());
  }
  // Repeated vertices (where a split cuts through shared vertices) stay few.
  EXPECT_LE(c.vertex_order.size(), mesh.positions.size() * 5 / 4);
  const scene::Mesh reordered = reorderedMesh(mesh, c);
  ASSERT_EQ(reordered.positions.size(), c.vertex_order.size());
  ASSERT_EQ(reordered.normals.size(), c.vertex_order.size());
  ASSERT_EQ(reordered.uvs.size(), c.vertex_order.size());
  for (size_t i = 0; i < c.indices.size(); ++i) {
    const uint32_t after = c.indices[i];
    EXPECT_EQ(reordered.positions[after], mesh.positions[c.vertex_order[after]]);
    EXPECT_EQ(reordered.normals[after], mesh.normals[c.vertex_order[after]]);
    EXPECT_EQ(reordered.uvs[after], mesh.uvs[c.vertex_order[after]]);
  }
}

TEST(MeshClusters, ClustersAreSpatiallyCompact) {
  // 64-triangle clusters (about five boxes) of a 60 m block: on average far smaller than the block, which clusters
  // of triangles taken in any order but by place would not be.
  const scene::Mesh mesh = blockOfBoxes(300, 2);
  const ClusteredIndices c = clusterTriangles(mesh, 64, 1u << 30);  // no facing split: spatial leaves only
  ASSERT_GE(c.clusters.size(), 3600u / 64);
  double volume = 0.0;
  for (const MeshCluster& cluster : c.clusters) {
    const Vec3 e = cluster.bounds.extent();
    volume += double(e.x) * e.y * e.z;
  }
  const Vec3 e = mesh.bounds.extent();
  EXPECT_LT(volume / double(c.clusters.size()), 0.05 * double(e.x) * e.y * e.z);
}

TEST(MeshClusters, FacesAwayOnlyWhenEveryTriangleFacesAway) {
  const scene::Mesh mesh = blockOfBoxes(200, 3);
  const ClusteredIndices c = clusterTriangles(mesh, 128, 4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-80.0f, 140.0f);
  int away = 0, all_back_but_kept = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Vec3 eye(u(rng), u(rng), std::abs(u(rng)) * 0.3f - 5.0f);
    for (const MeshCluster& cluster : c.clusters) {
      bool all_back = true;
      for (uint32_t i = cluster.first_index; i < cluster.first_index + cluster.index_count; i += 3) {
        auto at = [&](uint32_t k) { return glm::dvec3(mesh.positions[c.vertex_order[c.indices[k]]]); };
        const glm::dvec3 a = at(i), b = at(i + 1), d = at(i + 2);
        const glm::dvec3 n = glm::cross(b - a, d - a);
        if (glm::dot(n, glm::dvec3(eye) - a) >= 0.0) all_back = false;
      }
      const bool says_away = facesAway(cluster, c.facing, eye);
      if (says_away) {
        ++away;
        ASSERT_TRUE(all_back) << "trial " << trial << ", cluster at index " << cluster.first_index;
      } else if (all_back) {
        ++all_back_but_kept;
      }
    }
  }
  // Not vacuous: clusters of one facing direction do face away from many eyes, and the margins miss few of them.
  EXPECT_GT(away, 1000);
  EXPECT_LT(all_back_but_kept, away / 4);
}

TEST(MeshClusters, TrianglesWithoutAreaNeverFaceAway) {
  scene::Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  mesh.indices = {0, 1, 2, 0, 1, 3};  // an up-facing triangle and one on a line
  const ClusteredIndices c = clusterTriangles(mesh, 10, 1);
  for (const MeshCluster& cluster : c.clusters) {
    bool has_line = false;
    for (uint32_t i = cluster.first_index; i < cluster.first_index + cluster.index_count; ++i)
      has_line = has_line || c.vertex_order[c.indices[i]] == 3;
    EXPECT_EQ(facesAway(cluster, c.facing, Vec3(0.2f, 0.2f, -10.0f)), !has_line);
  }
}

TEST(MeshClusters, RejectsBadIndices) {
  scene::Mesh mesh = scene::makeUnitCube();
  mesh.indices.push_back(0);
  EXPECT_THROW(clusterTriangles(mesh, 16), Error);
  mesh = scene::makeUnitCube();
  mesh.indices[4] = uint32_t(mesh.positions.size());
  EXPECT_THROW(clusterTriangles(mesh, 16), Error);
  EXPECT_THROW(clusterTriangles(scene::makeUnitCube(), 0), Error);
  EXPECT_TRUE(clusterTriangles(scene::Mesh{}, 16).clusters.empty());
}

}  // namespace
}  // namespace farfield::gpu
