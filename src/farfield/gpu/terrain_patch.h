// A piece of terrain drawn on its own: a paged tile (terrain/paged_terrain.h) with its grid's positions, its own
// texture and an index list replaced every frame, so that the GPU holds only the tiles in use. Drawn unlit with
// the terrain's textured program, under TerrainRenderer's conventions (reversed Z, back faces culled, object id 1
// to attachment 1).
#pragma once

#include <cstdint>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/image/image.h"

namespace farfield::gpu {

// Building blocks of the terrain's draws, shared with TerrainRenderer (needs a current context):
// a vertex array whose attribute 0 reads a new buffer of positions (returned in vbo);
uint32_t createPositionArray(std::span<const Vec3> positions, uint32_t& vbo);
// an index store refilled by orphaning (draws issued before keep the old list), sized with headroom so that its
// allocation stays the same from frame to frame; capacity_bytes is the store's size, kept between calls;
void refillIndices(uint32_t buffer, std::span<const uint32_t> indices, size_t& capacity_bytes);
// the textured program's state for a draw: the camera, uv = world_xy * uv_scale + uv_offset, object id 1.
void useTextured(Program& program, const Camera& camera, Vec2 uv_scale, Vec2 uv_offset);

class TerrainPatch {
 public:
  // Needs a current context. positions: the patch's vertices (indices refer to them); texture sampled at
  // uv = world_xy * uv_scale + uv_offset (mipmapped, clamped at the edges). Throws farfield::Error for no vertices
  // or an empty texture.
  TerrainPatch(std::span<const Vec3> positions, const image::ColorImage& texture, Vec2 uv_scale, Vec2 uv_offset);
  ~TerrainPatch();
  TerrainPatch(const TerrainPatch&) = delete;
  TerrainPatch& operator=(const TerrainPatch&) = delete;

  // Replaces the index list (three vertex indices per triangle, counter-clockwise seen from above, each below the
  // vertex count). Draws issued before keep the old list (the store is orphaned).
  void setIndices(std::span<const uint32_t> indices);
  size_t triangleCount() const { return index_count_ / 3; }
  size_t vertexCount() const { return vertex_count_; }
  // Vertices, texture with its mipmaps, and the index store.
  size_t gpuBytes() const;

 private:
  friend class TerrainPatchRenderer;
  uint32_t vao_ = 0, vbo_ = 0, ibo_ = 0;
  size_t vertex_count_ = 0, index_count_ = 0, index_capacity_bytes_ = 0;
  Texture texture_;
  Vec2 uv_scale_{1.0f}, uv_offset_{0.0f};
};

class TerrainPatchRenderer {
 public:
  TerrainPatchRenderer();  // needs a current context
  // Draws the patch's triangles with its texture. Binds the target; does not clear it and does not wait.
  FrameStats draw(const Camera& camera, RenderTarget& target, const TerrainPatch& patch);
  // Waits until every command issued so far has completed (glFinish): the end of a timed frame.
  void finish();

 private:
  Program textured_;
};

}  // namespace farfield::gpu
