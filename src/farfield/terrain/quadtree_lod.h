// Quadtree continuous LOD for heightfields, in the spirit of Lindstrom et al. 1996 (which LOD-sprite, Chen et al.
// 1999 section 2.2, builds on), as a right-triangulated irregular network (longest-edge bisection) with the
// vertex dependencies of a restricted quadtree.
//
// The grid is a forest of square blocks of `block` x `block` cells (block a power of two); every grid point that is
// not a block corner is the split vertex of exactly one "diamond": either the centre of a quadtree square (the
// diamond is the square, split by one diagonal into two right triangles) or the midpoint of a square's edge (the
// diamond is the two triangles on either side of that edge). Splitting a triangle at its hypotenuse midpoint
// produces the next level; a vertex is in the mesh ("active") when its projected error exceeds the threshold.
//
// Per vertex v, precomputed bottom-up:
//   delta(v): the largest vertical distance (metres) between a grid point of v's diamond and the unsplit diamond
//             (its two triangles through the grid heights), then raised to the largest delta of v's descendants;
//   radius(v): the largest 3D distance from v to a grid point of its diamond, raised to cover each descendant's
//             sphere (radius(child) + |v - child|).
// A vertex is active when lambda * delta(v) > tau * (|eye - v| - radius(v)), lambda = pixels per radian (image
// height / (2 tan(fov_y / 2))), tau the threshold in pixels. Because delta and the spheres nest, a vertex is only
// ever active when the vertices it depends on are, so the mesh is conforming: no cracks and no T-junctions, and
// neighbouring triangles differ by at most one bisection level. And any grid point that a leaf triangle leaves out
// has vertical error e with lambda * e / |eye - p| <= tau: the screen-space error threshold, in pixels of angular
// size seen from the eye (Lindstrom et al.'s projection of the vertical error; exact at the image centre).
//
// "Quadrants" (Chen et al. section 3.2): the diamonds whose split vertex is not in the mesh but at least one of whose
// triangles is (a leaf of the refinement). Their central vertex C is the grid point the low-resolution mesh skips,
// their 4 corners (3 on the grid boundary) are mesh vertices or lie on mesh edges.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

struct LodSettings {
  float pixel_error = 1.0f;       // tau: screen-space error threshold, pixels
  bool cull = true;               // leave out triangles whose bounding sphere is outside the view frustum
  bool collect_quadrants = false; // fill LodMesh::quadrants
};

struct LodQuadrant {
  uint32_t centre = 0;                // grid index of the central vertex C (not in the mesh)
  std::array<uint32_t, 4> corners{};  // grid indices, counter-clockwise seen from above
  uint8_t corner_count = 4;           // 4, or 3 for an edge diamond on the grid boundary
  uint8_t square = 1;                 // 1: a quadtree square (axis-aligned); 0: an edge diamond (45 degrees)
};

struct LodMesh {
  std::vector<uint32_t> indices;         // grid indices, three per triangle, counter-clockwise seen from above
  std::vector<LodQuadrant> quadrants;    // with LodSettings::collect_quadrants, sorted by centre index
  size_t triangleCount() const { return indices.size() / 3; }
  void clear() {
    indices.clear();
    quadrants.clear();
  }
};

// A rectangle of grid points, [x0, x1] x [y0, y1] inclusive (empty by default).
struct GridRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0 || y1 < y0; }
  bool contains(int x, int y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

// Removes the triangles whose three vertices lie in `rect` (grid indices of a grid `grid_width` points wide); the
// quadrants stay. A hole cut for ground drawn by something else (a city on the terrain).
void removeTrianglesInside(LodMesh& mesh, const GridRect& rect, uint32_t grid_width);

// Part of a LOD to build, for a LOD over one tile of a larger grid (tiled_lod.h): only the blocks
// [block_x0, block_x1) x [block_y0, block_y1) are refined, and the mesh's indices (and quadrants) are grid indices
// of the larger grid, (x * step + origin.x) + (y * step + origin.y) * global_width for the LOD's grid point (x, y).
struct LodWindow {
  int block_x0 = 0, block_y0 = 0, block_x1 = 0, block_y1 = 0;
  uint32_t global_width = 0;
};

class QuadtreeLod {
 public:
  // hf must be (a * block + 1) x (b * block + 1) points, block a power of two >= 2 (cropForBlocks makes such a
  // grid); block 0 picks the largest power of two (at most 512) that fits. Throws farfield::Error otherwise. Keeps a
  // reference to hf, which must outlive the LOD. origin: where hf's grid point (0, 0) lies in a larger grid of the
  // same cell size (a tile, tiled_lod.h); positions are those of that grid's local frame, (i + origin.x) * cell_x,
  // computed exactly as the larger grid's own LOD computes them, so a tile's errors, spheres and choices match it.
  explicit QuadtreeLod(const Heightfield& hf, int block = 0, IVec2 origin = IVec2(0));
  // A LOD whose errors and spheres were computed beforehand on the full-resolution grid (tile_cache.h): hf holds
  // every step-th grid point (step a power of two; hf.cell_x = step * the full grid's cell), block is in hf's
  // points, origin in full-grid points, and delta / radius are the full grid's saturated values at hf's points.
  // Positions are computed as the full grid's (exactly), so every vertex hf keeps is active exactly when it is
  // in the full-resolution LOD. Throws farfield::Error for arrays that do not match hf.
  QuadtreeLod(const Heightfield& hf, int block, IVec2 origin, int step, std::vector<float> delta,
              std::vector<float> radius);

  const Heightfield& heightfield() const { return *hf_; }
  int block() const { return block_; }
  int width() const { return hf_->width; }
  int height() const { return hf_->height; }
  IVec2 origin() const { return origin_; }
  int step() const { return step_; }
  int blocksX() const { return (hf_->width - 1) / block_; }
  int blocksY() const { return (hf_->height - 1) / block_; }
  // Bytes held by the LOD's own arrays (positions, errors, spheres), not counting the heightfield.
  size_t bytes() const;
  // Saturated object-space error (metres) and sphere radius of a grid vertex; block corners give +infinity / 0.
  float objectError(uint32_t v) const { return delta_[v]; }
  float radius(uint32_t v) const { return radius_[v]; }
  // Grid vertices v depends on (0, 1 or 2; block corners have none).
  int parents(uint32_t v, std::array<uint32_t, 2>& out) const;
  Vec3 position(uint32_t v) const { return positions_[v]; }
  const std::vector<Vec3>& positions() const { return positions_; }
  const std::vector<float>& objectErrors() const { return delta_; }
  const std::vector<float>& radii() const { return radius_; }

  static double pixelsPerRadian(const Camera& camera);
  bool active(uint32_t v, const Vec3& eye, double lambda, float tau) const;

  // The view-dependent mesh for a camera (its eye, frustum and image height) and threshold.
  // window: null = every block, local indices; otherwise see LodWindow (out is cleared either way).
  void build(const Camera& camera, const LodSettings& settings, LodMesh& out,
             const LodWindow* window = nullptr) const;
  LodMesh build(const Camera& camera, const LodSettings& settings) const;
  // The grid at full resolution (two triangles per cell), counter-clockwise seen from above.
  std::vector<uint32_t> fullResolutionIndices() const;

 private:
  struct Build;
  void init(int block, int step);
  void computeErrors();

  const Heightfield* hf_;
  int block_ = 0;
  IVec2 origin_{0};
  int step_ = 1;  // full-grid points between neighbouring points of hf (precomputed LODs of tiles)
  std::vector<Vec3> positions_;
  std::vector<float> delta_;
  std::vector<float> radius_;
};

// Kind of a grid point in the LOD's hierarchy (exposed for tests).
enum class LodVertexKind { BlockCorner, SquareCentre, EdgeHorizontal, EdgeVertical };
// Kind and scale s (the side of the square whose centre or edge midpoint the point is) of grid point (x, y).
LodVertexKind lodVertexKind(int x, int y, int block, int* scale);

}  // namespace farfield::terrain
