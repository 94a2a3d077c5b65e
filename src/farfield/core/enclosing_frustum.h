// View-direction intervals and enclosing frusta (Jeschke et al. 2005, section 3.2, Figure 3-4; Aliaga and Lastra 1999).
//
// A view-direction interval (VDI) is a rectangle [u0,u1] x [v0,v1] on one face of the direction cube: face f has the
// major axis a = f / 2 with sign s = +1 for even f, -1 for odd f (0 +X, 1 -X, 2 +Y, 3 -Y, 4 +Z, 5 -Z), and the
// direction of face point (u, v) is normalize(s * e_a + u * e_(a+1)%3 + v * e_(a+2)%3). Full faces are [-1,1]^2 and
// the six of them cover every direction; quadtree children halve u and v (Figure 4, right).
//
// The enclosing frustum of a box region and a VDI contains every view frustum whose eye is in the region and whose
// view direction is in the VDI, for a camera with the given fov, aspect, near and far plane and any roll (so it also
// holds with Farfield's up = +Z, and for the straight-up and straight-down faces where that up is undefined).
#pragma once

#include <array>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/math.h"

namespace farfield {

struct Vdi {
  int face = 0;  // 0..5
  float u0 = -1.0f, u1 = 1.0f, v0 = -1.0f, v1 = 1.0f;  // -1 <= u0 < u1 <= 1, same for v

  static Vdi fullFace(int face);
  // The face whose major axis dominates `dir` (ties go to the lower axis) and the face coordinates of `dir` on it.
  // `dir` must be non-zero.
  static int faceOf(const Vec3& dir);
  static Vec2 faceCoords(int face, const Vec3& dir);

  // Unit direction of face point (u, v) of this VDI's face.
  Vec3 direction(float u, float v) const;
  Vec3 centerDirection() const { return direction(0.5f * (u0 + u1), 0.5f * (v0 + v1)); }
  // Corner directions in the order (u0,v0), (u1,v0), (u1,v1), (u0,v1): counter-clockwise seen from outside the cube.
  std::array<Vec3, 4> corners() const;
  // dir is in the interval (on this face, within the rectangle up to a small tolerance). dir need not be unit.
  bool contains(const Vec3& dir) const;
  // Quadtree children: (u low, v low), (u high, v low), (u low, v high), (u high, v high).
  std::array<Vdi, 4> split() const;
  // Largest angle (radians) between the centre direction and a corner direction.
  float angularRadius() const;
};

// Camera lens for enclosing frusta: fov_y (radians), aspect (width / height), near and far plane (metres).
struct Lens {
  float fov_y = float(degToRad(60.0));
  float aspect = 1.0f;
  float near_plane = 0.5f;
  float far_plane = 20000.0f;

  static Lens fromCamera(const Camera& camera);
  // Half-angle of the cone around the view axis that holds the whole view frustum for any roll: the angle of the
  // image corner, atan(sqrt(tan(fov_y/2)^2 + tan(fov_x/2)^2)).
  float halfDiagonal() const;
  // Throws farfield::Error naming `what` for fov outside (0, pi), aspect <= 0 or not 0 < near < far.
  void validate(const char* what = "lens") const;
};

// The enclosing frustum as six planes in Frustum's convention (inside: dot(n, p) + d >= 0). Planes 0..3 bound the
// directions beyond the VDI edges u0, u1, v0, v1, plane 4 is the far plane and plane 5 the near plane, all
// perpendicular-ish to the VDI's centre direction. Conservative: every point of every enclosed view frustum is
// inside (up to float rounding of about 1e-6 of the far distance). Throws farfield::Error for an empty or non-finite
// region, a VDI with a face outside 0..5 or a rectangle outside [-1,1]^2, or a bad lens.
Frustum enclosingFrustum(const Box3& region, const Vdi& vdi, const Lens& lens);

// Conservative box test against an enclosing frustum: false only when the box is certainly outside
// (Frustum::intersects; provided here for discoverability).
inline bool mayIntersect(const Frustum& frustum, const Box3& box) { return frustum.intersects(box); }
// Every point of the box is inside every plane.
bool containsBox(const Frustum& frustum, const Box3& box);

}  // namespace farfield
