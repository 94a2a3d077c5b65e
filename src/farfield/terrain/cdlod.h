// Continuous distance-dependent LOD for heightfields (Strugar 2009, "Continuous Distance-Dependent Level of Detail
// for Rendering Heightmaps"), with its ranges derived from a screen-space error bound instead of fixed ratios, so
// that it keeps the same promise as the quadtree LOD (quadtree_lod.h): every drawn point's vertical error, projected
// at its distance, is at most tau pixels.
//
// One static grid patch of P x P quads is drawn for every selected node, as instances of one draw; the vertex shader
// (gpu/cdlod_renderer.h) places the patch, fetches the heights from a texture and morphs each vertex towards the next
// coarser level. This file is the CPU half: the per-level errors and node boxes (computed once), the ranges for a
// camera and bound, the per-frame selection over a few hundred nodes, and a reference of the vertex shader's
// arithmetic for the tests.
//
// Levels: level L has a vertex every 2^L grid cells; a node (patch) of level L covers P * 2^L cells, its origin a
// multiple of that. 2^Lmax divides both (width - 1) and (height - 1), so every vertex of a level below the top lies on
// the grid or wholly beyond it (clamped onto the border: the triangles there are degenerate), and the border never
// moves under morphing. A cell's two triangles split it along its (0,0)-(1,1) diagonal.
//
// Errors, per node: E(N) = the largest vertical distance between a grid point of node N's area (its border included)
// and the mesh of N's level over it (0 at level 0). Ranges, per node Q of level L+1 >= 1, for the morph of the level-L
// vertices inside Q towards Q's level (s = lambda / tau, lambda = pixels per radian, tau the bound in pixels):
//   start(Q) = max(s * E(Q), max over Q's children P of endD(P) + diag(P))   (the second term from level 2 up)
//   end(Q)   = start(Q) + morph_fraction * max(start(Q), diag(Q) / 2)
//   endD(Q)  = the largest end(.) over Q and its 8 neighbours of its level
// (diag: the 3D diagonal of a node's box). A vertex of level L takes start and end as the largest over the level-(L+1)
// nodes it lies in (one, or two or four on their borders: the same values for every node that shares the vertex),
// and its morph factor is k = (d - start) / (end - start) clamped to [0, 1], d its distance from the eye before
// morphing. Selection: a node N of level L >= 1 whose box comes closer to the eye than endD(N) is replaced by its
// four children; otherwise it is drawn (frustum culling by its box first). Hence:
//   - a node N drawn at level L >= 1 lies beyond endD(N) >= start(N) >= s * E(N): its mesh keeps the bound; a
//     morphing vertex inside Q lies beyond start(Q) >= s * E(Q), where Q's coarser mesh keeps it too;
//   - a level-L node A next to a drawn level-(L+1) node B: A's vertices on the shared edge lie in B, beyond
//     endD(B) >= their end (k = 1: collapsed onto B's grid), and B's lie in A's parent P, within endD(P) + diag(P)
//     <= start of the node above P (k = 0): no crack; neighbours differ by at most one level (the same argument one
//     level up); and a node replaced by its children at endD shows the same surface before and after (no pop).
// The ranges depend on the camera only through s, so they are recomputed only when the image height, field of view
// or bound change, and selections at the same s share one table.
// Morphing: odd vertices of a patch (odd i or j) slide by k * 2^L cells towards the lower even vertex, and take the
// height bilinearly interpolated from the full-resolution grid at the morphed position: at k = 1 the patch is the
// coarser level's mesh (the (odd, odd) cell of each 2 x 2 block keeps its diagonal; the others collapse).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/math.h"
#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

struct CdlodOptions {
  int patch_cells = 16;         // P: quads per patch side, a power of two >= 2
  int max_level = 16;           // the top level is at most this (and as 2^L divides the grid's cell counts)
  float morph_fraction = 0.2f;  // width of the morph range, relative to its start (>= 0; 0: no morphing, pops)
};

// The grid a CDLOD terrain covers: points and cell sizes (heightfield.h's frame).
struct CdlodGrid {
  int width = 0, height = 0;
  double cell_x = 1.0, cell_y = 1.0;
};

struct CdlodNode {
  int level = 0;
  int x = 0, y = 0;  // node index at its level: grid origin (x, y) * P * 2^level
};

// Per node of levels >= 1 (indexed as CdlodTerrain::nodeIndex): start, end and endD (see the file comment), for one
// scale lambda / tau. The table is shared by every selection of the terrain at that scale while one holds it (a
// 16,385^2 grid's is 17 MB and 30 ms to make).
struct CdlodRanges {
  double scale = 0.0;  // lambda / tau they were made for (0: not made)
  std::shared_ptr<const std::vector<Vec3>> table;
  const Vec3& node(size_t index) const { return (*table)[index]; }
  size_t size() const { return table ? table->size() : 0; }
};

struct CdlodSelection {
  std::vector<CdlodNode> nodes;
  CdlodRanges ranges;           // kept from frame to frame, taken anew when the scale changes
  bool ranges_changed = false;  // taken anew by the last select() (made, or shared with another selection)
  size_t visited = 0;  // nodes tested
  size_t culled = 0;   // left out by the frustum
};

class CdlodTerrain {
 public:
  // Keeps a reference to hf, which must outlive this. Throws farfield::Error for a grid smaller than 2 x 2, a patch
  // size that is not a power of two >= 2, or a negative morph fraction.
  explicit CdlodTerrain(const Heightfield& hf, const CdlodOptions& options = {});
  // Node data made elsewhere (cdlod_tiles.h: from a tile cache, the grid never held whole): per node in nodeIndex
  // order, its height range (min, max) and its error E(N) (or an upper bound of it: the ranges then keep the bound
  // with room to spare). No heights: vertex(), morphFactor() and heightAt() need the other constructor. Throws
  // farfield::Error for arrays that do not match the grid's node counts, or as the other constructor.
  CdlodTerrain(const CdlodGrid& grid, const CdlodOptions& options, std::vector<Vec2> heights,
               std::vector<float> errors);

  // Nodes of every level for a grid (the length of the node data).
  static size_t nodeCountFor(const CdlodGrid& grid, const CdlodOptions& options);
  // The top level for a grid (see the file comment); throws farfield::Error (naming `what`) for bad options.
  static int topLevelFor(const CdlodGrid& grid, const CdlodOptions& options,
                         const std::string& what = "CDLOD terrain");

  const CdlodGrid& grid() const { return grid_; }
  bool hasHeights() const { return hf_ != nullptr; }
  const Heightfield& heightfield() const;
  const CdlodOptions& options() const { return options_; }
  int patchCells() const { return options_.patch_cells; }
  int topLevel() const { return top_; }
  int levels() const { return top_ + 1; }
  // Cells between neighbouring vertices of a level.
  int spacing(int level) const { return 1 << level; }
  // Nodes along x and y at a level (those that overlap the grid).
  int nodesX(int level) const;
  int nodesY(int level) const;
  // Index of a node of any level in per-node arrays (CdlodRanges::node(index)); levelOffset(l): node (l, 0, 0)'s.
  size_t nodeIndex(const CdlodNode& node) const;
  size_t levelOffset(int level) const { return box_offset_[size_t(level)]; }
  size_t nodeCount() const { return boxes_.size(); }
  float nodeError(const CdlodNode& node) const { return node_error_[nodeIndex(node)]; }  // E(N), metres
  Vec2 nodeHeights(const CdlodNode& node) const { return boxes_[nodeIndex(node)]; }      // (min, max), metres
  float levelError(int level) const { return error_[size_t(level)]; }  // largest E(N) of the level and finer ones
  // The node's box: its grid area clamped to the grid, heights over that area.
  Box3 nodeBox(const CdlodNode& node) const;
  size_t bytes() const;

  // Makes the ranges for a camera and bound tau (pixels) unless `ranges` already holds them (true when it did not):
  // the table of that scale that another selection holds, else a new one.
  bool updateRanges(const Camera& camera, float pixel_error, CdlodRanges& ranges) const;
  // The nodes to draw for a camera (eye, image height, field of view, frustum when cull) and bound tau (pixels).
  // Throws farfield::Error for a bound that is not a positive number.
  void select(const Camera& camera, float pixel_error, bool cull, CdlodSelection& out) const;

  // What the vertex shader computes for patch vertex (i, j), 0 <= i, j <= P, of a node: the world position after
  // morphing (grid coordinates clamped to the grid, heights interpolated bilinearly). Float arithmetic, as the GPU.
  Vec3 vertex(const CdlodNode& node, int i, int j, const CdlodRanges& ranges, const Vec3& eye) const;
  // Morph factor of that vertex (0 for the top level).
  float morphFactor(const CdlodNode& node, int i, int j, const CdlodRanges& ranges, const Vec3& eye) const;
  // Bilinear height at grid coordinates (gx, gy), clamped to the grid, in the shader's float arithmetic.
  float heightAt(float gx, float gy) const;

 private:
  void layOut();  // top_ set: the per-level offsets of the node data
  void computeBoxes();
  void computeErrors();
  void computeLevelErrors();  // error_ from node_error_
  void selectNode(const CdlodNode& node, const Vec3& eye, const Frustum* frustum, CdlodSelection& out) const;

  // The range tables that selections hold, by scale, shared by the terrain's copies.
  struct RangeTables {
    std::mutex mutex;
    std::vector<std::pair<double, std::weak_ptr<const std::vector<Vec3>>>> tables;
  };
  std::shared_ptr<RangeTables> range_tables_ = std::make_shared<RangeTables>();
  std::shared_ptr<const std::vector<Vec3>> makeRanges(double scale) const;

  const Heightfield* hf_ = nullptr;
  CdlodGrid grid_;
  CdlodOptions options_;
  int top_ = 0;
  std::vector<float> error_;       // per level
  std::vector<float> node_error_;  // per node
  // Per level, nodesX * nodesY (min, max) heights, row-major; offsets into boxes_.
  std::vector<size_t> box_offset_;
  std::vector<Vec2> boxes_;
};

// The largest vertical distance between the grid points h(i, j) of [x0, x1] x [y0, y1] (every stride-th one from
// (x0, y0)) and the mesh of level spacing s over them, its cells split along their (0,0)-(1,1) diagonal: a node's
// E(N) with stride 1. h(i, j) gives the grid's height, clamped to the grid. (With a stride that is a multiple of a
// finer level's spacing, the finer mesh's vertices: cdlod_tiles.h's bound.)
template <class Height>
double levelMeshError(const Height& h, int x0, int y0, int x1, int y1, int s, int stride = 1) {
  const double inv = 1.0 / s;
  double worst = 0.0;
  for (int j = y0; j <= y1; j += stride) {
    const int cy = j / s * s;
    const double v = (j - cy) * inv;
    for (int i = x0; i <= x1; i += stride) {
      const int cx = i / s * s;
      if (i == cx && j == cy) continue;  // a vertex of the level
      const double u = (i - cx) * inv;
      const double h00 = h(cx, cy), h10 = h(cx + s, cy), h01 = h(cx, cy + s), h11 = h(cx + s, cy + s);
      const double mesh = u >= v ? h00 + u * (h10 - h00) + v * (h11 - h10) : h00 + v * (h01 - h00) + u * (h11 - h01);
      worst = std::max(worst, std::abs(mesh - double(h(i, j))));
    }
  }
  return worst;
}

}  // namespace farfield::terrain
