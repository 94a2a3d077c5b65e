// Mesh on the GPU: one vertex buffer (interleaved position, normal, uv), one index buffer, one vertex array.
#pragma once

#include <cstddef>
#include <cstdint>

#include "farfield/core/bounds.h"
#include "farfield/scene/mesh.h"

namespace farfield::gpu {

// One interleaved vertex as the GPU meshes hold it (GpuMesh, SceneArena): 32 bytes, so a vertex fetch touches one
// cache line at most. Missing normals and uvs are zeros (a zero normal makes the fragment shader use the face's).
struct GpuVertex {
  float position[3];
  float normal[3];
  float uv[2];
};
static_assert(sizeof(GpuVertex) == 32);

// Throws farfield::Error ("mesh", ...) for attributes of the wrong length or indices that are not whole triangles or
// refer past the positions: what would make the GPU read outside the buffers.
void checkDrawableMesh(const scene::Mesh& mesh);
// Vertex v of the mesh as a GpuVertex.
GpuVertex gpuVertex(const scene::Mesh& mesh, size_t v);
// A new vertex array reading GpuVertex records (attributes 0 position, 1 normal, 2 uv, binding 0) from
// vertex_buffer, with index_buffer as its element buffer. The caller owns (and deletes) it.
uint32_t makeVertexArray(uint32_t vertex_buffer, uint32_t index_buffer);

class GpuMesh {
 public:
  GpuMesh() = default;
  explicit GpuMesh(const scene::Mesh& mesh);
  ~GpuMesh();
  GpuMesh(GpuMesh&& other) noexcept;
  GpuMesh& operator=(GpuMesh&& other) noexcept;
  GpuMesh(const GpuMesh&) = delete;
  GpuMesh& operator=(const GpuMesh&) = delete;

  void draw() const;  // binds the vertex array and draws all triangles
  uint32_t vertexArray() const { return vao_; }  // 0 for an empty mesh (the renderer binds it itself)
  uint32_t indexCount() const { return index_count_; }
  uint64_t triangleCount() const { return index_count_ / 3; }
  const Box3& bounds() const { return bounds_; }
  size_t byteSize() const { return bytes_; }

 private:
  uint32_t vao_ = 0, vbo_ = 0, ibo_ = 0;
  uint32_t index_count_ = 0;
  size_t bytes_ = 0;
  Box3 bounds_;
};

}  // namespace farfield::gpu
