#include "farfield/impostor/validity.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace farfield::impostor {

namespace {

// Largest sin(phi) over phi in [lo, hi] (clamped to [0, pi]).
double maxSin(double lo, double hi) {
  lo = std::max(lo, 0.0);
  hi = std::min(hi, kPi);
  if (lo > hi) return 0.0;
  if (lo <= 0.5 * kPi && hi >= 0.5 * kPi) return 1.0;
  return std::max(std::sin(lo), std::sin(hi));
}

}  // namespace

// A point X(d) = E + d u on a capture ray (unit u) seen from V = E + t, |t| = s: its direction from V turns at
// |(X - V) x u| / |X - V|^2 = s sin(phi) / r(d)^2 per metre of d, phi the angle between t and u, r(d) = |X(d) - V|.
// The angle between X(d1) and X(d2) is at most the integral of that over [d1, d2]. Three bounds make it closed:
//   - d1, d2 lie in [d_min, d_max], the distances from E to the box;
//   - sin(phi) <= its largest value over the cone of rays from E into the box (axis towards the box centre,
//     half-angle asin(R / |c - E|) with R the box's half diagonal);
//   - r(d) >= max(r_box, d - s): X(d) is in the box, at least r_box = dist(V, box) from V, and |d u - t| >= d - s.
// With d* = r_box + s the integral of 1 / max(r_box, d - s)^2 over [d_min, d_max] is
//   (min(d*, d_max) - d_min)+ / r_box^2  +  (1 / (max(d*, d_min) - s) - 1 / (d_max - s))  when d_max > d*.
double parallaxBound(const Vec3& capture_eye, const Vec3& eye, const Box3& box) {
  if (box.empty()) return 0.0;
  const DVec3 e(capture_eye), v(eye);
  const DVec3 t = v - e;
  const double s = glm::length(t);
  if (s == 0.0) return 0.0;
  const DVec3 lo(box.lo), hi(box.hi);
  auto distance_to_box = [&](const DVec3& p) { return glm::length(glm::max(glm::max(lo - p, p - hi), DVec3(0.0))); };
  const double d_min = distance_to_box(e);
  const double r_box = distance_to_box(v);
  if (d_min <= 0.0 || r_box <= 0.0) return kPi;
  const double d_max = glm::length(glm::max(glm::abs(lo - e), glm::abs(hi - e)));

  const DVec3 centre = 0.5 * (lo + hi);
  const double radius = 0.5 * glm::length(hi - lo);
  const double to_centre = glm::length(centre - e);
  double sin_max = 1.0;
  if (to_centre > radius) {
    const double half_angle = std::asin(radius / to_centre);
    const double phi_c = std::acos(std::clamp(glm::dot(t / s, (centre - e) / to_centre), -1.0, 1.0));
    sin_max = maxSin(phi_c - half_angle, phi_c + half_angle);
  }
  const double d_star = r_box + s;
  double integral = std::max(0.0, std::min(d_star, d_max) - d_min) / (r_box * r_box);
  if (d_max > d_star) integral += 1.0 / (std::max(d_star, d_min) - s) - 1.0 / (d_max - s);
  return std::min(kPi, s * sin_max * integral);
}

Vec3 ValidityRegion::local(const Vec3& eye) const {
  const DVec3 o(origin), d = DVec3(eye) - o;
  DVec2 axis(double(end.x) - o.x, double(end.y) - o.y);
  const double length = glm::length(axis);
  axis = length > 0.0 ? axis / length : DVec2(1.0, 0.0);
  const double s = d.x * axis.x + d.y * axis.y;
  const double l = -d.x * axis.y + d.y * axis.x;
  const double slope = length > 0.0 ? (double(end.z) - o.z) / length : 0.0;
  return Vec3(float(s), float(l), float(d.z - slope * s));
}

double ValidityRegion::errorAt(const Vec3& eye) const {
  constexpr double kOutside = std::numeric_limits<double>::infinity();
  const size_t n = samples();
  if (n == 0 || !(step > 0.0f) || laterals < 1 || envelope.size() != n * size_t(laterals)) return kOutside;
  const Vec3 p = local(eye);
  if (!(p.x >= -back) || !(std::abs(p.y) <= half_width) || !(p.z >= -below) || !(p.z <= above)) return kOutside;
  const double k = std::ceil(double(std::max(p.x, 0.0f)) / double(step));
  if (k >= double(n)) return kOutside;
  if (laterals == 1) return double(row(0, size_t(k)));
  // The two sampled lines around l (one when l is on a line).
  const double spacing = 2.0 * double(half_width) / double(laterals - 1);
  const double at = spacing > 0.0 ? (double(p.y) + double(half_width)) / spacing : 0.5 * double(laterals - 1);
  const int lo = std::clamp(int(std::floor(at)), 0, laterals - 1);
  const int hi = std::clamp(int(std::ceil(at)), 0, laterals - 1);
  return double(std::max(row(lo, size_t(k)), row(hi, size_t(k))));
}

double ValidityRegion::reach(double bound_rad) const {
  double best = -std::numeric_limits<double>::infinity();
  if (laterals < 1 || envelope.size() != samples() * size_t(laterals)) return best;
  for (size_t k = 0; k < samples() && double(row(laterals / 2, k)) <= bound_rad; ++k) best = double(k) * double(step);
  return best;
}

}  // namespace farfield::impostor
