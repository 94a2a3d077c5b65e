// Spatial clusters of a mesh's triangles: the culling units of gpu::GpuScene (finer than an object, so a frustum
// test drops the parts of a large mesh that lie out of view, and a facing test the parts that turn their back to
// the eye). Pure data in and out; no GL.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/scene/mesh.h"

namespace farfield::gpu {

// Triangles of a cluster whose unit face normals n (from the winding: (v1 - v0) x (v2 - v0), counter-clockwise
// front) lie within `spread` of `normal` (|n - normal| <= spread) and whose vertices v all satisfy
// -dot(normal, v) <= offset. Every such triangle faces away from an eye e with
//   dot(normal, e) + offset + spread * max_v |e - v| < 0,
// since dot(n, e - v) <= dot(normal, e - v) + |n - normal| |e - v|.
struct FacingGroup {
  Vec3 normal{0.0f, 0.0f, 1.0f};
  float offset = 0.0f;
  float spread = 0.0f;
};

struct MeshCluster {
  Box3 bounds;               // of the cluster's vertices, in the mesh's own space
  uint32_t first_index = 0;  // into ClusteredIndices::indices
  uint32_t index_count = 0;  // a multiple of 3, > 0
  // The cluster's triangles split into facing groups: ClusteredIndices::facing[first_facing, + facing_count).
  // facing_count 0: the cluster is never known to face away (too many directions, or a triangle without area).
  uint32_t first_facing = 0;
  uint32_t facing_count = 0;
};

struct ClusteredIndices {
  // The mesh's triangles reordered so that each cluster is one contiguous range, over vertices renumbered so that
  // each cluster's vertices are one contiguous block too, in the order its triangles first use them: new vertex v is
  // the mesh's vertex vertex_order[v]. A vertex that several clusters use is repeated in each (vertex_order holds
  // every vertex at least once, unused ones last). Vertex fetches then stay local, which matters on llvmpipe: the
  // same triangles with their vertices left in place drew the whole city twice as slowly.
  std::vector<uint32_t> indices;
  std::vector<uint32_t> vertex_order;
  std::vector<MeshCluster> clusters;  // in index order; their ranges cover `indices` exactly, without overlap
  std::vector<FacingGroup> facing;
};

// Triangles split first in space: at the median of their centroids along the longest axis of the centroids'
// bounds, recursively, until a part holds at most max_triangles (>= 1). Then each part by facing: up, down, eight
// sectors of horizontal directions; a direction holding fewer than min_facing_triangles of the part joins a last,
// mixed cluster (a separate draw would cost more than its triangles). Clusters come in depth-first order of the
// spatial splits, so neighbours in index order are neighbours in space; inside a cluster triangles keep their
// original relative order. A mesh without triangles gives none. Throws farfield::Error for indices that are not
// whole triangles or refer past the positions.
ClusteredIndices clusterTriangles(const scene::Mesh& mesh, uint32_t max_triangles, uint32_t min_facing_triangles = 64);

// True when every triangle of the cluster certainly faces away from `eye` (mesh space), with a margin of 1e-3 of
// the distance so that rounding on the GPU cannot turn a nearly edge-on triangle around: back-face culling then
// draws none of its pixels.
// The mesh with its vertices in clustered.vertex_order and clustered.indices as its triangles (normals or uvs of the
// wrong length are kept as they are, for the caller's validation to reject).
scene::Mesh reorderedMesh(const scene::Mesh& mesh, const ClusteredIndices& clustered);

bool facesAway(const MeshCluster& cluster, std::span<const FacingGroup> facing, const Vec3& eye);

// The facing class of a triangle (counter-clockwise front): 0 up (normal z > 0.7), 1 down (z < -0.7), 2..9 eight
// sectors of horizontal directions, kNoFacing for a triangle without area.
inline constexpr int kNoFacing = 10;
int facingClass(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace farfield::gpu
