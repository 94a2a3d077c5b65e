// The GPU half of the CDLOD terrain (terrain/cdlod.h, Strugar 2009): one static grid patch of P x P quads drawn as
// instances of one draw, a node per instance; the vertex shader places each patch vertex on the grid, fetches its
// height from a texture of the whole grid (R32F, one texel per grid point), and morphs it towards the next coarser
// level by its distance from the eye and the morph range of the nodes of the next level it lies in (a buffer of the
// ranges of every node, uploaded when they change: when the image height, field of view or bound change). Per frame
// the CPU uploads the selected nodes (16 bytes each); nothing is read back and nothing waits.
//
// Conventions as for TerrainRenderer: reversed Z, counter-clockwise front faces seen from above, unlit, the original
// texture at uv = world_xy * uv_scale + uv_offset, object id 1 to attachment 1; no clear, no wait.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/cdlod_pages.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/image/image.h"

namespace farfield::gpu {

// One drawn node: the grid point of its corner and its level (a vertex every 2^level grid points); with pages, the
// page layer holding its tile (-1: the overview).
struct CdlodInstance {
  int32_t x0 = 0, y0 = 0;
  int32_t level = 0;
  int32_t layer = -1;
};

// A paged terrain's overview (every step-th grid point), always held, for the nodes that do not read a page.
struct CdlodOverview {
  int step = 1;
  int width = 0, height = 0;         // its points
  std::span<const float> heights;    // width x height, row-major, row 0 south
  const image::ColorImage* colour = nullptr;  // the original texture at its points (width x height texels)
};

// A sprite for LOD-sprite's frame on the GPU (terrain/lod_sprite.h, Chen et al. 1999): a keyframe's colour and depth
// and its camera, with equation 3's thickness (terrain/keyframe_visibility.h's VisibilityOptions). The textures must
// have the camera's size and outlive the draws that use them.
struct CdlodSprite {
  const Texture* colour = nullptr;
  const Texture* depth = nullptr;  // window depth, reversed Z (RenderTarget::depthTexture)
  Camera camera;
  float thickness_m = 1.0f, thickness_rel = 0.01f, footprint_pixels = 1.0f;
};

class CdlodRenderer {
 public:
  static constexpr int kMaxLevels = 25;
  // Needs a current context. heights: width x height grid points, row-major, row 0 the south edge (terrain/
  // heightfield.h); cell: metres between grid points along x and y; patch_cells: P. Throws farfield::Error for an
  // empty or mismatched grid, a grid larger than the driver's textures, or an empty texture.
  CdlodRenderer(int width, int height, std::span<const float> heights, Vec2 cell, int patch_cells,
                const image::ColorImage& texture, Vec2 uv_scale, Vec2 uv_offset);
  // A terrain paged in tiles: heights and colours from `pages` for the nodes whose instance names a layer, from the
  // overview for the others (whose vertices must lie on it). pages must outlive the renderer. Throws farfield::Error
  // for an overview that does not cover the grid at its step.
  CdlodRenderer(int width, int height, Vec2 cell, int patch_cells, const CdlodOverview& overview, CdlodPages& pages);
  ~CdlodRenderer();
  CdlodRenderer(const CdlodRenderer&) = delete;
  CdlodRenderer& operator=(const CdlodRenderer&) = delete;

  // The node grid of each level: its first index in the range buffer and its node counts along x and y (levels
  // 0..top, at most kMaxLevels). Throws farfield::Error for more levels or mismatched arrays.
  void setLevels(std::span<const int> offsets, std::span<const IVec2> counts);
  // The morph range (start, end) of every node, indexed as setLevels says (a node's range applies to the vertices of
  // the level below inside it; no morph where end is not above start), kept in one of kRangeSlots slots (one per
  // bound in use: ranges depend on it). Uploaded once; call again when they change.
  static constexpr int kRangeSlots = 4;
  void setRanges(std::span<const Vec2> ranges, int slot = 0);
  // Draws the nodes with a slot's ranges. Throws farfield::Error before setLevels, or for a slot never set.
  FrameStats draw(const Camera& camera, RenderTarget& target, std::span<const CdlodInstance> nodes, int slot = 0);

  // As TerrainRenderer::setDepthBias.
  void setDepthBias(float slope_factor, float units) {
    bias_factor_ = slope_factor;
    bias_units_ = units;
  }
  // Leaves out the ground inside a rectangle of world x, y (lo, hi), which someone else draws (a city's ground);
  // clearHole draws it all again. Applies to the draws that follow.
  void setHole(Vec2 lo, Vec2 hi);
  void clearHole() { hole_ = false; }
  // The draws that follow test each vertex against the sprite's keyframe as keyframe_visibility.h's vertexVisible
  // does (in the vertex shader), and take the sprite, projected through its camera, over the triangles whose three
  // vertices are visible there, the original texture elsewhere: the sprite frame in one draw, with nothing read back.
  // clearSprite draws the original texture alone again. A paged terrain's vertices take their normals from their
  // node's page or the overview. Throws farfield::Error for missing textures or textures of another size than the
  // camera's.
  void setSprite(const CdlodSprite& sprite);
  void clearSprite() { sprite_on_ = false; }
  // Waits until every command issued so far has completed (glFinish): the end of a timed terrain frame.
  void finish();
  int patchCells() const { return patch_cells_; }
  size_t trianglesPerNode() const { return size_t(2) * size_t(patch_cells_) * size_t(patch_cells_); }
  size_t gpuBytes() const;

 private:
  int width_, height_, patch_cells_;
  Vec2 cell_;
  uint32_t vao_ = 0, ibo_ = 0, nodes_ = 0;
  uint32_t ranges_[kRangeSlots] = {};
  size_t range_bytes_[kRangeSlots] = {};
  size_t node_capacity_ = 0;
  int top_ = -1;
  std::vector<int> level_offset_;
  std::vector<IVec2> level_count_;
  size_t index_count_ = 0;
  Texture heights_;
  Texture texture_;
  Program& program(bool hole, bool sprite);
  void makePatch();

  CdlodPages* pages_ = nullptr;
  int overview_step_ = 1;
  Program programs_[4];  // by hole + 2 * sprite, each made at its first use
  bool hole_ = false;
  bool sprite_on_ = false;
  CdlodSprite sprite_;
  Vec4 hole_rect_{0.0f};
  Vec2 uv_scale_, uv_offset_;
  float bias_factor_ = 0.0f, bias_units_ = 0.0f;
};

}  // namespace farfield::gpu
