#include "farfield/gpu/gpu_mesh.h"

#include <epoxy/gl.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::gpu {

void checkDrawableMesh(const scene::Mesh& mesh) {
  const size_t n = mesh.positions.size();
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    throw Error("mesh", std::to_string(mesh.normals.size()) + " normals for " + std::to_string(n) + " positions");
  if (!mesh.uvs.empty() && mesh.uvs.size() != n)
    throw Error("mesh", std::to_string(mesh.uvs.size()) + " uvs for " + std::to_string(n) + " positions");
  if (mesh.indices.size() % 3 != 0)
    throw Error("mesh", std::to_string(mesh.indices.size()) + " indices, expected a multiple of 3");
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= n)
      throw Error("mesh", "index " + std::to_string(i) + " is " + std::to_string(mesh.indices[i]) + ", only " +
                              std::to_string(n) + " vertices");
}

GpuVertex gpuVertex(const scene::Mesh& mesh, size_t v) {
  const Vec3& p = mesh.positions[v];
  const Vec3 normal = mesh.normals.empty() ? Vec3(0.0f) : mesh.normals[v];
  const Vec2 uv = mesh.uvs.empty() ? Vec2(0.0f) : mesh.uvs[v];
  return {{p.x, p.y, p.z}, {normal.x, normal.y, normal.z}, {uv.x, uv.y}};
}

GpuMesh::GpuMesh(const scene::Mesh& mesh) {
  // Wrong-length attributes or out-of-range indices would make the GPU read outside the buffers: reject them here,
  // where the mesh is still in hand.
  checkDrawableMesh(mesh);
  const size_t n = mesh.positions.size();
  for (const Vec3& p : mesh.positions) bounds_.expand(p);
  index_count_ = uint32_t(mesh.indices.size());
  if (n == 0 || index_count_ == 0) return;

  std::vector<GpuVertex> vertices(n);
  for (size_t i = 0; i < n; ++i) vertices[i] = gpuVertex(mesh, i);
  const size_t vertex_bytes = vertices.size() * sizeof(GpuVertex);
  const size_t index_bytes = mesh.indices.size() * sizeof(uint32_t);
  glCreateBuffers(1, &vbo_);
  glNamedBufferStorage(vbo_, GLsizeiptr(vertex_bytes), vertices.data(), 0);
  glCreateBuffers(1, &ibo_);
  glNamedBufferStorage(ibo_, GLsizeiptr(index_bytes), mesh.indices.data(), 0);
  bytes_ = vertex_bytes + index_bytes;

  vao_ = makeVertexArray(vbo_, ibo_);
}

uint32_t makeVertexArray(uint32_t vertex_buffer, uint32_t index_buffer) {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  glVertexArrayVertexBuffer(vao, 0, vertex_buffer, 0, sizeof(GpuVertex));
  glVertexArrayElementBuffer(vao, index_buffer);
  const GLuint offsets[3] = {offsetof(GpuVertex, position), offsetof(GpuVertex, normal), offsetof(GpuVertex, uv)};
  const GLint sizes[3] = {3, 3, 2};
  for (GLuint attribute = 0; attribute < 3; ++attribute) {
    glEnableVertexArrayAttrib(vao, attribute);
    glVertexArrayAttribFormat(vao, attribute, sizes[attribute], GL_FLOAT, GL_FALSE, offsets[attribute]);
    glVertexArrayAttribBinding(vao, attribute, 0);
  }
  return vao;
}

GpuMesh::~GpuMesh() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (ibo_) glDeleteBuffers(1, &ibo_);
}

GpuMesh::GpuMesh(GpuMesh&& other) noexcept
    : vao_(std::exchange(other.vao_, 0)),
      vbo_(std::exchange(other.vbo_, 0)),
      ibo_(std::exchange(other.ibo_, 0)),
      index_count_(std::exchange(other.index_count_, 0)),
      bytes_(std::exchange(other.bytes_, 0)),
      bounds_(other.bounds_) {}

GpuMesh& GpuMesh::operator=(GpuMesh&& other) noexcept {
  if (this != &other) {
    if (vao_) glDeleteVertexArrays(1, &vao_);
    if (vbo_) glDeleteBuffers(1, &vbo_);
    if (ibo_) glDeleteBuffers(1, &ibo_);
    vao_ = std::exchange(other.vao_, 0);
    vbo_ = std::exchange(other.vbo_, 0);
    ibo_ = std::exchange(other.ibo_, 0);
    index_count_ = std::exchange(other.index_count_, 0);
    bytes_ = std::exchange(other.bytes_, 0);
    bounds_ = other.bounds_;
  }
  return *this;
}

void GpuMesh::draw() const {
  if (!vao_) return;
  glBindVertexArray(vao_);
  glDrawElements(GL_TRIANGLES, GLsizei(index_count_), GL_UNSIGNED_INT, nullptr);
}

}  // namespace farfield::gpu
