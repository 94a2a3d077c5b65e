#include "farfield/impostor/validity.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/camera.h"
#include "farfield/core/check.h"

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

std::vector<TriangleError> triangleErrors(const DepthMeshImpostor& impostor, const image::DepthImage& depth,
                                          const Camera& camera) {
  FF_CHECK(depth.width() == camera.width && depth.height() == camera.height);
  const scene::Mesh& mesh = impostor.mesh;
  const int w = depth.width(), h = depth.height();
  // The capture camera's basis, once (Camera::unproject inverts the view matrix per call).
  const DVec3 e(camera.eye);
  const DVec3 forward = glm::normalize(DVec3(camera.at) - e);
  const DVec3 right = glm::normalize(glm::cross(forward, DVec3(camera.up)));
  const DVec3 up = glm::cross(right, forward);
  const double tan_y = std::tan(0.5 * double(camera.fov_y)), tan_x = tan_y * double(w) / double(h);
  auto ray = [&](double px, double py) {  // unit direction through image point (px, py), row 0 at the top
    return glm::normalize(forward + (2.0 * px / w - 1.0) * tan_x * right + (1.0 - 2.0 * py / h) * tan_y * up);
  };
  std::vector<TriangleError> out;
  out.reserve(mesh.triangleCount());
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    DVec3 x[3];
    DVec2 uv[3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = mesh.indices[3 * t + size_t(k)];
      x[k] = DVec3(mesh.positions[i]);
      uv[k] = DVec2(double(mesh.uvs[i].x) * w, double(mesh.uvs[i].y) * h);  // texels
    }
    const DVec3 normal = glm::cross(x[1] - x[0], x[2] - x[0]);
    const double plane = glm::dot(normal, x[0] - e);
    std::vector<DVec3> directions;
    double near = std::numeric_limits<double>::infinity(), gap = 0.0;
    for (const DVec3& v : x) {
      near = std::min(near, glm::length(v - e));
      directions.push_back(glm::normalize(v - e));
    }
    const double area = (uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (uv[1].y - uv[0].y);
    const double sign = area >= 0.0 ? 1.0 : -1.0;
    auto inside = [&](const DVec2& p) {
      for (int k = 0; k < 3; ++k) {
        const DVec2 a = uv[k], edge = uv[(k + 1) % 3] - a;
        if (sign * (edge.x * (p.y - a.y) - edge.y * (p.x - a.x)) < -0.75 * glm::length(edge)) return false;
      }
      return true;
    };
    const int x0 = std::max(0, int(std::floor(std::min({uv[0].x, uv[1].x, uv[2].x}) - 1.0)));
    const int x1 = std::min(w - 1, int(std::ceil(std::max({uv[0].x, uv[1].x, uv[2].x}))));
    const int y0 = std::max(0, int(std::floor(std::min({uv[0].y, uv[1].y, uv[2].y}) - 1.0)));
    const int y1 = std::min(h - 1, int(std::ceil(std::max({uv[0].y, uv[1].y, uv[2].y}))));
    for (int py = y0; py <= y1; ++py)
      for (int px = x0; px <= x1; ++px) {
        const float z = depth.at(px, py);
        if (!(z > 0.0f) || !inside(DVec2(px + 0.5, py + 0.5))) continue;
        const DVec3 u = ray(px + 0.5, py + 0.5);
        directions.push_back(u);
        // P: the captured point (linear depth is along the view axis); Q: the ray meets the triangle's plane.
        const double p_dist = double(camera.linearDepth(z)) / glm::dot(u, forward);
        const double un = glm::dot(u, normal);
        const double q_dist = un != 0.0 ? plane / un : -1.0;
        near = std::min(near, p_dist);
        if (q_dist > 0.0) {
          near = std::min(near, q_dist);
          gap = std::max(gap, std::abs(1.0 / p_dist - 1.0 / q_dist));
        } else {
          gap = std::numeric_limits<double>::infinity();  // the ray misses the plane: anything can be drawn there
        }
      }
    TriangleError r;
    DVec3 axis(0.0);
    for (const DVec3& d : directions) axis += d;
    axis = glm::length(axis) > 0.0 ? glm::normalize(axis) : forward;
    double half_angle = 0.0;
    for (const DVec3& d : directions) half_angle = std::max(half_angle, std::acos(std::clamp(glm::dot(d, axis), -1.0, 1.0)));
    r.axis = Vec3(axis);
    r.half_angle = float(half_angle) * 1.0001f + 1e-6f;
    r.near_m = float(near) * 0.9999f;
    r.inv_depth_gap = std::isfinite(gap) ? float(gap) * 1.0001f + 1e-7f : float(1.0 / std::max(near, 1e-6));
    out.push_back(r);
  }
  return out;
}

// The chord [Q, P] lies on one capture ray at distances d1 < d2 >= near_m; seen from eye = E + t (|t| = s) it
// subtends at most the integral over [d1, d2] of s sin(phi) / r(d)^2 with r(d) >= d - s (as in parallaxBound), which
// is (d2 - d1) / ((d1 - s)(d2 - s)) = (1/d1 - 1/d2) * d1 d2 / ((d1 - s)(d2 - s)) <= gap * (near / (near - s))^2.
// A ray that misses the triangle's plane gets gap = 1 / near (P anywhere beyond near on it): the chord to infinity.
double triangleErrorBound(const Vec3& capture_eye, const Vec3& eye, const TriangleError& triangle) {
  const DVec3 t = DVec3(eye) - DVec3(capture_eye);
  const double s = glm::length(t);
  if (s == 0.0) return 0.0;
  const double near = double(triangle.near_m);
  if (s >= near) return kPi;
  const double phi_c = std::acos(std::clamp(glm::dot(t / s, DVec3(triangle.axis)), -1.0, 1.0));
  const double sin_max = maxSin(phi_c - double(triangle.half_angle), phi_c + double(triangle.half_angle));
  const double k = near / (near - s);
  return std::min(kPi, s * sin_max * double(triangle.inv_depth_gap) * k * k);
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
