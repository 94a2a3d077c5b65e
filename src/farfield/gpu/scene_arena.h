// A scene's geometry arena (DESIGN.md, "The GPU-driven frame"): every static mesh in one vertex and one index buffer,
// cut into clusters of at most 124 triangles by meshoptimizer (meshopt_buildMeshlets) with their bounds and normal
// cones (meshopt_computeMeshletBounds); object transforms, materials and the cluster instances (object part x mesh
// cluster) in GPU buffers; colour textures in arrays, one per size, so that a pass draws every material of a group
// with one multi-draw. gpu::GpuCuller culls and draws it without the CPU touching a cluster.
//
// Why meshoptimizer's clusters and not GpuScene's (gpu/mesh_clusters.h): those are culling units of 2,048 triangles
// sized for one draw call each on the CPU path; here a cluster costs no draw call, so clusters as small as the GPU
// culls well are best, and meshopt_buildMeshlets makes them compact in space and in normal direction (cone_weight)
// with bounds and a cone in the form the culling shader tests. docs/DESIGN-NOTES.md compares the two.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/scene/scene.h"

namespace farfield::gpu {

struct ArenaOptions {
  uint32_t max_vertices = 64;    // per cluster (meshoptimizer: at most 255)
  uint32_t max_triangles = 124;  // per cluster (at most 512, a multiple of 4)
  float cone_weight = 0.5f;      // meshoptimizer's balance of compact clusters against narrow normal cones
  // Before meshoptimizer cuts a mesh, its triangles are split by facing (gpu/mesh_clusters.h, facingClass: up, down,
  // eight horizontal sectors) where a class holds at least this many; smaller classes stay together. A building of
  // a few dozen triangles is then one cluster (a cluster per wall would cost more draws than its back walls save),
  // and a detailed facade's clusters have cones narrow enough to be culled from behind. 0: no split.
  uint32_t min_facing_triangles = 32;
  // A simplified level per mesh (gpu/arena_mesh.h, simplifiedMesh), which the culler draws for a part whose error
  // projects under GpuCuller::setLodErrorPx: meshopt_simplify towards this share of the triangles (0: no level; the
  // governed modes ask for 0.25: measuring each level's deviation about doubles the arena's build time) ...
  float lod_ratio = 0.0f;
  float lod_max_error = 0.02f;        // ... within this share of the mesh's extent ...
  uint32_t lod_min_triangles = 256;   // ... for meshes of at least this many triangles.
};

// One cluster of a mesh, in the mesh's own space.
struct ArenaCluster {
  Vec3 center{0.0f};  // bounding sphere
  float radius = 0.0f;
  Box3 bounds;        // of its vertices
  // Normal cone (meshopt_Bounds): every triangle faces away from an eye e with
  // dot(normalize(cone_apex - e), cone_axis) >= cone_cutoff. cone_cutoff >= 1: never tested.
  Vec3 cone_apex{0.0f};
  Vec3 cone_axis{0.0f, 0.0f, 1.0f};
  float cone_cutoff = 1.0f;
  uint32_t first_index = 0;  // into the arena's index buffer
  uint32_t index_count = 0;
  uint32_t base_vertex = 0;  // its mesh's first vertex in the arena's vertex buffer
};

// A cluster drawn for an object part.
struct ArenaInstance {
  uint32_t cluster = 0;
  uint32_t object = 0;    // index into Scene::objects (id - 1)
  uint32_t material = 0;  // index into Scene::materials
  uint32_t group = 0;     // material group
  bool cone_test = false;  // single-sided material, a transform that keeps angles, a cone that can reject
};

// The instances of one object part (its mesh's clusters, contiguous among the instances): culled whole first.
struct ArenaPart {
  uint32_t object = 0;  // index into Scene::objects
  uint32_t material = 0;  // index into Scene::materials
  uint32_t first_instance = 0;
  uint32_t instance_count = 0;
  Box3 bounds;  // its mesh's, in the object's own space
  // Its simplified level: instances [first_instance + instance_count, + lod_instance_count), within lod_error (the
  // mesh's units) of the full surface; 0 instances: none.
  uint32_t lod_instance_count = 0;
  float lod_error = 0.0f;
};

// Bounds of how much an object's transform stretches lengths: at least `first`, at most `second` (the scale of a
// similarity; otherwise 1 / |L^-1|_F and |L|_F of its linear part L). {0, 0} for a singular transform.
std::pair<double, double> objectStretch(const Mat4& model);

// The error in pixels of drawing a part's simplified level for a camera: lod_error stretched by the most the object's
// transform stretches, projected at the distance from the eye to the part's box (in the object's space, times the
// least the transform stretches; pixels_per_unit = target height / (2 tan(fov_y / 2))). An upper bound of how far any
// point of the level is drawn from the full level. Infinite for a part without a level, an eye inside its box or a
// transform that is not affine or is singular. The culling shader makes the same test (gpu_cull.comp.glsl).
double partLodErrorPx(const ArenaPart& part, const Mat4& model, const Vec3& eye, double pixels_per_unit);

// Instances that one multi-draw draws: same texture array, same face culling, same winding.
struct MaterialGroup {
  int texture_array = -1;   // -1: untextured
  bool double_sided = false;
  bool mirrored = false;    // object transforms that flip handedness (drawn with clockwise fronts)
  uint32_t first_instance = 0;  // instances [first_instance, first_instance + instance_count) are this group's
  uint32_t instance_count = 0;
  uint64_t triangles = 0;
};

// A GL buffer of `bytes` (at least 16, so that an empty one can still be bound) with `data` (bytes of it, or none)
// and the glNamedBufferStorage flags; for the arena's and the culler's storage buffers. Returns its name.
uint32_t createStorageBuffer(size_t bytes, const void* data, uint32_t flags);

// The eye test of a cluster's normal cone, as the culling shader makes it (both in the mesh's own space): true when
// every triangle of the cluster faces away from the eye, with a margin for the GPU's rounding of nearly edge-on ones.
bool coneRejects(const ArenaCluster& cluster, const Vec3& eye);

class SceneArena {
 public:
  // Uploads the scene's meshes, materials, textures and objects. Needs a current context; keeps a pointer to the
  // scene, which must outlive it. Throws farfield::Error for a mesh or a part that cannot be drawn (naming it).
  explicit SceneArena(const scene::Scene& scene, const ArenaOptions& options = {});
  ~SceneArena();
  SceneArena(const SceneArena&) = delete;
  SceneArena& operator=(const SceneArena&) = delete;

  const scene::Scene& scene() const { return *scene_; }
  std::span<const ArenaCluster> clusters() const { return clusters_; }
  // Clusters of scene mesh m: clusters()[meshClusters(m).first, + second); its simplified level's follow them
  // (meshLodClusters(m): count, error), none where the count is 0.
  std::pair<uint32_t, uint32_t> meshClusters(uint32_t mesh) const { return mesh_clusters_.at(mesh); }
  std::pair<uint32_t, float> meshLodClusters(uint32_t mesh) const { return mesh_lod_.at(mesh); }
  std::span<const ArenaInstance> instances() const { return instances_; }
  std::span<const ArenaPart> parts() const { return parts_; }
  // The parts of object index o (into Scene::objects): parts()[objectParts(o).first, .second), consecutive.
  std::pair<uint32_t, uint32_t> objectParts(size_t o) const { return {object_parts_.at(o), object_parts_.at(o + 1)}; }
  std::span<const MaterialGroup> groups() const { return groups_; }
  uint64_t triangleCount() const { return triangles_; }       // of the full levels
  uint64_t lodTriangleCount() const { return lod_triangles_; }  // of the simplified levels
  size_t gpuBytes() const { return gpu_bytes_; }

  // Re-uploads the transforms of these objects (ids, 1-based) after the scene's objects changed them. A change of
  // handedness or of whether the transform keeps angles needs a new arena (FF_CHECK).
  void updateTransforms(std::span<const uint32_t> ids);

  // The index buffer read back from the GPU (a wait: for tests and tools, never in a frame). Cluster c's triangles are
  // indices [first_index, + index_count) plus its base_vertex, numbered as the mesh's vertices after the arena's
  // reordering; readVertexPositions() gives their positions.
  std::vector<uint32_t> readIndices() const;
  std::vector<Vec3> readVertexPositions() const;

  // GL names for gpu::GpuCuller.
  struct Buffers {
    // Positions, normals, uvs (locations 0-2), and per instance (a draw's baseInstance: its part) the part's row:
    // the object's transform (3-6), normal matrix (7-9), the material's colour (10), object id, unlit, layer (11).
    uint32_t vertex_array = 0;
    uint32_t clusters = 0, instances = 0, objects = 0, materials = 0, parts = 0;
  };
  const Buffers& buffers() const { return buffers_; }
  // The GL texture of texture array i (MaterialGroup::texture_array).
  uint32_t textureArray(int i) const { return texture_arrays_.at(size_t(i)); }

 private:
  void uploadObjects(uint32_t first, uint32_t count);
  void uploadPartRows(uint32_t first, uint32_t count);

  const scene::Scene* scene_;
  std::vector<ArenaCluster> clusters_;
  std::vector<std::pair<uint32_t, uint32_t>> mesh_clusters_;
  std::vector<std::pair<uint32_t, float>> mesh_lod_;
  std::vector<ArenaInstance> instances_;
  std::vector<ArenaPart> parts_;
  std::vector<MaterialGroup> groups_;
  std::vector<uint8_t> object_kind_;  // per object: bit 0 mirrored, bit 1 keeps angles (similarity)
  uint64_t triangles_ = 0, lod_triangles_ = 0;
  size_t gpu_bytes_ = 0;
  Buffers buffers_;
  uint32_t vertex_buffer_ = 0, index_buffer_ = 0, part_rows_ = 0;
  std::vector<uint32_t> object_parts_;    // the parts of object o: [object_parts_[o], object_parts_[o + 1])
  std::vector<uint32_t> material_layer_;  // per material: its texture's layer in its array (0 untextured)
  size_t vertex_count_ = 0, index_count_ = 0;
  std::vector<uint32_t> texture_arrays_;
};

}  // namespace farfield::gpu
