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
};

// Throws farfield::Error ("mesh", ...) for a mesh the GPU cannot draw (checkDrawableMesh). A mesh without triangles
// gives no cluster.
ArenaMesh clusterArenaMesh(const scene::Mesh& mesh, const ArenaOptions& options);

}  // namespace farfield::gpu
