// CDLOD node data (cdlod.h) from a tile cache (tile_cache.h), for terrains never held whole: the cache is read tile by
// tile at full resolution, one tile in memory at a time.
//
// Nodes that lie inside one tile (levels 0..Lt, Lt the largest level whose node size divides the tile size) get
// their exact height range and error from the tile's heights. Coarser nodes take their height range from their
// children, and an upper bound of their error by the triangle inequality: E(N) <= max E(D) over N's level-Lt
// descendants D + max |h(v) - m_L(v)| over the level-Lt vertices v in N (h the grid, m_L N's level mesh). The second
// term is exact at those vertices alone because every level-Lt triangle lies inside one level-L triangle (all cells
// split along the same diagonal), so m_Lt - m_L is linear on each; it is evaluated on the cache's overview. The bound
// makes coarse ranges a little longer, never shorter: the drawn surface keeps the bound.
#pragma once

#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/tile_cache.h"

namespace farfield::terrain {

// The level Lt (see above) for a cache's tiles; -1 when no node fits in a tile.
int cdlodTileLevel(const TileLayout& layout, const CdlodOptions& options);

// Node data for the cache's grid. Throws farfield::Error (naming the cache) when a patch does not fit in a tile, or
// as TileCache's reads and CdlodTerrain do.
CdlodTerrain cdlodFromTileCache(const TileCache& cache, const CdlodOptions& options = {});

// The same, kept beside the cache in "<cache>.cdlod" so that a run does not read every tile again: read back when it
// was made for this cache (its size and time), grid and patch size and its checksum holds; otherwise (missing,
// stale, or damaged: a warning naming it) made from the cache and written (a temporary file renamed over it; a
// directory that cannot be written is a warning, not an error). `reused`: whether it was read back.
CdlodTerrain cdlodFromTileCacheKept(const TileCache& cache, const CdlodOptions& options = {}, bool* reused = nullptr);

}  // namespace farfield::terrain
