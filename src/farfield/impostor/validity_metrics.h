// The lecture's two validity metrics of a planar impostor (steed-ibr-impostors-lecture, part 2: "First metric -
// Shade" and "Second metric - Schaufler (I) and (II)"), each a function of its own, for the dynamic image cache
// (impostor/dynamic.h) and the bench that compares them.
//
// A planar impostor is an image captured from `capture_eye` and drawn on a plane: a point P of the object is shown
// where the capture ray through P meets the plane (its image Q). From a moved eye the image is wrong by the angle
// between P and Q.
//
// Shade et al. 1996: the largest such angle over given points of the object (their bounding-box corners, or
// vertices). Exact for the points given; it says nothing about points between them.
// Schaufler 1995: two worst cases of a bounding sphere (radius r, centre at distance d from the capture eye), the
// plane through its centre facing the capture eye: (I) translation of the eye parallel to the plane moves the front
// and the back of the object on one capture ray apart; (II) motion towards the object (or away) changes the size of
// the front and the back differently from the plane's. The image is used while both angles stay below the angle of
// one pixel (alpha_screen; here the error bound's angle).
#pragma once

#include <span>

#include "farfield/core/math.h"

namespace farfield::impostor {

// The plane an impostor image is drawn on: a point of it and its unit normal (turned towards the capture eye).
struct ImpostorPlane {
  DVec3 point{0.0};
  DVec3 normal{0.0, 0.0, 1.0};
};

// Where the ray from `capture_eye` through `p` meets the plane (Q). Returns p itself when the ray is parallel to the
// plane or meets it behind the eye (the point cannot be imaged; shadePointError then reports pi).
DVec3 imageOnPlane(const DVec3& p, const ImpostorPlane& plane, const DVec3& capture_eye);

// Shade: the angle (radians, 0..pi), seen from `eye`, between p and its image on the plane. pi when p cannot be
// imaged from the capture eye (ray parallel to the plane or meeting it behind the eye); 0 when eye == capture_eye.
double shadePointError(const DVec3& p, const ImpostorPlane& plane, const DVec3& capture_eye, const DVec3& eye);
// Shade: the largest shadePointError over the points (0 for none).
double shadeError(std::span<const DVec3> points, const ImpostorPlane& plane, const DVec3& capture_eye,
                  const DVec3& eye);

// Schaufler's object: a bounding sphere seen from the capture eye at centre distance `distance` (> radius).
struct SchauflerObject {
  double distance = 1.0;  // d: capture eye to the sphere's centre, metres
  double radius = 0.0;    // r: metres
};
// (I) The angle between the front (distance d - r) and the back (d + r) of the object on the central capture ray,
// seen from an eye moved by `translation` metres parallel to the plane: atan(t / (d - r)) - atan(t / (d + r)).
double schauflerTranslationAngle(const SchauflerObject& object, double translation);
// (II) The largest angle between a rim point of the object's bounding cylinder (lateral r, at depth d - r or d + r)
// and its image on the plane at depth d, seen from an eye moved `approach` metres towards the object along the
// capture axis (negative: away). pi when the eye reaches the front (approach >= d - r).
double schauflerSizeAngle(const SchauflerObject& object, double approach);

struct SchauflerAngles {
  double translation = 0.0;  // alpha_trans, radians
  double size = 0.0;         // alpha_size, radians
  double worst() const { return translation > size ? translation : size; }
  // Schaufler's test: use the impostor while both stay below alpha_screen.
  bool valid(double alpha_screen) const { return translation < alpha_screen && size < alpha_screen; }
};
// Both angles for an impostor of the sphere (centre, radius) captured from capture_eye and seen from eye: the eye's
// displacement split into its part along the capture axis (towards the centre) and across it. pi for both when the
// capture eye is inside the sphere.
SchauflerAngles schauflerAngles(const DVec3& centre, double radius, const DVec3& capture_eye, const DVec3& eye);

}  // namespace farfield::impostor
