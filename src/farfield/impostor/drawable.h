// Drawing a mesh impostor with the standard renderer: as a scene mesh + unlit material, or uploaded to the GPU.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/impostor/impostor_mesh.h"
#include "farfield/scene/material.h"
#include "farfield/scene/mesh.h"

namespace farfield::impostor {

// The impostor as scene data: the mesh as is, and an unlit, double-sided material whose texture is the impostor
// texture (double-sided because the triangles that span a depth step may turn their back to a moved viewer).
struct SceneImpostor {
  scene::Mesh mesh;
  scene::Material material;
};
SceneImpostor toSceneImpostor(const DepthMeshImpostor& impostor, const std::string& name = "impostor");

// Splits the mesh into one mesh per object id of its triangles (triangle_ids must have one id per triangle).
struct IdMesh {
  uint32_t id = 0;
  scene::Mesh mesh;
};
std::vector<IdMesh> splitByObjectId(const scene::Mesh& mesh, const std::vector<uint32_t>& triangle_ids);

struct GpuImpostorOptions {
  // One mesh per object id of the triangles (when the impostor has triangle ids), so that item buffers show which
  // object each impostor pixel stands for; otherwise one mesh.
  bool split_by_object_id = false;
  // Off by default: from its cell the impostor is seen at about its capture scale, where mip levels only blur (and
  // mix the transparent background into the silhouette's alpha). With uv interpolation instead of projective
  // texturing, the narrow triangles across depth steps would also pick blurred levels.
  bool mipmaps = false;
  // Texture coordinates projected from the creation camera (gpu::GpuMaterial::projective_texture) instead of the
  // mesh's interpolated uvs: exact in the creation view whatever the triangles' depth range.
  bool projective_texture = true;
  // Upload the impostor's per-texel ids (DepthMeshImpostor::ids) as the material's id texture, so item buffers show
  // the object of every impostor pixel (finer than split_by_object_id's per-triangle majority, and one draw call).
  bool id_texture = false;
};

// The impostor on the GPU: its texture (bilinear, clamped at the edges so the image border does not wrap) and its
// mesh(es). Needs a current context. Movable; draw items point into it.
class GpuImpostor {
 public:
  explicit GpuImpostor(const DepthMeshImpostor& impostor, const GpuImpostorOptions& options = {});

  // Appends its draw items; object_id is used for the unsplit mesh (and for triangles without id).
  void appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id = 0,
                       const Mat4& transform = Mat4(1.0f)) const;
  uint64_t triangleCount() const { return triangles_; }
  size_t gpuBytes() const;
  bool empty() const { return meshes_.empty(); }

 private:
  std::vector<gpu::GpuMesh> meshes_;
  std::vector<uint32_t> ids_;  // per mesh, 0 = use appendDrawItems' object_id
  std::unique_ptr<gpu::Texture> texture_;
  std::unique_ptr<gpu::Texture> id_texture_;
  std::unique_ptr<gpu::GpuMaterial> material_;
  uint64_t triangles_ = 0;
};

}  // namespace farfield::impostor
