#include "farfield/gpu/terrain_renderer.h"

#include <epoxy/gl.h>

#include <algorithm>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/terrain_patch.h"

namespace farfield::gpu {

TerrainRenderer::TerrainRenderer(std::span<const Vec3> positions, const image::ColorImage& texture, Vec2 uv_scale,
                                 Vec2 uv_offset)
    : uv_scale_(uv_scale), uv_offset_(uv_offset) {
  if (positions.empty()) throw Error("terrain renderer", "no grid vertices");
  if (texture.empty()) throw Error("terrain renderer", "empty texture");
  vertex_count_ = positions.size();
  texture_ = Texture::fromImage(texture, true);
  texture_.setClampToEdge();
  textured_ = Program::fromEmbedded("terrain.vert.glsl", "terrain.frag.glsl");
  sprite_ = Program::fromEmbedded("terrain.vert.glsl", "terrain.frag.glsl", "#define FF_SPRITE 1");

  vao_ = createPositionArray(positions, vbo_);
  glCreateBuffers(kSlots, ibo_);
}

TerrainRenderer::~TerrainRenderer() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  glDeleteBuffers(kSlots, ibo_);
}

void TerrainRenderer::setIndices(std::span<const uint32_t> indices, int slot) {
  FF_CHECK(slot >= 0 && slot < kSlots);
  refillIndices(ibo_[slot], indices, index_capacity_bytes_[slot]);
  index_count_[slot] = indices.size();
}

void TerrainRenderer::setState(const Camera& camera, RenderTarget& target, int slot) {
  camera.validate("camera");
  target.bindForOpaquePass();
  glVertexArrayElementBuffer(vao_, ibo_[slot]);
}

void TerrainRenderer::drawRange(size_t first, size_t count) {
  const bool bias = bias_factor_ != 0.0f || bias_units_ != 0.0f;
  if (bias) {
    // Reversed Z: farther is smaller.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-bias_factor_, -bias_units_);
  }
  glBindVertexArray(vao_);
  glDrawElements(GL_TRIANGLES, GLsizei(count * 3), GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(first * 3 * sizeof(uint32_t)));
  glBindVertexArray(0);
  if (bias) glDisable(GL_POLYGON_OFFSET_FILL);
}

void TerrainRenderer::finish() { glFinish(); }

FrameStats TerrainRenderer::drawTextured(const Camera& camera, RenderTarget& target, size_t first, size_t count,
                                         int slot) {
  FF_CHECK(slot >= 0 && slot < kSlots && (first + count) * 3 <= index_count_[slot]);
  Stopwatch wall;
  FrameStats stats;
  if (count == 0) return stats;
  setState(camera, target, slot);
  useTextured(textured_, camera, uv_scale_, uv_offset_);
  texture_.bind(0);
  drawRange(first, count);
  stats.triangles = count;
  stats.draw_calls = 1;
  stats.objects = 1;
  stats.wall_ms = wall.milliseconds();
  return stats;
}

FrameStats TerrainRenderer::drawSprite(const Camera& camera, RenderTarget& target, const Texture& sprite,
                                       const Mat4& sprite_view_proj, size_t first, size_t count, int slot) {
  FF_CHECK(slot >= 0 && slot < kSlots && (first + count) * 3 <= index_count_[slot]);
  Stopwatch wall;
  FrameStats stats;
  if (count == 0) return stats;
  FF_CHECK_MSG(sprite.handle() != target.colorTexture().handle(), "a sprite cannot be drawn into itself");
  setState(camera, target, slot);
  sprite_.use();
  sprite_.set("u_view_proj", camera.viewProjection());
  sprite_.set("u_sprite_view_proj", sprite_view_proj);
  sprite_.set("u_object_id", uint32_t(1));
  sprite.bind(0);
  drawRange(first, count);
  stats.triangles = count;
  stats.draw_calls = 1;
  stats.objects = 1;
  stats.wall_ms = wall.milliseconds();
  return stats;
}

size_t TerrainRenderer::gpuBytes() const {
  size_t bytes = vertex_count_ * sizeof(Vec3) + texture_.byteSize();
  for (size_t c : index_capacity_bytes_) bytes += c;
  return bytes;
}

}  // namespace farfield::gpu
