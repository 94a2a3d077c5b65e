#include "farfield/gpu/terrain_patch.h"

#include <epoxy/gl.h>

#include <algorithm>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::gpu {

uint32_t createPositionArray(std::span<const Vec3> positions, uint32_t& vbo) {
  glCreateBuffers(1, &vbo);
  glNamedBufferStorage(vbo, GLsizeiptr(positions.size_bytes()), positions.data(), 0);
  uint32_t vao = 0;
  glCreateVertexArrays(1, &vao);
  glVertexArrayVertexBuffer(vao, 0, vbo, 0, sizeof(Vec3));
  glEnableVertexArrayAttrib(vao, 0);
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 0, 0);
  return vao;
}

void refillIndices(uint32_t buffer, std::span<const uint32_t> indices, size_t& capacity_bytes) {
  FF_CHECK(indices.size() % 3 == 0);
  const size_t bytes = indices.size_bytes();
  if (bytes > capacity_bytes || bytes < capacity_bytes / 4) capacity_bytes = std::max<size_t>(bytes + bytes / 2, 64);
  glNamedBufferData(buffer, GLsizeiptr(capacity_bytes), nullptr, GL_STREAM_DRAW);
  if (bytes) glNamedBufferSubData(buffer, 0, GLsizeiptr(bytes), indices.data());
}

void useTextured(Program& program, const Camera& camera, Vec2 uv_scale, Vec2 uv_offset) {
  program.use();
  program.set("u_view_proj", camera.viewProjection());
  glUniform2fv(program.uniformLocation("u_uv_scale"), 1, glm::value_ptr(uv_scale));
  glUniform2fv(program.uniformLocation("u_uv_offset"), 1, glm::value_ptr(uv_offset));
  program.set("u_object_id", uint32_t(1));
}

TerrainPatch::TerrainPatch(std::span<const Vec3> positions, const image::ColorImage& texture, Vec2 uv_scale,
                           Vec2 uv_offset)
    : uv_scale_(uv_scale), uv_offset_(uv_offset) {
  if (positions.empty()) throw Error("terrain patch", "no vertices");
  if (texture.empty()) throw Error("terrain patch", "empty texture");
  vertex_count_ = positions.size();
  texture_ = Texture::fromImage(texture, true);
  texture_.setClampToEdge();
  vao_ = createPositionArray(positions, vbo_);
  glCreateBuffers(1, &ibo_);
  glVertexArrayElementBuffer(vao_, ibo_);
}

TerrainPatch::~TerrainPatch() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (ibo_) glDeleteBuffers(1, &ibo_);
}

void TerrainPatch::setIndices(std::span<const uint32_t> indices) {
  refillIndices(ibo_, indices, index_capacity_bytes_);
  index_count_ = indices.size();
}

size_t TerrainPatch::gpuBytes() const {
  return vertex_count_ * sizeof(Vec3) + texture_.byteSize() + index_capacity_bytes_;
}

TerrainPatchRenderer::TerrainPatchRenderer()
    : textured_(Program::fromEmbedded("terrain.vert.glsl", "terrain.frag.glsl")) {}

FrameStats TerrainPatchRenderer::draw(const Camera& camera, RenderTarget& target, const TerrainPatch& patch) {
  const Stopwatch wall;
  FrameStats stats;
  if (patch.index_count_ == 0) return stats;
  camera.validate("camera");
  target.bindForOpaquePass();
  useTextured(textured_, camera, patch.uv_scale_, patch.uv_offset_);
  patch.texture_.bind(0);
  glBindVertexArray(patch.vao_);
  glDrawElements(GL_TRIANGLES, GLsizei(patch.index_count_), GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  stats.triangles = patch.index_count_ / 3;
  stats.draw_calls = 1;
  stats.objects = 1;
  stats.wall_ms = wall.milliseconds();
  return stats;
}

void TerrainPatchRenderer::finish() { glFinish(); }

}  // namespace farfield::gpu
