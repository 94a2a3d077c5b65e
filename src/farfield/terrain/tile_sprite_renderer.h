// LOD-sprite terrain with a sprite per tile (issue 18): the rendering of the decisions of tile_sprites.h.
//
// Chen et al. 1999 (section 3) render the whole frame as one sprite and re-render it whole when equation 2's mean
// over the frame's quadrants trips, near ground dominating that mean. Here the terrain is cut into square tiles of
// tile_cells cells and each tile keeps its own sprite:
// - Each frame builds the low-resolution LOD mesh (as the paper), and sorts its triangles and quadrants into tiles
//   (a triangle by its centroid's cell, a quadrant by its central vertex).
// - A tile's error is equation 2 over its own quadrants, from its sprite's viewpoint to the eye; a tile with no
//   sprite, or whose error reaches epsilon, is re-rendered alone.
// - A tile's keyframe frames its region: the grid rectangle of the tile and of the tile's low-resolution triangles
//   in that frame (far triangles reach past a small tile), grown by region_margin, with the heights of the tiles it
//   touches. The whole tile, not only its part in view: a turning or advancing view brings the rest into view. The
//   camera sits at the eye and looks at the region's box, its frustum just enclosing the box, at the frame's pixel
//   density (so the sprite is as sharp as a whole-frame keyframe would be there). Since it frames the whole region,
//   the sprite stays valid whatever the view direction later: its validity depends on the eye's position only,
//   which is what equation 2 measures.
//   Only the high-resolution triangles that meet the region are drawn into it (the LOD built over the region's
//   blocks), and its z-buffer is kept.
// - Drawing: a low-resolution triangle whose three vertices lie inside its tile's region and are visible in the
//   tile's keyframe (equation 3, keyframe_visibility.h) is textured with the tile's sprite; the others with the
//   original texture, as the paper does with triangles the keyframe did not see. Occlusion between tiles is the
//   frame's own z-buffer's business: a sprite holds its region's terrain unoccluded by other tiles.
// - A tile whose region cannot be framed (it reaches behind or beside the eye by more than max_half_angle_deg,
//   e.g. the ground right under a low eye) takes the frame's own view instead, widened by view_margin on each side
//   as the whole-frame keyframe is; such a sprite is also refreshed when the view has turned by more than that
//   margin's angle (triangles out of its image would otherwise fall back to the original texture).
//
// Far tiles subtend small parallax angles, so their sprites last longer than near ones; a refresh re-renders one
// tile's high LOD, not the frame's. Sprites of tiles out of view for keep_frames frames are released.
//
// Never slower (path_choice.h), with a cost model (TileSpriteRenderOptions::cost): each frame predicts the high LOD's
// frame and the tile path's (the low mesh in a draw per sprite, plus the keyframes of the tiles due, each from its
// last keyframe's triangles and size) and draws the high LOD when the tiles do not pay: a frame whose sprites are all
// valid is drawn from them when that is cheaper than the high LOD; a frame with tiles due takes the tiles when their
// frame plus each keyframe's share per frame of its expected life costs less (a tile's expected life: the frames its
// last sprite served; a tile without one: the median of recent lifetimes). A frame drawn as the high LOD renders no
// keyframe; the tiles due stay due. The high LOD's size is the latest one drawn, scaled by the low mesh's size since
// (their ratio changes slowly along a path).
//
// Deciding costs time the high LOD does not pay (the low mesh, its sorting into tiles, equation 2 per tile: about 3 %
// of a high frame on the fractals where the tiles lose, docs/BENCHMARKS.md). So after a frame the choice gave to the
// high LOD, the next frames draw the high LOD without deciding, for a run that doubles with each further such
// choice in a row (1, 2, 4, ... up to max_carried_high frames) and ends at the first choice of the tiles: where the
// tiles lose for long, deciding costs 1 / max_carried_high of what it did, and where they win a frame that turns to
// them is found within that many frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/image/image.h"
#include "farfield/terrain/keyframe_visibility.h"
#include "farfield/terrain/path_choice.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_cost.h"

namespace farfield::terrain {

struct TileSpriteRenderOptions {
  int tile_cells = 128;      // tile side, grid cells
  double epsilon = 1.0;      // error threshold, pixels (equation 2, per tile)
  float high_error = 1.0f;   // LOD threshold of keyframes, pixels
  float low_error = 4.0f;    // LOD threshold of novel frames, pixels
  VisibilityOptions visibility;
  Vec4 sky_color{0.62f, 0.74f, 0.88f, 1.0f};
  float region_margin = 0.1f;      // share of the region's side added on each side (at least one cell)
  float max_half_angle_deg = 60.0f;  // widest half-angle of a tile keyframe's frustum
  int max_sprite_size = 2048;      // pixels per side; larger regions are drawn at a lower density
  float view_margin = 0.1f;        // share of the frame added on each side of a keyframe taking the frame's view
  int keep_frames = 30;            // frames a sprite is kept out of view
  // The per-frame choice between the high LOD and the tile path (see above); null = always the tile path.
  const TerrainCost* cost = nullptr;
  // Frames at most that draw the high LOD on an earlier frame's choice, without deciding (see above); 0: decide on
  // every frame.
  int max_carried_high = 8;
};

struct TileSpriteRenderFrame {
  TerrainPath path = TerrainPath::Sprite;  // High: the frame drew the high-resolution LOD (the per-frame choice)
  bool carried = false;  // path High on an earlier frame's choice: the tiles were not evaluated (nor counted)
  size_t tiles_due = 0;           // tiles in view whose sprite was missing or over epsilon
  double predicted_high_ms = 0.0;   // with a cost model: this frame's alternatives (path_choice.h's PathCosts)
  double predicted_sprite_ms = 0.0;
  double predicted_keyframe_ms = 0.0;
  uint64_t high_triangles = 0;    // path High: the high LOD drawn
  size_t tiles_in_view = 0;       // tiles holding a triangle of the frame's low mesh
  size_t tiles_refreshed = 0;     // keyframes rendered in this frame
  size_t tiles_view_framed = 0;   // keyframes of this frame that took the frame's view (the region could not be framed)
  uint64_t keyframe_triangles = 0;  // high-resolution triangles drawn into this frame's keyframes
  uint64_t keyframe_pixels = 0;     // their pixels
  uint64_t low_triangles = 0;
  uint64_t sprite_triangles = 0;  // low-resolution triangles textured with a sprite
  double max_tile_error_px = 0.0; // largest error of a sprite kept (below epsilon)
};

struct TileSpriteCounters {
  size_t frames = 0;
  size_t high_frames = 0;  // frames drawn as the high-resolution LOD (the per-frame choice)
  size_t carried_high_frames = 0;  // of high_frames: on an earlier frame's choice, without deciding
  size_t frames_with_keyframes = 0;
  size_t tile_keyframes = 0;
  size_t tile_frames_in_view = 0;
  size_t view_framed_keyframes = 0;
  uint64_t keyframe_triangles = 0;
  uint64_t low_triangles = 0;
  uint64_t sprite_triangles = 0;
  size_t peak_sprites = 0;
  uint64_t peak_sprite_bytes = 0;  // GPU bytes of the sprites held (colour, ids, depth) and their z-buffer copies
};

class TileSpriteRenderer {
 public:
  // Needs a current context. lod and renderer must outlive this object; frames are width x height. Throws
  // farfield::Error for bad options.
  TileSpriteRenderer(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer, int width, int height,
                     const TileSpriteRenderOptions& options);
  ~TileSpriteRenderer();

  // Draws one frame into target (bound here; not cleared: the caller clears it to the sky colour).
  gpu::FrameStats render(const Camera& camera, gpu::RenderTarget& target, TileSpriteRenderFrame* info = nullptr);
  // Forgets every sprite and counter (a new pass over a path); keeps the GPU allocations for reuse.
  void reset();

  IVec2 tileOf(int x, int y) const;
  int tilesX() const { return tiles_x_; }
  int tilesY() const { return tiles_y_; }
  const TileSpriteCounters& counters() const { return counters_; }
  // Released render targets kept for reuse (at most kMaxSpareTargets).
  size_t spareTargets() const { return spare_count_; }
  const TileSpriteRenderOptions& options() const { return options_; }
  // The sprite of a tile (tests): its camera, region and z-buffer; null when the tile has none.
  struct SpriteView {
    const Camera* camera;
    GridRect region;
    const image::DepthImage* depth;
  };
  bool sprite(IVec2 tile, SpriteView& out) const;

 private:
  struct Sprite;
  using TileKey = std::pair<int, int>;
  bool frame(const Camera& camera, GridRect region, Camera& out) const;
  // Whether this frame draws the high LOD instead of the tiles (options_.cost), with its predictions in `info`.
  bool chooseHigh(size_t due, TileSpriteRenderFrame& info) const;
  // Draws the high LOD as this frame (the choice's or a carried one), counts it and sets the next carried run.
  gpu::FrameStats drawHigh(const Camera& camera, gpu::RenderTarget& target, TileSpriteRenderFrame& info);
  void countFrame(const TileSpriteRenderFrame& info);
  void renderKeyframe(Sprite& sprite, TileSpriteRenderFrame& info, gpu::FrameStats& stats);
  gpu::RenderTarget takeTarget(int width, int height);
  void release(Sprite& sprite);
  uint64_t spriteBytes() const;

  const QuadtreeLod& lod_;
  gpu::TerrainRenderer& renderer_;
  int width_, height_;
  TileSpriteRenderOptions options_;
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<float> tile_min_z_, tile_max_z_;
  std::map<TileKey, std::unique_ptr<Sprite>> sprites_;
  static constexpr size_t kMaxSpareTargets = 16;
  std::map<TileKey, std::vector<gpu::RenderTarget>> spare_;  // released targets by size (never an empty list)
  size_t spare_count_ = 0;
  TileSpriteCounters counters_;
  uint64_t frame_ = 0;
  LodMesh low_, high_;
  // The per-frame choice: the latest high LOD drawn (its triangles and the low mesh's then) and recent lifetimes.
  uint64_t high_triangles_ = 0, low_at_high_ = 0;
  bool high_known_ = false;
  int high_streak_ = 0;  // frames in a row the choice (not a carried run) drew the high LOD
  int carry_high_ = 0;   // frames still to draw the high LOD without deciding
  std::deque<uint64_t> lifetimes_;
  std::vector<uint32_t> keyframe_indices_, frame_indices_;
};

}  // namespace farfield::terrain
