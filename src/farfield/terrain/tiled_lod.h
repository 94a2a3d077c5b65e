// The quadtree LOD of a large terrain built tile by tile (issue 18; Chen et al. 1999 section 2.2's LOD): per frame,
// every tile whose box meets the view frustum is acquired from the pager at the coarsest step that still gives the
// full grid's mesh (TileCache::stepFor), its LOD is built over its own blocks, and the pieces are joined with
// indices of the whole grid. The result is the mesh (and the quadrants) the whole grid's QuadtreeLod builds for the
// same camera and settings, up to the order of triangles and, with culling, extra triangles outside the frustum
// (a coarse tile bounds its finest triangles by a larger sphere); test_tiled_lod.cpp checks both.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/tile_pager.h"

namespace farfield::terrain {

struct TiledLodFrame {
  size_t tiles_in_view = 0;  // tiles whose box meets the frustum (acquired)
  size_t tiles_culled = 0;
  size_t full_resolution_tiles = 0;  // acquired at step 1
  int coarsest_step = 1;
};

// The tiles a frame of this camera draws: those whose box meets the view frustum (all without settings.cull), each
// at the coarsest step that still gives the whole grid's mesh (TileCache::stepFor). `culled`: the others' count.
std::vector<TileRequest> tilesInView(const TileCache& cache, const Camera& camera, const LodSettings& settings,
                                     size_t* culled = nullptr);

// Visits every tile whose box meets the view frustum (all tiles without settings.cull), acquired from the pager at
// the coarsest step that gives the full grid's mesh, with its LOD piece for the camera (indices of the whole grid).
// The tile and piece are valid during the call. Returns the frame's tile counts.
using TileLodVisitor = std::function<void(const TerrainTile& tile, const LodMesh& piece)>;
TiledLodFrame visitTiledLod(TilePager& pager, const Camera& camera, const LodSettings& settings,
                            const TileLodVisitor& visit);

// Builds the LOD mesh of the pager's terrain for a camera (indices of the whole grid; quadrants sorted by centre,
// each once). Loads and evicts tiles through the pager.
void buildTiledLod(TilePager& pager, const Camera& camera, const LodSettings& settings, LodMesh& out,
                   TiledLodFrame* frame = nullptr);

}  // namespace farfield::terrain
