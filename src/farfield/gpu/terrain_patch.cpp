#include "farfield/gpu/terrain_patch.h"

#include <epoxy/gl.h>

#include <algorithm>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::gpu {

TerrainPatch::TerrainPatch(std::span<const Vec3> positions, const image::ColorImage& texture, Vec2 uv_scale,
                           Vec2 uv_offset)
    : uv_scale_(uv_scale), uv_offset_(uv_offset) {
  if (positions.empty()) throw Error("terrain patch", "no vertices");
  if (texture.empty()) throw Error("terrain patch", "empty texture");
  vertex_count_ = positions.size();
  texture_ = Texture::fromImage(texture, true);
  texture_.setClampToEdge();
  glCreateBuffers(1, &vbo_);
  glNamedBufferStorage(vbo_, GLsizeiptr(positions.size_bytes()), positions.data(), 0);
  glCreateBuffers(1, &ibo_);
  glCreateVertexArrays(1, &vao_);
  glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, sizeof(Vec3));
  glEnableVertexArrayAttrib(vao_, 0);
  glVertexArrayAttribFormat(vao_, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao_, 0, 0);
  glVertexArrayElementBuffer(vao_, ibo_);
}

TerrainPatch::~TerrainPatch() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (ibo_) glDeleteBuffers(1, &ibo_);
}

void TerrainPatch::setIndices(std::span<const uint32_t> indices) {
  FF_CHECK(indices.size() % 3 == 0);
  index_count_ = indices.size();
  const size_t bytes = indices.size_bytes();
  // Orphan-and-refill with headroom, as TerrainRenderer::setIndices.
  if (bytes > index_capacity_bytes_ || bytes < index_capacity_bytes_ / 4)
    index_capacity_bytes_ = std::max<size_t>(bytes + bytes / 2, 64);
  glNamedBufferData(ibo_, GLsizeiptr(index_capacity_bytes_), nullptr, GL_STREAM_DRAW);
  if (bytes) glNamedBufferSubData(ibo_, 0, GLsizeiptr(bytes), indices.data());
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
  textured_.use();
  textured_.set("u_view_proj", camera.viewProjection());
  glUniform2fv(textured_.uniformLocation("u_uv_scale"), 1, glm::value_ptr(patch.uv_scale_));
  glUniform2fv(textured_.uniformLocation("u_uv_offset"), 1, glm::value_ptr(patch.uv_offset_));
  textured_.set("u_object_id", uint32_t(1));
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
