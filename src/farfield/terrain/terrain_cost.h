// The frame-time cost model of LOD-sprite terrain (Chen et al. 1999 section 3, Figure 3's two kinds of frame),
// fitted on the running machine: what path_choice.h needs to predict a high-resolution frame, a sprite frame and a
// keyframe before drawing them.
//
// A terrain frame is gpu::CostModel's linear workload (gpu/cost_model.h) measured the way the terrain draws it: the
// view-dependent LOD mesh built on the CPU, its indices uploaded, drawn, and glFinish; so ms_per_mtriangle holds the
// LOD build as well as the rasterisation. A keyframe adds reading its z-buffer back (keyframe_visibility.h), a term
// of its own, linear in the keyframe's pixels.
#pragma once

#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/camera.h"
#include "farfield/gpu/cost_model.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {

struct TerrainCost {
  gpu::CostModel frame;                   // LOD build + draw + finish of a frame
  double readback_ms_per_mpixel = 0.0;    // z-buffer read back, per million keyframe pixels (>= 0)
  double safety_factor = 1.0;             // predictions are multiplied by it (>= 1)
  // With TerrainCostOptions::gpu_high: frames of the high LOD drawn by the CDLOD terrain on the GPU (gpu_lod.h):
  // selection, node upload, one instanced draw, finish. Its triangles cost differently from the CPU LOD's (no mesh
  // built, every vertex shaded by the patch), so they have a model of their own.
  std::optional<gpu::CostModel> gpu_high;
  // With gpu_high as well: CDLOD frames drawn as LOD-sprite's sprite frame on the GPU (gpu::CdlodSprite: each vertex
  // tested against a keyframe's depth, the sprite or the original texture per triangle), in one draw.
  std::optional<gpu::CostModel> gpu_sprite;

  // A frame of `triangles` in `draw_calls` calls into a width x height target, ms.
  double frameMs(double triangles, double draw_calls, int width, int height) const;
  // A CDLOD frame of `triangles` (its patches') into a width x height target, ms; needs gpu_high.
  double gpuHighMs(double triangles, int width, int height) const;
  // A CDLOD sprite frame of `triangles` into a width x height target, ms; needs gpu_sprite.
  double gpuSpriteMs(double triangles, int width, int height) const;
  double readbackMs(int width, int height) const;
  // {"frame": CostModel::toJson(), "readback_ms_per_mpixel", "safety_factor"}, "gpu_high" and "gpu_sprite" when fitted.
  nlohmann::json toJson() const;
};

struct TerrainCostOptions {
  std::vector<Camera> views;  // frames to time from (a few of the path's cameras); required, each a usable camera
  int keyframe_width = 0;     // the keyframe target (frame plus guard band); 0 = the views' size
  int keyframe_height = 0;
  std::vector<float> pixel_errors{1.0f, 2.0f, 4.0f, 16.0f};  // LOD thresholds timed (the triangle term's spread)
  // Sprite frames timed per threshold: half the mesh drawn with a sprite in this many calls (0: the whole mesh with the
  // original texture in one call), the rest in one call. The draw-call term's spread: tile modes draw a call per
  // tile with a sprite, and with only 1 and 2 calls timed its fit swung from 0 to 0.7 ms a call between runs.
  std::vector<int> sprite_calls{0, 1, 15};
  int repeats = 3;            // timed renders per workload (median kept; one untimed warm-up per view and size)
  // Also time its frames at each threshold and size (TerrainCost::gpu_high), and its sprite frames with a keyframe of
  // the view at the first threshold as the sprite (TerrainCost::gpu_sprite); null = not. Must hold the same terrain.
  GpuLodTerrain* gpu_high = nullptr;
};

// Times the LOD meshes of the views at each threshold, drawn with the original texture and, in sprite_calls + 1 draw
// calls, with a sprite, into a frame-size and a keyframe-size target, and the z-buffer read back
// of the keyframe target; fits TerrainCost::frame (gpu::CostModel::fit) and the read-back term. Needs a current
// context; must not run inside a timed frame. Throws farfield::Error for no views or bad options.
TerrainCost calibrateTerrainCost(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer,
                                 const TerrainCostOptions& options);
// The CDLOD terrain's models alone (TerrainCost::gpu_high and gpu_sprite; `frame` is left unfitted and the read-back
// term 0): for LOD-sprite wholly on the CDLOD terrain, e.g. a paged one with no quadtree LOD. options.gpu_high and
// sprite_calls are not used. Needs a current context; must not run inside a timed frame. Throws farfield::Error for
// no views or bad options.
TerrainCost calibrateCdlodCost(GpuLodTerrain& terrain, const TerrainCostOptions& options);

}  // namespace farfield::terrain
