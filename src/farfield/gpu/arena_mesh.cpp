#include "farfield/gpu/arena_mesh.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <limits>
#include <utility>

#include "farfield/gpu/mesh_clusters.h"
#include "farfield/gpu/surface_deviation.h"

namespace farfield::gpu {

namespace {

// Meshlets of one index list: its triangles split by facing class (small classes and triangles without area pooled
// last), each class cut by meshoptimizer. Appends to the three meshlet arrays.
void buildMeshlets(const scene::Mesh& mesh, const std::vector<uint32_t>& indices, const ArenaOptions& options,
                   std::vector<meshopt_Meshlet>& meshlets, std::vector<unsigned int>& meshlet_vertices,
                   std::vector<unsigned char>& meshlet_triangles) {
  const float* positions = &mesh.positions[0].x;
  const size_t vertex_count = mesh.positions.size();
  const size_t triangle_count = indices.size() / 3;
  std::array<std::vector<uint32_t>, kNoFacing + 2> by_class;
  for (size_t t = 0; t < triangle_count; ++t) {
    const uint32_t* tri = &indices[3 * t];
    const int c = options.min_facing_triangles > 0
                      ? facingClass(mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]])
                      : kNoFacing;
    by_class[size_t(c)].insert(by_class[size_t(c)].end(), tri, tri + 3);
  }
  for (int c = 0; c < kNoFacing; ++c)
    if (by_class[size_t(c)].size() / 3 < options.min_facing_triangles) {
      auto& pool = by_class[kNoFacing + 1];
      pool.insert(pool.end(), by_class[size_t(c)].begin(), by_class[size_t(c)].end());
      by_class[size_t(c)].clear();
    }
  by_class[kNoFacing + 1].insert(by_class[kNoFacing + 1].end(), by_class[kNoFacing].begin(),
                                 by_class[kNoFacing].end());
  by_class[kNoFacing].clear();
  size_t count = meshlets.size();
  for (const std::vector<uint32_t>& part : by_class) {
    if (part.empty()) continue;
    const size_t bound = meshopt_buildMeshletsBound(part.size(), options.max_vertices, options.max_triangles);
    meshlets.resize(count + bound);
    const size_t vertex_base = meshlet_vertices.size(), triangle_base = meshlet_triangles.size();
    meshlet_vertices.resize(vertex_base + bound * options.max_vertices);
    meshlet_triangles.resize(triangle_base + bound * options.max_triangles * 3);
    const size_t made = meshopt_buildMeshlets(&meshlets[count], &meshlet_vertices[vertex_base],
                                              &meshlet_triangles[triangle_base], part.data(), part.size(), positions,
                                              vertex_count, sizeof(Vec3), options.max_vertices,
                                              options.max_triangles, options.cone_weight);
    for (size_t k = count; k < count + made; ++k) {
      meshlets[k].vertex_offset += uint32_t(vertex_base);
      meshlets[k].triangle_offset += uint32_t(triangle_base);
    }
    count += made;
    meshlets.resize(count);
  }
}

}  // namespace

float simplifiedMesh(const scene::Mesh& mesh, const ArenaOptions& options, std::vector<uint32_t>& out) {
  out.clear();
  const size_t triangles = mesh.indices.size() / 3;
  if (!(options.lod_ratio > 0.0f) || triangles < options.lod_min_triangles || mesh.positions.empty()) return 0.0f;
  const float* positions = &mesh.positions[0].x;
  const size_t vertex_count = mesh.positions.size();
  const size_t target = std::max<size_t>(3, size_t(double(mesh.indices.size()) * options.lod_ratio) / 3 * 3);
  // Simplified over positions alone: flat-shaded meshes (a building's walls) repeat each corner once per face with its
  // own normal, and over those vertices every face is an island that nothing can collapse. The shadow index buffer
  // names each position by one vertex; each corner of a simplified triangle then takes, among the vertices at its
  // position, the one whose normal is closest to the triangle's own (its face's normal and texture coordinates).
  std::vector<uint32_t> shadow(mesh.indices.size());
  meshopt_generateShadowIndexBuffer(shadow.data(), mesh.indices.data(), mesh.indices.size(), positions, vertex_count,
                                    sizeof(Vec3), sizeof(Vec3));
  out.resize(mesh.indices.size());
  float relative = 0.0f;
  out.resize(meshopt_simplify(out.data(), shadow.data(), shadow.size(), positions, vertex_count, sizeof(Vec3), target,
                              options.lod_max_error, 0, &relative));
  // Where edge collapses cannot get far (facades of many small boxes: windows, ledges, each an island), the sloppy
  // simplifier merges vertices over a grid, across islands.
  if (out.size() > mesh.indices.size() * 3 / 4) {
    out.resize(mesh.indices.size());
    out.resize(meshopt_simplifySloppy(out.data(), shadow.data(), shadow.size(), positions, vertex_count, sizeof(Vec3),
                                      target, options.lod_max_error, &relative));
  }
  if (!mesh.normals.empty() && !out.empty()) {
    std::vector<std::vector<uint32_t>> at_position(vertex_count);  // shadow vertex -> the vertices at its position
    for (size_t i = 0; i < mesh.indices.size(); ++i) {
      std::vector<uint32_t>& same = at_position[shadow[i]];
      if (std::find(same.begin(), same.end(), mesh.indices[i]) == same.end()) same.push_back(mesh.indices[i]);
    }
    for (size_t t = 0; t + 2 < out.size(); t += 3) {
      const Vec3 n = glm::cross(mesh.positions[out[t + 1]] - mesh.positions[out[t]],
                                mesh.positions[out[t + 2]] - mesh.positions[out[t]]);
      for (size_t k = t; k < t + 3; ++k) {
        uint32_t best = out[k];
        float best_dot = -std::numeric_limits<float>::infinity();
        for (uint32_t v : at_position[out[k]]) {
          const float d = glm::dot(mesh.normals[v], n);
          if (d > best_dot) best_dot = d, best = v;
        }
        out[k] = best;
      }
    }
  }
  // Worth a level only when it removes a good share of the triangles.
  if (out.empty() || out.size() > mesh.indices.size() * 3 / 4) {
    out.clear();
    return 0.0f;
  }
  (void)relative;  // meshoptimizer's own estimate is smaller than the real deviation (2-4x on the tests' meshes)
  return float(surfaceDeviation(mesh.positions, mesh.indices, out));
}

ArenaMesh clusterArenaMesh(const scene::Mesh& mesh, const ArenaOptions& options) {
  ArenaMesh out;
  checkDrawableMesh(mesh);
  if (mesh.indices.empty() || mesh.positions.empty()) return out;
  std::vector<meshopt_Meshlet> meshlets;
  std::vector<unsigned int> meshlet_vertices;
  std::vector<unsigned char> meshlet_triangles;
  const float* positions = &mesh.positions[0].x;
  const size_t vertex_count = mesh.positions.size();
  buildMeshlets(mesh, mesh.indices, options, meshlets, meshlet_vertices, meshlet_triangles);
  const size_t full_count = meshlets.size();
  // The simplified level: its clusters after the full ones, over the same vertices (meshopt_simplify keeps a subset).
  std::vector<uint32_t> simplified;
  const float lod_error = simplifiedMesh(mesh, options, simplified);
  if (!simplified.empty()) {
    buildMeshlets(mesh, simplified, options, meshlets, meshlet_vertices, meshlet_triangles);
    out.lod_clusters = uint32_t(meshlets.size() - full_count);
    out.lod_error = lod_error;
  }
  const size_t count = meshlets.size();
  // The clusters' triangles as the mesh's own indices, cluster after cluster; then the vertices renumbered in the
  // order those first use them (meshopt_optimizeVertexFetchRemap), so that a cluster's vertices lie together.
  std::vector<uint32_t> local;  // the mesh's indices in cluster order
  std::vector<std::pair<uint32_t, uint32_t>> ranges;  // per cluster: first, count in `local`
  for (size_t c = 0; c < count; ++c) {
    const meshopt_Meshlet& ml = meshlets[c];
    ranges.emplace_back(uint32_t(local.size()), ml.triangle_count * 3);
    for (uint32_t t = 0; t < ml.triangle_count * 3; ++t)
      local.push_back(meshlet_vertices[ml.vertex_offset + meshlet_triangles[ml.triangle_offset + t]]);
  }
  std::vector<unsigned int> remap(vertex_count);
  const size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), local.data(), local.size(), vertex_count);
  out.vertices.resize(used);
  for (size_t v = 0; v < vertex_count; ++v) {
    if (remap[v] == ~0u) continue;
    out.vertices[remap[v]] = gpuVertex(mesh, v);
  }
  for (size_t c = 0; c < count; ++c) {
    const meshopt_Meshlet& ml = meshlets[c];
    const meshopt_Bounds b =
        meshopt_computeMeshletBounds(&meshlet_vertices[ml.vertex_offset], &meshlet_triangles[ml.triangle_offset],
                                     ml.triangle_count, positions, vertex_count, sizeof(Vec3));
    ArenaCluster cluster;
    cluster.center = Vec3(b.center[0], b.center[1], b.center[2]);
    cluster.radius = b.radius;
    cluster.cone_apex = Vec3(b.cone_apex[0], b.cone_apex[1], b.cone_apex[2]);
    cluster.cone_axis = Vec3(b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]);
    cluster.cone_cutoff = b.cone_cutoff;
    // The box of its vertices, and a sphere that holds them whatever meshoptimizer's rounding.
    for (uint32_t v = 0; v < ml.vertex_count; ++v) {
      const Vec3& p = mesh.positions[meshlet_vertices[ml.vertex_offset + v]];
      cluster.bounds.expand(p);
      cluster.radius = std::max(cluster.radius, glm::length(p - cluster.center));
    }
    cluster.first_index = uint32_t(out.indices.size());
    cluster.index_count = ranges[c].second;
    for (uint32_t i = 0; i < ranges[c].second; ++i) out.indices.push_back(remap[local[ranges[c].first + i]]);
    out.clusters.push_back(cluster);
  }
  return out;
}

}  // namespace farfield::gpu
