#include "farfield/terrain/gpu_lod.h"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/terrain/sprite_error.h"

#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain {
namespace {

Vec2 uvScale(const Heightfield& hf) {
  Vec2 scale, offset;
  texCoordTransform(hf, scale, offset);
  return scale;
}

Vec2 uvOffset(const Heightfield& hf) {
  Vec2 scale, offset;
  texCoordTransform(hf, scale, offset);
  return offset;
}

}  // namespace

GpuLodTerrain::GpuLodTerrain(const Heightfield& hf, const image::ColorImage& texture, const CdlodOptions& options)
    : lod_(hf, options) {
  attachRenderer(std::make_unique<gpu::CdlodRenderer>(hf.width, hf.height, hf.heights,
                                                      Vec2(float(hf.cell_x), float(hf.cell_y)), options.patch_cells,
                                                      texture, uvScale(hf), uvOffset(hf)));
}

GpuLodTerrain::GpuLodTerrain(CdlodTerrain lod) : lod_(std::move(lod)) {}

GpuLodTerrain::~GpuLodTerrain() = default;

void GpuLodTerrain::attachRenderer(std::unique_ptr<gpu::CdlodRenderer> renderer) {
  std::vector<int> offsets;
  std::vector<IVec2> counts;
  for (int l = 0; l <= lod_.topLevel(); ++l) {
    offsets.push_back(int(lod_.levelOffset(l)));
    counts.emplace_back(lod_.nodesX(l), lod_.nodesY(l));
  }
  renderer->setLevels(offsets, counts);
  renderer_ = std::move(renderer);
}

void GpuLodTerrain::setHole(const GridRect& hole) {
  if (hole.empty()) {
    renderer_->clearHole();
    return;
  }
  const CdlodGrid& g = lod_.grid();
  renderer_->setHole(Vec2(float(hole.x0 * g.cell_x), float(hole.y0 * g.cell_y)),
                     Vec2(float(hole.x1 * g.cell_x), float(hole.y1 * g.cell_y)));
}

void GpuLodTerrain::gridHeights(std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own) const {
  heightfieldHeights(lod_.heightfield())(points, out, own);
}

float GpuLodTerrain::gridHeight(int i, int j) const {
  const IVec2 point(i, j);
  float h = 0.0f;
  gridHeights({&point, 1}, {&h, 1});
  return h;
}

float GpuLodTerrain::groundHeight(double x, double y) const { return lod_.heightfield().sample(x, y); }

Box3 GpuLodTerrain::bounds() const {
  const int top = lod_.topLevel();
  Box3 box = lod_.nodeBox(CdlodNode{top, 0, 0});
  for (int y = 0; y < lod_.nodesY(top); ++y)
    for (int x = 0; x < lod_.nodesX(top); ++x) {
      const Box3 b = lod_.nodeBox(CdlodNode{top, x, y});
      box.lo = glm::min(box.lo, b.lo);
      box.hi = glm::max(box.hi, b.hi);
    }
  return box;
}

void GpuLodTerrain::placeNodes(std::span<const CdlodNode> nodes, std::vector<gpu::CdlodInstance>& out,
                               GpuLodFrame&) {
  for (const CdlodNode& n : nodes) out.push_back(cdlodInstance(n, lod_.patchCells()));
}

void uploadRanges(const CdlodSelection& selection, gpu::CdlodRenderer& renderer, int slot) {
  std::vector<Vec2> ranges;
  ranges.reserve(selection.ranges.size());
  for (size_t k = 0; k < selection.ranges.size(); ++k) ranges.emplace_back(Vec2(selection.ranges.node(k)));
  renderer.setRanges(ranges, slot);
}

gpu::CdlodInstance cdlodInstance(const CdlodNode& node, int patch_cells, int layer) {
  const int cells = patch_cells << node.level;
  return {int32_t(node.x * cells), int32_t(node.y * cells), int32_t(node.level), int32_t(layer)};
}

int GpuLodTerrain::slotFor(double scale) {
  int slot = 0;
  for (int s = 0; s < gpu::CdlodRenderer::kRangeSlots; ++s) {
    if (selections_[s].ranges.scale == scale) {
      slot = s;
      break;
    }
    if (used_[s] < used_[slot]) slot = s;
  }
  used_[slot] = ++frame_;
  return slot;
}

int GpuLodTerrain::select(const Camera& camera, float pixel_error, bool cull) {
  const int slot = slotFor(QuadtreeLod::pixelsPerRadian(camera) / double(pixel_error));
  last_ = slot;
  CdlodSelection& selection = selections_[slot];
  lod_.select(camera, pixel_error, cull, selection);
  if (selection.ranges_changed) uploadRanges(selection, *renderer_, slot);
  return slot;
}

const CdlodSelection& GpuLodTerrain::selection(int handle) const {
  if (handle < 0 || handle >= gpu::CdlodRenderer::kRangeSlots || used_[handle] == 0)
    throw Error("CDLOD terrain", "no selection " + std::to_string(handle));
  return selections_[handle];
}

GpuLodFrame GpuLodTerrain::drawInstances(const Camera& camera, std::span<const CdlodNode> nodes, int slot,
                                         gpu::RenderTarget& target) {
  instances_.clear();
  GpuLodFrame frame;
  placeNodes(nodes, instances_, frame);
  frame.draw = renderer_->draw(camera, target, instances_, slot);
  frame.nodes = nodes.size();
  return frame;
}

GpuLodFrame GpuLodTerrain::drawSelection(const Camera& camera, int handle, gpu::RenderTarget& target) {
  const CdlodSelection& sel = selection(handle);
  GpuLodFrame frame = drawInstances(camera, sel.nodes, handle, target);
  frame.nodes_visited = sel.visited;
  frame.nodes_culled = sel.culled;
  return frame;
}

GpuLodFrame GpuLodTerrain::drawNodes(const Camera& camera, float pixel_error, std::span<const CdlodNode> nodes,
                                     gpu::RenderTarget& target) {
  const double scale = QuadtreeLod::pixelsPerRadian(camera) / double(pixel_error);
  const int slot = slotFor(scale);
  CdlodSelection& held = selections_[slot];
  if (held.ranges.scale != scale) {
    // The slot is remade for this bound: its old selection is gone (a handle to it now names an empty one).
    held.nodes.clear();
    held.visited = held.culled = 0;
    lod_.updateRanges(camera, pixel_error, held.ranges);  // throws for a bound that is not a positive number
    uploadRanges(held, *renderer_, slot);
  }
  return drawInstances(camera, nodes, slot, target);
}

GpuLodFrame GpuLodTerrain::draw(const Camera& camera, float pixel_error, gpu::RenderTarget& target, bool cull) {
  return drawSelection(camera, select(camera, pixel_error, cull), target);
}

}  // namespace farfield::terrain
