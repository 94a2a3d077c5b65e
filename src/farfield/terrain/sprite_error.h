// LOD-sprite error metric, Chen et al. 1999 section 3.2 (equations 1 and 2).
//
// For a low-resolution quadrant with true central vertex C (a grid point the low-resolution mesh skips) and corners
// Q_k, the estimated central vertex is C^ = the mean of the corners (for a 3-corner diamond on the grid boundary,
// the midpoint of its two corners on the boundary line, which lies above C like C^ does). The keyframe, rendered
// from v1, shows C where the ray v1 -> C meets the low-resolution surface: C' = the intersection of that ray with
// the plane spanned by C^ and two corners Q_k, Q_k+1 of the quadrant. Which two the paper leaves open; we take the
// fan triangle (C^, Q_k, Q_k+1) the ray actually crosses (the first crossing from v1), and when the ray crosses
// none of them (it grazes the quadrant) the plane of the fan triangle that lies in the ray's direction (past C^
// when C is above C^, before it otherwise). From the novel viewpoint v2, the sprite shows C at C', so the angular
// error is theta = angle(v2C, v2C') (equation 1 compares it with beta * epsilon). A new keyframe is due when the
// mean of theta^2 over the frame's n low-resolution quadrants reaches (beta * epsilon)^2 (equation 2), with
// beta = field of view / image width (the horizontal view angle of one pixel) and epsilon in pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/core/math.h"
#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {

// C' for one quadrant (see above); returns false (and leaves c_prime alone) when the ray is parallel to every
// candidate plane or v1 coincides with C. near: a fallback C' is kept within the quadrant's neighbourhood, its xy box
// grown by its own size on every side, where the ray leaves that. A ray that grazes the fallback plane meets it
// arbitrarily far away, even next to v1: in the CDLOD metric's test one cell 4 km from the eye had C' next to v1 and
// theta 3 rad, the whole of the mean over 6,400 cells. The quadtree's metric (near = false) keeps the plane as the
// paper states it, so that its figures stay comparable; with near, its test path's keyframes trip later (the first
// at frame 16 instead of 12 on LodSprite.KeyframesRenderedAheadAreUsed's path): it has such outliers too.
bool spriteProjection(const DVec3& c, std::span<const DVec3> corners, const DVec3& v1, DVec3& c_prime,
                      bool near = false);
// theta (radians) for one quadrant; 0 when spriteProjection fails (the caller counts those as skipped).
double quadrantTheta(const DVec3& c, std::span<const DVec3> corners, const DVec3& v1, const DVec3& v2,
                     bool* ok = nullptr, bool near = false);
// theta from C' already found: the angle at v2 between C and C' (radians).
double spriteTheta(const DVec3& c, const DVec3& c_prime, const DVec3& v2);
// |C - v1| / |C - v2| (SpriteError::mean_magnification's term), 1 where C is at v2.
double spriteMagnification(const DVec3& c, const DVec3& v1, const DVec3& v2);

// beta: the view angle of one pixel, horizontal field of view / image width (radians per pixel).
double pixelAngle(const Camera& camera);

struct SpriteError {
  double mean_theta_sq = 0.0;  // radians^2, equation 2's left side
  size_t quadrants = 0;        // n
  size_t skipped = 0;          // quadrants with no usable C' (not in n)
  double max_theta = 0.0;      // radians
  // The sprite's stretch: the mean over the quadrants of |C - v1| / |C - v2|, the keyframe's distance to a point
  // over the novel view's (both draw at the same pixel density). Above 1 the keyframe's texels cover more than a
  // pixel there: the sprite is magnified, and blurs what the high LOD would show sharp, which theta does not see
  // (a sprite on a smooth terrain approached head-on keeps theta near 0). 1 with no quadrant.
  double mean_magnification = 1.0;
  // The error in pixels: sqrt(mean theta^2) / beta (what the paper's Figure 10 plots).
  double pixels(double beta) const { return beta > 0.0 ? std::sqrt(mean_theta_sq) / beta : 0.0; }
};

// Equation 2's mean over the quadrants of a low-resolution mesh (LodSettings::collect_quadrants).
SpriteError spriteError(const QuadtreeLod& lod, std::span<const LodQuadrant> quadrants, const Vec3& v1,
                        const Vec3& v2);
// Equation 2's mean over the quadrants of a CDLOD low-resolution mesh (gpu_lod.h's selection): a cell of a drawn node
// of level L >= 1 has its corners every 2^L grid points and its true central vertex C at the grid point in its middle
// (cells of level 0 skip no grid point, and cells beyond the grid are degenerate: neither is a quadrant). The mesh
// is taken unmorphed. With more than max_quadrants cells (0: no limit; a CDLOD mesh has thousands where the
// quadtree's has hundreds), a stratified sample of about max_quadrants stands for the mean: each node is a stratum
// whose sampled mean stands for all its cells, and the sample is spread over the nodes by (E(N) / d^2)^2, the size
// of theta^2 there (E(N) the node's error, d its distance from v2), at least one cell each: theta^2 is heavy-tailed,
// and the near nodes, few of the cells, hold most of the mean. A node's cells are every k-th (k odd, so that the
// sample moves across the patch's columns) from an offset fixed by the node, so a node keeps its sample from frame to
// frame. C' as spriteProjection with near. quadrants: the cells evaluated. Needs the terrain's heights.
SpriteError spriteError(const CdlodTerrain& lod, std::span<const CdlodNode> nodes, const Vec3& v1, const Vec3& v2,
                        size_t max_quadrants = 1024);
// The same with the grid's heights from `heights` (the heights of grid points, clamped to the grid, into a span of
// as many), asked once for the whole sample: a terrain whose heights are not held whole (a paged one: gpu_lod.h's
// GpuLodTerrain::gridHeights) gathers them in one pass, so that their cache misses overlap (on the 2-core machine the
// rasterizer evicts the CPU's caches between frames, and the sample's 5 points a cell then cost 100 ns each when
// read one by one between the cells' arithmetic). Its third span (as many): 1 where a height is the grid's own, 0
// where it stands in for it (a paged terrain's overview). Defined in cdlod_sprite_error.cpp, which keeps the sample
// from frame to frame (CdlodSpriteError).
using GridHeightsFn = std::function<void(std::span<const IVec2>, std::span<float>, std::span<uint8_t>)>;
SpriteError spriteError(const CdlodTerrain& lod, const GridHeightsFn& heights, std::span<const CdlodNode> nodes,
                        const Vec3& v1, const Vec3& v2, size_t max_quadrants = 1024);
// A heightfield's heights as GridHeightsFn (each point clamped to the grid, every height its own); hf must outlive it.
GridHeightsFn heightfieldHeights(const Heightfield& hf);

// Equation 2: true when a new keyframe is due (mean theta^2 >= (beta * epsilon)^2). No quadrants: never due.
bool keyframeDue(const SpriteError& error, double beta, double epsilon_pixels);
// Equation 2, or (max_magnification > 0) the sprite magnified by more than max_magnification on average.
bool keyframeDue(const SpriteError& error, double beta, double epsilon_pixels, double max_magnification);

}  // namespace farfield::terrain
