// Occlusion culling against the frame's own depth: exact, so a frame drawn with it equals the frame without it.
//
// The items of a frame are drawn in two passes. The occluders (the items nearest the eye, up to a share of the
// frame's triangles, and every item whose bounds reach behind the eye) go first. The depth they leave is read back
// and reduced into a pyramid of farthest depths (DepthPyramid). Every other item whose bounding box lies behind that
// depth over the whole screen rectangle the box covers is dropped: each fragment it could make is farther than the
// depth already stored at its pixel (reversed Z, the GL_GREATER test), and later draws only bring stored depth
// nearer, so it would draw no pixel. Nothing is carried from frame to frame: no popping, no dependence on history.
//
// What it costs: one depth readback per frame (a wait for the occluder pass) and the pyramid's reduction on the CPU
// (about a third of a float comparison per pixel). What it saves: the triangles of everything behind the street's
// first row of buildings, which frustum and facing culling (GpuScene) keep.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/renderer.h"

namespace farfield::gpu {

class RenderTarget;

// A box's footprint on the screen: the window pixels [x0, x1] x [y0, y1] (GL order: row 0 at the bottom) that hold
// every pixel centre its projection covers, and the nearest window depth of its points (reversed Z: the largest).
// reaches_eye: some corner is at or behind the eye plane; the footprint is then the whole screen and the box is
// never hidden.
struct ScreenBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  float nearest = 0.0f;
  bool reaches_eye = false;
  bool onScreen() const { return x0 <= x1 && y0 <= y1; }
};

// box in the space that mvp (projection * view * model) takes to clip space; width x height pixels.
ScreenBox projectBox(const Box3& box, const Mat4& mvp, int width, int height);

// Levels of farthest depth: level 0 is the depth image, each texel of level k + 1 the farthest (smallest, reversed
// Z) of the texels of level k it covers.
class DepthPyramid {
 public:
  // depth: width x height window depths in GL order (row 0 at the bottom).
  void build(std::span<const float> depth, int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }
  // The farthest depth over the pixels [x0, x1] x [y0, y1] (clamped to the image), or an upper bound of it taken
  // from a coarser level: never nearer than a pixel of the rectangle. 1 (the near plane) for an empty rectangle.
  float farthest(int x0, int y0, int x1, int y1) const;
  // True when every point of the box is farther than the depth over its footprint (a small relative margin keeps
  // rounding on the safe side).
  bool hides(const ScreenBox& box) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<std::vector<float>> levels_;
  std::vector<std::pair<int, int>> sizes_;
};

// The split of occlusion culling's first pass: sorts `order` (indices into `boxes`) nearest first (boxes reaching
// the eye are infinitely near; ties by index, for a deterministic split) and returns how many of its first entries
// are occluders: the nearest until they hold `share` of the triangles of all (triangles(i) for index i, plus
// also_triangles: geometry that may follow them in the frame but is not among the boxes), and every box that reaches
// the eye.
size_t splitNearestFirst(std::vector<uint32_t>& order, std::span<const ScreenBox> boxes,
                         const std::function<uint64_t(uint32_t)>& triangles, double share,
                         uint64_t also_triangles = 0);

struct OcclusionStats {
  uint32_t items = 0;      // items offered
  uint32_t occluders = 0;  // drawn in the first pass
  uint32_t hidden = 0;     // dropped
  uint64_t hidden_triangles = 0;
  double readback_ms = 0.0;  // waiting for the occluder pass and reading its depth
  double pyramid_ms = 0.0;   // building the pyramid and testing the boxes
};

class OcclusionCuller {
 public:
  // occluder_share: the first pass draws the nearest items until they hold this share of the triangles.
  explicit OcclusionCuller(double occluder_share = 0.1);
  double occluderShare() const { return occluder_share_; }

  // items and bounds (parallel: each item's bounds in its mesh's space, as GpuScene::appendDrawItems gives them) of a
  // frame seen by camera into target. Calls draw_occluders once with the first pass's items (which must draw them
  // into target), then appends to `rest` the other items that are not hidden, nearest first. also_triangles: other
  // geometry the frame may draw behind these items (tested later with hidesBox), counted in the total whose share
  // the occluders hold, so that a frame whose items are a small near part of it gets the occluders a cull of all of
  // it would.
  OcclusionStats cull(const Camera& camera, std::span<const DrawItem> items, std::span<const Box3> bounds,
                      const RenderTarget& target,
                      const std::function<void(std::span<const DrawItem>)>& draw_occluders,
                      std::vector<DrawItem>& rest, uint64_t also_triangles = 0);
  // After cull(): whether a box given in world space lies behind the depth the occluders of the last cull left over
  // the whole of its footprint in that cull's camera (the same test cull() applies to its items). Reads the depth
  // back on first use when cull() did not need it (every item was an occluder). Things that are not draw items use
  // it: the nodes of an image cache, whose images and regenerations a hidden node does not need.
  bool hidesWorldBox(const Box3& box) { return hidesBox(box, Mat4(1.0f)); }
  // The same for a box in the space that `model` takes to the world (a draw item's bounds and transform).
  bool hidesBox(const Box3& box, const Mat4& model);
  // After cull(): appends to `out` the items (bounds parallel, as cull() takes them) that hidesBox does not hide, in
  // their order; the stats count the items offered and those hidden.
  OcclusionStats appendNotHidden(std::span<const DrawItem> items, std::span<const Box3> bounds,
                                 std::vector<DrawItem>& out);
  // Both passes with `renderer` (Renderer::draw: no clear, no wait): the occluders, then the items not hidden, then
  // `also` (items drawn after them as they are, such as impostors), all in `mode`.
  OcclusionStats draw(Renderer& renderer, const Camera& camera, std::span<const DrawItem> items,
                      std::span<const Box3> bounds, RenderTarget& target, std::span<const DrawItem> also = {},
                      RenderMode mode = RenderMode::Shaded);

 private:
  double occluder_share_;
  std::vector<ScreenBox> boxes_;
  std::vector<uint32_t> order_;
  std::vector<DrawItem> occluders_;
  std::vector<DrawItem> rest_;  // draw()'s second pass
  std::vector<float> depth_;
  DepthPyramid pyramid_;
  // The last cull's camera and target, and whether its pyramid has been built (hidesWorldBox).
  Mat4 view_proj_{1.0f};
  const RenderTarget* target_ = nullptr;
  bool pyramid_built_ = false;
  void buildPyramid(OcclusionStats* stats);
};

}  // namespace farfield::gpu
