// The CDLOD terrain on the GPU (terrain/cdlod.h's selection, gpu/cdlod_renderer.h's instanced patch): the terrain
// module's frame for `high-gpu` and `low-gpu`. Per frame: the selection over the node tree on the CPU (a few hundred
// nodes), an upload of 16 bytes a drawn node, one instanced draw; no per-frame triangle list, no wait.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/cdlod_renderer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/image.h"
#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/heightfield.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {

struct GpuLodFrame {
  gpu::FrameStats draw;     // triangles (every drawn node's patch, degenerate ones included), one draw call
  size_t nodes = 0;         // drawn
  size_t nodes_visited = 0; // tested by the selection
  size_t nodes_culled = 0;  // left out by the frustum
  // A terrain paged in tiles (paged_gpu_lod.h); 0 otherwise.
  size_t paged_nodes = 0;   // drawn nodes reading a page
  size_t pages_needed = 0;  // distinct pages the draw read
  size_t page_loads = 0;    // read by the draw itself (it waited)
};

// A selection's morph ranges into a renderer's range slot (when select() remade them).
void uploadRanges(const CdlodSelection& selection, gpu::CdlodRenderer& renderer, int slot = 0);
// A selected node as the renderer's instance: its corner grid point, its level and its page layer (-1: none).
gpu::CdlodInstance cdlodInstance(const CdlodNode& node, int patch_cells, int layer = -1);

class GpuLodTerrain {
 public:
  // Needs a current context; hf must outlive this. texture: the terrain's original texture, placed as
  // texCoordTransform (terrain_texture.h) places it. Throws farfield::Error as CdlodTerrain and CdlodRenderer do.
  GpuLodTerrain(const Heightfield& hf, const image::ColorImage& texture, const CdlodOptions& options = {});
  virtual ~GpuLodTerrain();
  GpuLodTerrain(const GpuLodTerrain&) = delete;
  GpuLodTerrain& operator=(const GpuLodTerrain&) = delete;

  // Selects and draws the terrain for the camera under the bound (pixels) into the bound target (not cleared).
  GpuLodFrame draw(const Camera& camera, float pixel_error, gpu::RenderTarget& target, bool cull = true);
  // draw() in two steps, for a host that decides between them (LOD-sprite: its error metric runs over the
  // selection): select() returns the selection's handle, valid until selections for kRangeSlots other bounds were
  // made; drawSelection() draws it with the camera it was selected for (or one of the same image height and field
  // of view). Throws farfield::Error for a handle never returned.
  int select(const Camera& camera, float pixel_error, bool cull = true);
  const CdlodSelection& selection(int handle) const;
  GpuLodFrame drawSelection(const Camera& camera, int handle, gpu::RenderTarget& target);
  // Part of a selection kept by the caller: `nodes` (a copy of selection(handle).nodes made for this camera and
  // bound, or a run of it) drawn with the ranges of the bound at the camera's pixel density, made again where no
  // slot still holds them. LOD-sprite draws a keyframe rendered ahead this way, in slices over several frames, while
  // other selections are made in between. nodes_visited and nodes_culled are 0.
  GpuLodFrame drawNodes(const Camera& camera, float pixel_error, std::span<const CdlodNode> nodes,
                        gpu::RenderTarget& target);

  // Leaves out the ground of a rectangle of grid points (the quadtree LOD's hole, removeTrianglesInside: a city's
  // ground drawn by someone else): fragments strictly inside it, in world x, y, are discarded. An empty rectangle
  // clears it. Applies to the draws that follow.
  void setHole(const GridRect& hole);
  void clearHole() { renderer_->clearHole(); }

  // The heights of grid points (each clamped to the grid) into `out` (as many), as the CPU holds them (LOD-sprite's
  // error metric runs over grid points, sprite_error.h); a paged terrain answers from the pages it holds, else from
  // its overview. own (empty, or as many): 1 where the height is the grid's own, 0 where it is the overview's.
  // gridHeight: one point.
  virtual void gridHeights(std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own = {}) const;
  float gridHeight(int i, int j) const;
  // Changes whenever gridHeights may answer a point with another height than before (a paged terrain: when a page's
  // heights come in for its overview's); this one: always 0.
  virtual uint64_t heightsVersion() const { return 0; }
  // Whether gridHeights gives the grid's own heights wherever the terrain is drawn at full resolution (a paged
  // terrain: only when it keeps its pages' heights); LOD-sprite's metric needs them.
  virtual bool holdsGridHeights() const { return true; }
  // The ground's height under world (x, y), bilinear (a paged terrain: its overview's).
  virtual float groundHeight(double x, double y) const;
  // The box of the whole terrain (its top level's node boxes).
  Box3 bounds() const;

  const CdlodTerrain& lod() const { return lod_; }
  const CdlodSelection& lastSelection() const { return selections_[last_]; }
  gpu::CdlodRenderer& renderer() { return *renderer_; }
  virtual size_t gpuBytes() const { return renderer_->gpuBytes(); }

 protected:
  // A terrain whose node data were made elsewhere (a paged one): the renderer is attached by the derived class.
  explicit GpuLodTerrain(CdlodTerrain lod);
  // Sets the renderer and its levels from the node tree.
  void attachRenderer(std::unique_ptr<gpu::CdlodRenderer> renderer);
  // The instances of the nodes to draw, with the page layer each reads (-1: none), made resident for the draw; the
  // paged counts go to `frame`. This one: every layer -1.
  virtual void placeNodes(std::span<const CdlodNode> nodes, std::vector<gpu::CdlodInstance>& out, GpuLodFrame& frame);

  CdlodTerrain lod_;
  std::unique_ptr<gpu::CdlodRenderer> renderer_;

 private:
  // One selection (with its ranges) per bound in use, each drawn with its own range slot; the least recently used
  // is remade for a new bound.
  CdlodSelection selections_[gpu::CdlodRenderer::kRangeSlots];
  uint64_t used_[gpu::CdlodRenderer::kRangeSlots] = {};
  uint64_t frame_ = 0;
  int last_ = 0;
  std::vector<gpu::CdlodInstance> instances_;
  // The slot for a scale (lambda / tau): the one whose ranges were made for it, else the least recently used; marked
  // used.
  int slotFor(double scale);
  GpuLodFrame drawInstances(const Camera& camera, std::span<const CdlodNode> nodes, int slot,
                            gpu::RenderTarget& target);
};

}  // namespace farfield::terrain
