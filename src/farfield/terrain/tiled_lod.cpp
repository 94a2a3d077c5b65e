// The quadtree LOD built tile by tile from paged tiles (issue 18; see tiled_lod.h).
#include "farfield/terrain/tiled_lod.h"

#include <algorithm>

namespace farfield::terrain {

std::vector<TileRequest> tilesInView(const TileCache& cache, const Camera& camera, const LodSettings& settings,
                                     size_t* culled) {
  std::vector<TileRequest> out;
  const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  const double lambda = QuadtreeLod::pixelsPerRadian(camera);
  size_t n = 0;
  for (int ty = 0; ty < cache.layout().tilesY(); ++ty)
    for (int tx = 0; tx < cache.layout().tilesX(); ++tx) {
      if (settings.cull && !frustum.intersects(cache.tileBox(tx, ty))) {
        ++n;
        continue;
      }
      out.push_back({tx, ty, cache.stepFor(tx, ty, camera.eye, lambda, settings.pixel_error)});
    }
  if (culled) *culled = n;
  return out;
}

TiledLodFrame visitTiledLod(TilePager& pager, const Camera& camera, const LodSettings& settings,
                            const TileLodVisitor& visit) {
  TiledLodFrame f;
  LodMesh piece;
  for (const TileRequest& r : tilesInView(pager.cache(), camera, settings, &f.tiles_culled)) {
    const TerrainTile& tile = pager.acquire(r.tx, r.ty, r.step);
    tile.lod->build(camera, settings, piece, &tile.window);
    visit(tile, piece);
    ++f.tiles_in_view;
    f.full_resolution_tiles += tile.grid.step == 1 ? 1 : 0;
    f.coarsest_step = std::max(f.coarsest_step, tile.grid.step);
  }
  return f;
}

void buildTiledLod(TilePager& pager, const Camera& camera, const LodSettings& settings, LodMesh& out,
                   TiledLodFrame* frame) {
  out.clear();
  const TiledLodFrame f = visitTiledLod(pager, camera, settings, [&](const TerrainTile&, const LodMesh& piece) {
    out.indices.insert(out.indices.end(), piece.indices.begin(), piece.indices.end());
    out.quadrants.insert(out.quadrants.end(), piece.quadrants.begin(), piece.quadrants.end());
  });
  // A quadrant on a tile's edge comes from both tiles (its two triangles lie on either side).
  std::sort(out.quadrants.begin(), out.quadrants.end(),
            [](const LodQuadrant& a, const LodQuadrant& b) { return a.centre < b.centre; });
  out.quadrants.erase(std::unique(out.quadrants.begin(), out.quadrants.end(),
                                  [](const LodQuadrant& a, const LodQuadrant& b) { return a.centre == b.centre; }),
                      out.quadrants.end());
  if (frame) *frame = f;
}

}  // namespace farfield::terrain
