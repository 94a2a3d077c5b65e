// Shade's and Schaufler's validity metrics of planar impostors (steed-ibr-impostors-lecture, part 2, "First metric -
// Shade", "Second metric - Schaufler (I), (II)").
//
// Schaufler's (II) in the view frame of the capture (axis z, eye at z = 0, plane at z = d): a rim point (r, z) with
// z = d -+ r is imaged at lateral r d / z on the plane. From an eye moved to z = m it is seen at atan(r / (z - m)),
// its image at atan(r d / (z (d - m))); the two differ by r m (d - z) / (z (z - m)(d - m)) to first order, which
// grows with |d - z| = r and with r, so the rim of the bounding cylinder at the front or the back is the worst case.
#include "farfield/impostor/validity_metrics.h"

#include <algorithm>
#include <cmath>

namespace farfield::impostor {
namespace {

double angleBetween(const DVec3& a, const DVec3& b) {
  const double la = glm::length(a), lb = glm::length(b);
  if (la <= 0.0 || lb <= 0.0) return 0.0;
  // atan2 of |a x b| and a . b: accurate for the tiny angles the metrics compare with a pixel.
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

}  // namespace

DVec3 imageOnPlane(const DVec3& p, const ImpostorPlane& plane, const DVec3& capture_eye) {
  const DVec3 dir = p - capture_eye;
  const double denom = glm::dot(dir, plane.normal);
  if (std::abs(denom) < 1e-12) return p;
  const double t = glm::dot(plane.point - capture_eye, plane.normal) / denom;
  if (!(t > 0.0) || !std::isfinite(t)) return p;
  return capture_eye + t * dir;
}

double shadePointError(const DVec3& p, const ImpostorPlane& plane, const DVec3& capture_eye, const DVec3& eye) {
  const DVec3 dir = p - capture_eye;
  const double denom = glm::dot(dir, plane.normal);
  const double t = std::abs(denom) < 1e-12 ? -1.0 : glm::dot(plane.point - capture_eye, plane.normal) / denom;
  if (!(t > 0.0) || !std::isfinite(t)) return kPi;
  if (eye == capture_eye) return 0.0;
  const DVec3 q = capture_eye + t * dir;
  return angleBetween(p - eye, q - eye);
}

double shadeError(std::span<const DVec3> points, const ImpostorPlane& plane, const DVec3& capture_eye,
                  const DVec3& eye) {
  double worst = 0.0;
  for (const DVec3& p : points) worst = std::max(worst, shadePointError(p, plane, capture_eye, eye));
  return worst;
}

double schauflerTranslationAngle(const SchauflerObject& object, double translation) {
  const double d = object.distance, r = object.radius, t = std::abs(translation);
  if (!(d > r)) return kPi;
  return std::atan(t / (d - r)) - std::atan(t / (d + r));
}

double schauflerSizeAngle(const SchauflerObject& object, double approach) {
  const double d = object.distance, r = object.radius, m = approach;
  if (!(d > r) || m >= d - r) return kPi;
  double worst = 0.0;
  for (const double z : {d - r, d + r}) {
    const double seen = std::atan(r / (z - m));
    const double imaged = std::atan(r * d / (z * (d - m)));
    worst = std::max(worst, std::abs(seen - imaged));
  }
  return worst;
}

SchauflerAngles schauflerAngles(const DVec3& centre, double radius, const DVec3& capture_eye, const DVec3& eye) {
  const DVec3 axis = centre - capture_eye;
  const double d = glm::length(axis);
  if (!(d > radius)) return {kPi, kPi};
  const DVec3 n = axis / d;
  const DVec3 move = eye - capture_eye;
  const double approach = glm::dot(move, n);
  const double across = glm::length(move - approach * n);
  const SchauflerObject object{d, radius};
  return {schauflerTranslationAngle(object, across), schauflerSizeAngle(object, approach)};
}

}  // namespace farfield::impostor
