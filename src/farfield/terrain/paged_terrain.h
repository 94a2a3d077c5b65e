// A large terrain drawn from paged tiles (issue 18: terrains held in tiles and paged under a memory budget, drawn
// by the quadtree LOD of Chen et al. 1999 section 2.2 built per tile). Per frame, every tile in view is acquired
// from the TilePager at the coarsest step that still gives the whole grid's mesh (tiled_lod.h), and its LOD piece
// is drawn from that tile's own GPU patch (gpu/terrain_patch.h): the tile's grid points at its step and a texture
// computed from its heights (terrain_texture.h, over the whole terrain's height range, so that at step 1 its
// texels are the whole texture's). Patches are kept under a GPU memory budget, the least recently used evicted
// first; a tile needed at a finer step than its patch gets a new one. With the pager's budget for heights and LOD
// data, neither memory holds the whole terrain.
#pragma once

#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/terrain_patch.h"
#include "farfield/terrain/tile_pager.h"
#include "farfield/terrain/tiled_lod.h"

namespace farfield::terrain {

struct PagedTerrainStats {
  size_t patches = 0;      // held now
  size_t loads = 0;        // patches made (a tile's vertices and texture uploaded)
  size_t evictions = 0;
  size_t gpu_bytes = 0;    // held now, counted as PagedTerrainRenderer::patchBytes
  size_t peak_gpu_bytes = 0;
  double load_seconds = 0.0;  // making patches: texture, positions, upload
};

struct PagedTerrainFrame {
  TiledLodFrame tiles;
  size_t patch_loads = 0;  // in this frame
  gpu::FrameStats draw;    // triangles and draw calls (one per tile in view with triangles)
};

class PagedTerrainRenderer {
 public:
  // Needs a current context; the pager must outlive the renderer. Throws farfield::Error when the budget cannot
  // hold the largest tile's patch at step 1 (a frame may need any tile at full resolution). prefetch_frames > 0:
  // after each frame, the tiles of the camera moved on by its last motion, half and all of that many frames ahead,
  // are handed to the pager's prefetch (TilePager::prefetch), so a steady flight rarely waits for a tile read.
  PagedTerrainRenderer(TilePager& pager, size_t gpu_budget_bytes, int prefetch_frames = 32);
  ~PagedTerrainRenderer();

  // Draws the terrain's LOD for the camera into the target (bound; not cleared; no wait).
  PagedTerrainFrame draw(const Camera& camera, const LodSettings& settings, gpu::RenderTarget& target);
  // Waits for the GPU (glFinish): the end of a timed frame.
  void finish() { renderer_.finish(); }

  const PagedTerrainStats& stats() const { return stats_; }
  size_t budget() const { return budget_; }
  // The bytes a patch of tile (tx, ty) at step holds at most: its vertices, its texture with mipmaps, and the index
  // store of its grid fully refined (with the store's headroom).
  size_t patchBytes(int tx, int ty, int step) const;

 private:
  struct Patch {
    int tx = 0, ty = 0, step = 1;
    IVec2 first{0};  // whole-grid point of the patch's vertex 0
    int width = 0;   // patch vertices per row
    size_t bytes = 0;
    std::unique_ptr<gpu::TerrainPatch> gpu;
  };
  Patch& acquire(const TerrainTile& tile);
  void evict();

  void prefetchAhead(const Camera& camera, const LodSettings& settings);

  TilePager& pager_;
  size_t budget_;
  int prefetch_frames_;
  std::optional<Camera> last_camera_;
  gpu::TerrainPatchRenderer renderer_;
  PagedTerrainStats stats_;
  std::list<Patch> lru_;  // most recently used first
  std::map<std::pair<int, int>, std::list<Patch>::iterator> where_;
  std::vector<uint32_t> local_;
};

}  // namespace farfield::terrain
