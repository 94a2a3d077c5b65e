// Terrain drawing for the terrain module (LOD meshes and LOD-sprite, Chen et al. 1999 section 3): a heightfield
// grid whose positions are uploaded once and whose triangles change every frame (view-dependent LOD), drawn unlit
// with the terrain's original texture, or with a sprite (an earlier rendered frame) mapped by projective texturing
// through the sprite camera's view-projection.
//
// Conventions as for Renderer: reversed Z (depth test GREATER), back faces culled (counter-clockwise front faces),
// colour to attachment 0, object id (1 for the terrain) to attachment 1. Draw calls do not clear and do not wait.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/image/image.h"

namespace farfield::gpu {

// Adds one draw's counts to a frame's (objects: the larger, the terrain being one object).
inline void addDraw(FrameStats& sum, const FrameStats& draw) {
  sum.triangles += draw.triangles;
  sum.draw_calls += draw.draw_calls;
  sum.objects = std::max(sum.objects, draw.objects);
}

class TerrainRenderer {
 public:
  // Needs a current context. positions: every grid vertex (indices refer to them); texture: the original texture,
  // sampled at uv = world_xy * uv_scale + uv_offset (mipmapped, clamped at the edges). Throws farfield::Error for
  // an empty grid or texture.
  TerrainRenderer(std::span<const Vec3> positions, const image::ColorImage& texture, Vec2 uv_scale, Vec2 uv_offset);
  ~TerrainRenderer();
  TerrainRenderer(const TerrainRenderer&) = delete;
  TerrainRenderer& operator=(const TerrainRenderer&) = delete;

  // Index lists live in kSlots slots (e.g. this frame's mesh in slot 0 and a keyframe drawn over several frames in
  // slot 1). setIndices replaces a slot's list (three vertex indices per triangle, counter-clockwise seen from
  // above; indices below the vertex count, which the terrain module guarantees). Draws issued before keep the old
  // list: the buffer store is orphaned, not overwritten.
  static constexpr int kSlots = 2;
  void setIndices(std::span<const uint32_t> indices, int slot = 0);
  size_t triangleCount(int slot = 0) const { return index_count_[slot] / 3; }

  // Draws triangles [first, first + count) of a slot's list with the original texture.
  FrameStats drawTextured(const Camera& camera, RenderTarget& target, size_t first, size_t count, int slot = 0);
  // ... with `sprite` (e.g. another RenderTarget's colour texture) projected through sprite_view_proj.
  FrameStats drawSprite(const Camera& camera, RenderTarget& target, const Texture& sprite,
                        const Mat4& sprite_view_proj, size_t first, size_t count, int slot = 0);

  // Pushes the terrain's depth away from the eye by slope_factor times each triangle's depth change per pixel plus
  // `units` steps of the depth buffer (glPolygonOffset), so that ground drawn by someone else on the same surface
  // (a city's streets) wins the depth test; 0, 0 (the default) = no bias. Applies to the draws that follow.
  void setDepthBias(float slope_factor, float units) {
    bias_factor_ = slope_factor;
    bias_units_ = units;
  }

  // Waits until every command issued so far has completed (glFinish): the end of a timed terrain frame.
  void finish();

  size_t vertexCount() const { return vertex_count_; }
  size_t gpuBytes() const;

 private:
  void setState(const Camera& camera, RenderTarget& target, int slot);
  void drawRange(size_t first, size_t count);

  uint32_t vao_ = 0, vbo_ = 0;
  uint32_t ibo_[kSlots] = {};
  size_t vertex_count_ = 0;
  size_t index_count_[kSlots] = {};
  size_t index_capacity_bytes_[kSlots] = {};
  Texture texture_;
  Program textured_;
  Program sprite_;
  Vec2 uv_scale_{1.0f}, uv_offset_{0.0f};
  float bias_factor_ = 0.0f, bias_units_ = 0.0f;
};

}  // namespace farfield::gpu
