// One mesh of a scene arena (gpu/scene_arena.h) cut into clusters: the triangles split by facing where a class is
// large enough, each class cut by meshoptimizer (meshopt_buildMeshlets, meshopt_computeMeshletBounds), the vertices
// renumbered in the order the clusters use them. Pure data in and out; no GL, so meshes are cut on worker threads.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/scene_arena.h"
#include "farfield/scene/mesh.h"

namespace farfield::gpu {

struct ArenaMesh {
  std::vector<GpuVertex> vertices;     // the used vertices, renumbered
  std::vector<uint32_t> indices;       // into `vertices`, cluster after cluster
  std::vector<ArenaCluster> clusters;  // first_index into `indices`, base_vertex 0
  // The last lod_clusters clusters are the simplified level (ArenaOptions::lod_ratio), whose surface lies within
  // lod_error (mesh units, gpu/surface_deviation.h) of the full one; 0: no such level.
  uint32_t lod_clusters = 0;
  float lod_error = 0.0f;
};

// The simplified level of a mesh (meshopt_simplify towards lod_ratio of its triangles within lod_max_error of its
// extent) into `out` (indices into the mesh's vertices), and its error in mesh units: the two-sided deviation of the
// surfaces measured by gpu/surface_deviation.h (meshoptimizer's own estimate is 2-4x smaller than that). Empty, and
// 0, where the mesh is too small (lod_min_triangles) or the level would keep more than three quarters of its
// triangles.
float simplifiedMesh(const scene::Mesh& mesh, const ArenaOptions& options, std::vector<uint32_t>& out);

// Throws farfield::Error ("mesh", ...) for a mesh the GPU cannot draw (checkDrawableMesh). A mesh without triangles
// gives no cluster.
ArenaMesh clusterArenaMesh(const scene::Mesh& mesh, const ArenaOptions& options);

}  // namespace farfield::gpu
