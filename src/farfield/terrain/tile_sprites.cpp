// Sprites per terrain tile: equation 2 of Chen et al. 1999 section 3.2 measured per tile (see tile_sprites.h).
#include "farfield/terrain/tile_sprites.h"

#include <algorithm>

#include "farfield/core/error.h"

namespace farfield::terrain {

TileSprites::TileSprites(const QuadtreeLod& lod, const TileSpriteOptions& options) : lod_(lod), options_(options) {
  if (options.tile_cells < 1) throw Error("tile sprites", "tile_cells must be at least 1");
  if (!(options.epsilon > 0.0)) throw Error("tile sprites", "epsilon must be positive");
}

IVec2 gridPointTile(int x, int y, int width, int height, int tile_cells) {
  x = std::clamp(x, 0, width - 2);
  y = std::clamp(y, 0, height - 2);
  return IVec2(x / tile_cells, y / tile_cells);
}

IVec2 centroidPoint(const uint32_t* triangle, uint32_t width) {
  int x = 0, y = 0;
  for (int k = 0; k < 3; ++k) {
    x += int(triangle[k] % width);
    y += int(triangle[k] / width);
  }
  return IVec2(x / 3, y / 3);
}

IVec2 TileSprites::tileOf(uint32_t v) const {
  const uint32_t w = uint32_t(lod_.width());
  return gridPointTile(int(v % w), int(v / w), lod_.width(), lod_.height(), options_.tile_cells);
}

TileSpriteFrame TileSprites::advance(const Camera& camera) {
  TileSpriteFrame out;
  const double beta = pixelAngle(camera);
  lod_.build(camera, LodSettings{options_.low_error, true, true}, low_);

  // Quadrants by tile.
  std::map<std::pair<int, int>, std::vector<LodQuadrant>> by_tile;
  for (const LodQuadrant& q : low_.quadrants) {
    const IVec2 t = tileOf(q.centre);
    by_tile[{t.x, t.y}].push_back(q);
  }
  out.tiles_in_view = by_tile.size();
  std::vector<std::pair<int, int>> refresh;
  for (const auto& [tile, quads] : by_tile) {
    auto it = sprites_.find(tile);
    if (it == sprites_.end()) {
      refresh.push_back(tile);
      continue;
    }
    const SpriteError e = spriteError(lod_, quads, it->second.key_eye, camera.eye);
    if (keyframeDue(e, beta, options_.epsilon)) refresh.push_back(tile);
    else out.max_tile_error_px = std::max(out.max_tile_error_px, e.pixels(beta));
  }
  out.tiles_refreshed = refresh.size();
  if (!refresh.empty()) {
    // A tile's keyframe draws the tile's whole high-resolution LOD from this eye (framing the tile's box).
    lod_.build(camera, LodSettings{options_.high_error, false, false}, high_);
    std::map<std::pair<int, int>, uint64_t> triangles;
    for (size_t t = 0; t < high_.indices.size(); t += 3) {
      const IVec2 c = centroidPoint(&high_.indices[t], uint32_t(lod_.width()));
      const IVec2 tile = gridPointTile(c.x, c.y, lod_.width(), lod_.height(), options_.tile_cells);
      ++triangles[{tile.x, tile.y}];
    }
    for (const auto& tile : refresh) {
      sprites_[tile] = TileSpriteState{camera.eye, frame_};
      out.refreshed_triangles += triangles[tile];
    }
  }

  // The whole-frame sprite (simulateKeyframes' decision) on the same frame.
  out.whole_keyframe = !whole_have_ ||
                       keyframeDue(spriteError(lod_, low_.quadrants, whole_eye_, camera.eye), beta, options_.epsilon);
  if (out.whole_keyframe) {
    whole_have_ = true;
    whole_eye_ = camera.eye;
    lod_.build(camera, LodSettings{options_.high_error, true, false}, high_);
    out.whole_triangles = high_.triangleCount();
  }
  ++frame_;
  return out;
}

}  // namespace farfield::terrain
