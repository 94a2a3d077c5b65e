// Mesh on the GPU: one vertex buffer (interleaved position, normal, uv), one index buffer, one vertex array.
#pragma once

#include <cstdint>

#include "farfield/core/bounds.h"
#include "farfield/scene/mesh.h"

namespace farfield::gpu {

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
