// Sprites per terrain tile (issue 18, extending Chen et al. 1999 section 3, which renders the whole frame as one
// sprite): the terrain is cut into square tiles of tile_cells cells; each tile keeps its own sprite, taken from its
// own keyframe viewpoint, and equation 2's error is measured per tile, over the quadrants of the frame's
// low-resolution mesh whose central vertex lies in the tile. A tile whose error reaches the threshold (or that has no
// sprite yet) is re-rendered alone: only its high-resolution triangles. A far tile's quadrants subtend small
// parallax angles, so its sprite lasts longer than a near tile's; the whole-frame sprite is re-rendered whole as
// soon as the mean over all quadrants trips, near tiles dominating it.
//
// A tile's sprite is rendered with a projection that frames the tile's box from its keyframe viewpoint, so it covers
// the tile whatever the view direction later; its validity depends on the eye's position only (the error metric's
// v1 -> v2), not on where the camera looks.
//
// This is the decision and its cost, without rendering: per frame, which tiles are re-rendered and how many
// high-resolution triangles that takes, against the whole-frame sprite's keyframes on the same frames
// (simulateKeyframes in lod_sprite.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/sprite_error.h"

namespace farfield::terrain {

// The tile of grid point (x, y) of a width x height grid cut into tiles of tile_cells cells (coordinates clamped into
// the grid); the last row and column of points belong to the tiles before them.
IVec2 gridPointTile(int x, int y, int width, int height, int tile_cells);
// The grid point at the (truncated) centroid of a triangle of grid indices (a grid `width` points wide): a triangle
// belongs to that point's tile.
IVec2 centroidPoint(const uint32_t* triangle, uint32_t width);

struct TileSpriteOptions {
  int tile_cells = 256;     // tile side, grid cells
  double epsilon = 1.0;     // error threshold, pixels (equation 2, per tile)
  float low_error = 4.0f;   // LOD threshold of novel frames, pixels
  float high_error = 1.0f;  // LOD threshold of keyframes, pixels
};

struct TileSpriteState {
  Vec3 key_eye{0.0f};
  size_t since = 0;  // frame of its keyframe
};

struct TileSpriteFrame {
  size_t tiles_in_view = 0;         // tiles holding a quadrant of the frame's low mesh
  size_t tiles_refreshed = 0;       // re-rendered in this frame
  uint64_t refreshed_triangles = 0; // high-resolution triangles of the re-rendered tiles (whole tiles, no culling)
  double max_tile_error_px = 0.0;   // largest per-tile error of the sprites kept (below epsilon)
  bool whole_keyframe = false;      // the whole-frame sprite's keyframe (simulateKeyframes) on the same frames
  uint64_t whole_triangles = 0;     // high-resolution triangles of that keyframe (its view, culled), when due
};

class TileSprites {
 public:
  TileSprites(const QuadtreeLod& lod, const TileSpriteOptions& options);

  // Decides this frame (cameras in path order).
  TileSpriteFrame advance(const Camera& camera);

  IVec2 tileOf(uint32_t grid_index) const;
  const std::map<std::pair<int, int>, TileSpriteState>& sprites() const { return sprites_; }
  const LodMesh& lowMesh() const { return low_; }
  const TileSpriteOptions& options() const { return options_; }

 private:
  const QuadtreeLod& lod_;
  TileSpriteOptions options_;
  std::map<std::pair<int, int>, TileSpriteState> sprites_;
  bool whole_have_ = false;
  Vec3 whole_eye_{0.0f};
  size_t frame_ = 0;
  LodMesh low_, high_;
};

}  // namespace farfield::terrain
