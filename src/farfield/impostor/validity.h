// Validity regions of static impostors: the viewpoints from which an impostor's reprojection error stays under the
// error bound (DESIGN.md, "the two promises"; the lecture's "impostor validity", Schaufler's error angle; Decoret et
// al. 1999, section 4.1, for the events between objects of one impostor).
//
// parallaxBound() bounds the error of anything drawn from a box of the scene (Schaufler's metric made tight); the
// finer triangleErrorBound() follows a meshed impostor's own triangles. Both are closed-form upper bounds of the angle, seen from a new eye, between two
// points of an object that one ray of the capture eye met (one texel of the image, drawn at one depth). It refines
// Schaufler's s (1/d_min - 1/d_max) with the direction of motion (motion along the ray shows no parallax) and with
// the distance from the new eye to the object, and stays a true upper bound for any motion (derivation in the .cpp).
//
// ValidityRegion is what the bake stores per impostor and the runtime tests per frame: in the frame of a street
// cell (origin = the capture eye at the cell's start, axis towards the eye point at its end), a viewpoint is
// (s along the axis, l across it, dz above the eye line). The bake samples `laterals` lines across the street
// (l_i from -half_width to +half_width) and for each keeps the envelope e_i(s) = the largest error angle found at
// along-distances in [-back, s] on that line, over the heights dz in [-below, above]. errorAt() answers with the
// envelope of the two lines around the viewpoint at the first sample at or beyond its s (+infinity outside), so one
// stored region answers for any bound: the impostor is valid for a bound of theta radians where errorAt(eye) <= theta.
#pragma once

#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/image/image.h"
#include "farfield/impostor/impostor_mesh.h"

namespace farfield::impostor {

// Upper bound (radians, capped at pi) of the angle between two points of `box` on one ray from `capture_eye`, seen
// from `eye`. 0 when eye == capture_eye or the box is empty; pi when `eye` or `capture_eye` lies in the box.
double parallaxBound(const Vec3& capture_eye, const Vec3& eye, const Box3& box);

// The error record of one triangle of a meshed impostor drawn with projective texturing (GpuImpostorOptions::
// projective_texture, the default): a fragment at a point X of the triangle shows the texel whose capture ray goes
// through X, so the texel is drawn where its ray meets the triangle (Q) while what it shows lies on the same ray at
// its captured depth (P). The error seen from a new eye is the angle between Q and P: the parallax of two points on
// one capture ray, which depends only on their inverse distances from the capture eye and on the direction of
// motion. Per triangle, over its data texels (texels whose centre lies in its texture-space triangle, with half a
// texel of tolerance):
struct TriangleError {
  Vec3 axis{0.0f, 0.0f, 1.0f};  // unit direction from the capture eye towards the triangle
  float half_angle = 0.0f;      // radians: the directions of its vertices and texels lie within it of axis
  float near_m = 0.0f;          // smallest distance from the capture eye to a vertex, a P or a Q
  float inv_depth_gap = 0.0f;   // largest |1 / |P - E| - 1 / |Q - E||, 1/metres (1 / near_m for a ray that grazes
                                // the triangle's plane)
};
// Records of every triangle (in mesh order). `depth` is the capture's window depth (0 = background) and `camera`
// its camera; the sizes must agree (FF_CHECK).
std::vector<TriangleError> triangleErrors(const DepthMeshImpostor& impostor, const image::DepthImage& depth,
                                          const Camera& camera);
// Upper bound (radians, capped at pi) of the angle between Q and P of any texel of the triangle, seen from `eye`:
// with s = |eye - capture_eye| < near_m and sin(phi) bounded over the cone,
//     s sin(phi)max * inv_depth_gap * (near_m / (near_m - s))^2
// (the integral of s sin(phi) / r^2 along the ray, r >= d - s; derivation in the .cpp). 0 at the capture eye.
double triangleErrorBound(const Vec3& capture_eye, const Vec3& eye, const TriangleError& triangle);

struct ValidityRegion {
  Vec3 origin{0.0f};          // capture eye (the cell's start at eye height)
  Vec3 end{0.0f};             // the eye point at the cell's end (axis = end - origin; its horizontal part is used)
  float half_width = 0.0f;    // |l| <= half_width, metres
  float below = 0.0f;         // dz >= -below, metres (dz from the line origin -> end)
  float above = 0.0f;         // dz <= above
  float back = 0.0f;          // s >= -back, metres
  float step = 1.0f;          // envelope spacing along s, metres (> 0)
  int laterals = 1;           // lines across the street (odd: the centreline is one)
  // laterals rows of samples() values, row i for l_i = half_width (2 i / (laterals - 1) - 1); entry k of a row is
  // the largest error angle (radians, <= pi) for s in [-back, k * step] on that line; rows do not decrease.
  std::vector<float> envelope;

  bool empty() const { return envelope.empty(); }
  size_t samples() const { return laterals > 0 ? envelope.size() / size_t(laterals) : 0; }
  float row(int lateral, size_t k) const { return envelope[size_t(lateral) * samples() + k]; }
  // (s, l, dz) of a viewpoint in the region's frame.
  Vec3 local(const Vec3& eye) const;
  // The error bound at the viewpoint, +infinity outside the sampled region or when the region is empty.
  double errorAt(const Vec3& eye) const;
  bool valid(const Vec3& eye, double bound_rad) const { return errorAt(eye) <= bound_rad; }
  // Largest s (metres) on the centreline with an envelope <= bound_rad, or -infinity when none (for reports).
  double reach(double bound_rad) const;
};

}  // namespace farfield::impostor
