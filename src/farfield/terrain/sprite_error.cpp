// LOD-sprite error metric, Chen et al. 1999 section 3.2, equations 1-2.
#include "farfield/terrain/sprite_error.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace farfield::terrain {
namespace {

// Is q (in xy) inside triangle (a, b, c) (either orientation), with a relative tolerance?
bool insideXY(const DVec3& q, const DVec3& a, const DVec3& b, const DVec3& c) {
  const DVec2 p(q), pa(a), pb(b), pc(c);
  const double area = cross2(pb - pa, pc - pa);
  if (std::abs(area) < 1e-12) return false;
  const double s = area > 0 ? 1.0 : -1.0;
  const double eps = -1e-9 * std::abs(area);
  return s * cross2(pb - pa, p - pa) >= eps && s * cross2(pc - pb, p - pb) >= eps && s * cross2(pa - pc, p - pc) >= eps;
}

// Ray v1 + t * dir against the plane through (p0, p1, p2); false when parallel (|cos| under 1e-12, compared in
// squares: dir_sq is the squared length of dir).
bool rayPlane(const DVec3& v1, const DVec3& dir, double dir_sq, const DVec3& p0, const DVec3& p1, const DVec3& p2,
              double& t) {
  const DVec3 n = glm::cross(p1 - p0, p2 - p0);
  const double denom = glm::dot(n, dir);
  if (denom * denom < 1e-24 * glm::dot(n, n) * dir_sq) return false;
  t = glm::dot(n, p0 - v1) / denom;
  return std::isfinite(t);
}

}  // namespace

bool spriteProjection(const DVec3& c, std::span<const DVec3> corners, const DVec3& v1, DVec3& c_prime, bool near) {
  const size_t n = corners.size();
  if (n < 3) return false;
  const DVec3 dir = c - v1;
  const double dir_sq = glm::dot(dir, dir);
  if (!(dir_sq > 0.0)) return false;
  // C^: the low-resolution surface above the quadrant's centre.
  DVec3 centre(0.0);
  if (n == 4) {
    for (const DVec3& q : corners) centre += q;
    centre /= 4.0;
  } else {
    // Boundary diamond: the corner pair whose midpoint lies at C's xy.
    double best = std::numeric_limits<double>::max();
    for (size_t k = 0; k < n; ++k) {
      const DVec3 mid = 0.5 * (corners[k] + corners[(k + 1) % n]);
      const double dxy = glm::length(DVec2(mid) - DVec2(c));
      if (dxy < best) best = dxy, centre = mid;
    }
  }
  // Fan triangles (C^, Q_k, Q_k+1), skipping degenerate ones (the boundary edge through C^), and the plane of each.
  auto fanPlane = [&](size_t k, double& t) {
    const DVec3& a = corners[k];
    const DVec3& b = corners[(k + 1) % n];
    return std::abs(cross2(DVec2(a) - DVec2(centre), DVec2(b) - DVec2(centre))) >= 1e-9 &&
           rayPlane(v1, dir, dir_sq, centre, a, b, t);
  };
  // The nearest one the ray meets inside it (a cell's C' is made once per keyframe, but for every sampled cell of a
  // new one: 850 a measure).
  double best_t = std::numeric_limits<double>::max();
  bool hit = false;
  for (size_t k = 0; k < n; ++k) {
    double t = 0.0;
    if (fanPlane(k, t) && t > 0.0 && t < best_t && insideXY(v1 + t * dir, centre, corners[k], corners[(k + 1) % n])) {
      best_t = t;
      hit = true;
    }
  }
  if (hit) {
    c_prime = v1 + best_t * dir;
    return true;
  }
  // Fallback (rare: the planes are made again): the fan triangle whose direction from C^ best matches the ray's xy
  // direction (forward when C lies above C^, backward otherwise), if its plane lies ahead of v1.
  double fallback_t = 0.0;
  bool have_fallback = false;
  double fallback_score = -std::numeric_limits<double>::max();
  const DVec2 ray_xy = DVec2(dir);
  const double ray_xy_len = glm::length(ray_xy);
  const bool above = c.z > centre.z;
  for (size_t k = 0; k < n; ++k) {
    double t = 0.0;
    if (!fanPlane(k, t)) continue;
    const DVec2 towards = 0.5 * (DVec2(corners[k]) + DVec2(corners[(k + 1) % n])) - DVec2(centre);
    const double score = ray_xy_len > 0.0 ? glm::dot(glm::normalize(towards), ray_xy / ray_xy_len) * (above ? 1 : -1)
                                          : 0.0;
    if (t > 0.0 && score > fallback_score) {
      fallback_score = score;
      fallback_t = t;
      have_fallback = true;
    }
  }
  if (!have_fallback) return false;
  if (!near) {
    c_prime = v1 + fallback_t * dir;
    return true;
  }
  // The fallback plane is met where it extends beyond the quadrant; a ray that grazes it meets it arbitrarily far
  // away, even next to v1 (a cell 4 km from the eye in the CDLOD test had C' near v1, theta 3 rad: the whole of a
  // mean over 6,400 cells). The sprite shows C on the low surface past the quadrant, which the quadrant's plane does
  // not describe that far: C' is kept within the quadrant's neighbourhood, its xy box grown by its own size on every
  // side (C, at t = 1, lies inside it), where the ray leaves that.
  DVec2 lo(corners[0]), hi(corners[0]);
  for (const DVec3& q : corners) lo = glm::min(lo, DVec2(q)), hi = glm::max(hi, DVec2(q));
  const DVec2 size = hi - lo;
  lo -= size;
  hi += size;
  double t_lo = -std::numeric_limits<double>::max(), t_hi = std::numeric_limits<double>::max();
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(dir[axis]) < 1e-12) continue;
    const double a = (lo[axis] - v1[axis]) / dir[axis], b = (hi[axis] - v1[axis]) / dir[axis];
    t_lo = std::max(t_lo, std::min(a, b));
    t_hi = std::min(t_hi, std::max(a, b));
  }
  if (t_lo <= 1.0 && 1.0 <= t_hi) fallback_t = std::clamp(fallback_t, std::max(t_lo, 0.0), t_hi);
  c_prime = v1 + fallback_t * dir;
  return true;
}

double quadrantTheta(const DVec3& c, std::span<const DVec3> corners, const DVec3& v1, const DVec3& v2, bool* ok,
                     bool near) {
  DVec3 c_prime;
  const bool good = spriteProjection(c, corners, v1, c_prime, near);
  if (ok) *ok = good;
  if (!good) return 0.0;
  return spriteTheta(c, c_prime, v2);
}

double spriteTheta(const DVec3& c, const DVec3& c_prime, const DVec3& v2) {
  const DVec3 a = c - v2, b = c_prime - v2;
  const double sine = glm::length(glm::cross(a, b)), cosine = glm::dot(a, b);
  // The metric's angles are a few pixels (thousandths of a radian): there atan's series to t^11 is exact to the last
  // bit of a double (the first term left out, t^13 / 13, is under 2e-16 t for t < 1/16) and a third of atan2's cost,
  // which was a tenth of a measure over 850 cells.
  if (cosine > 0.0 && sine < 0.0625 * cosine) {
    const double t = sine / cosine, t2 = t * t;
    return t * (1.0 - t2 * (1.0 / 3.0 - t2 * (1.0 / 5.0 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0 - t2 / 11.0)))));
  }
  return std::atan2(sine, cosine);
}

double spriteMagnification(const DVec3& c, const DVec3& v1, const DVec3& v2) {
  const double near = glm::length(c - v2);
  return near > 1e-9 ? glm::length(c - v1) / near : 1.0;
}

double pixelAngle(const Camera& camera) { return double(camera.fovX()) / double(camera.width); }

SpriteError spriteError(const QuadtreeLod& lod, std::span<const LodQuadrant> quadrants, const Vec3& v1,
                        const Vec3& v2) {
  SpriteError e;
  double sum = 0.0, stretch = 0.0;
  DVec3 corners[4];
  for (const LodQuadrant& q : quadrants) {
    for (int k = 0; k < q.corner_count; ++k) corners[k] = DVec3(lod.position(q.corners[size_t(k)]));
    bool ok = false;
    const DVec3 c(lod.position(q.centre));
    const double theta =
        quadrantTheta(c, std::span<const DVec3>(corners, q.corner_count), DVec3(v1), DVec3(v2), &ok);
    if (!ok) {
      ++e.skipped;
      continue;
    }
    sum += theta * theta;
    stretch += spriteMagnification(c, DVec3(v1), DVec3(v2));
    e.max_theta = std::max(e.max_theta, theta);
    ++e.quadrants;
  }
  e.mean_theta_sq = e.quadrants ? sum / double(e.quadrants) : 0.0;
  e.mean_magnification = e.quadrants ? stretch / double(e.quadrants) : 1.0;
  return e;
}

bool keyframeDue(const SpriteError& error, double beta, double epsilon_pixels, double max_magnification) {
  return keyframeDue(error, beta, epsilon_pixels) ||
         (max_magnification > 0.0 && error.quadrants > 0 && error.mean_magnification > max_magnification);
}

bool keyframeDue(const SpriteError& error, double beta, double epsilon_pixels) {
  if (error.quadrants == 0) return false;
  const double limit = beta * epsilon_pixels;
  return error.mean_theta_sq >= limit * limit;
}

}  // namespace farfield::terrain
