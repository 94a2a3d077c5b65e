// Choosing the best impostor plane (steed-ibr-impostors-lecture, part 2, "Choosing the best impostor plane").
//
// With the plane through the centroid c and unit normal n, the mean squared distance is n^T C n (C the samples'
// covariance): a quadratic form on the sphere, smallest at C's smallest eigenvector (Jacobi rotations below). When
// that vector leaves the cone around the view direction v, the form has no other minimum inside the cone (its only
// stationary points are the eigenvectors, and a larger-eigenvalue one is a saddle or maximum there), so the best
// allowed normal lies on the rim: n(phi) = cos(tilt) v + sin(tilt) (cos(phi) a + sin(phi) b), a trigonometric
// quadratic in phi, minimised by a dense scan refined by golden sections.
#include "farfield/impostor/best_plane.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

using Sym3 = std::array<std::array<double, 3>, 3>;

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations; returns the eigenvector of the smallest
// eigenvalue.
DVec3 smallestEigenvector(Sym3 a) {
  Sym3 v{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    if (off < 1e-30) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (std::abs(a[p][q]) < 1e-300) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (a[i][i] < a[best][best]) best = i;
  return glm::normalize(DVec3(v[0][best], v[1][best], v[2][best]));
}

DVec3 centroidOf(std::span<const DVec3> points) {
  DVec3 c(0.0);
  for (const DVec3& p : points) c += p;
  return c / double(points.size());
}

}  // namespace

double meanSquaredDistance(std::span<const DVec3> points, const DVec3& n) {
  if (points.empty()) return 0.0;
  const DVec3 c = centroidOf(points);
  double sum = 0.0;
  for (const DVec3& p : points) sum += glm::dot(p - c, n) * glm::dot(p - c, n);
  return sum / double(points.size());
}

BestPlane bestPlane(std::span<const DVec3> points, const DVec3& capture_eye, double max_tilt) {
  if (points.empty()) throw Error("bestPlane", "no sample points");
  for (size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z))
      throw Error("bestPlane", "sample point " + std::to_string(i) + " is not finite");
  if (!(max_tilt >= 0.0 && max_tilt <= kPi / 2))
    throw Error("bestPlane", "max_tilt " + std::to_string(max_tilt) + " outside 0..pi/2");
  const DVec3 c = centroidOf(points);
  const double view_len = glm::length(capture_eye - c);
  if (!(view_len > 0.0)) throw Error("bestPlane", "the capture eye is at the samples' centroid");
  const DVec3 v = (capture_eye - c) / view_len;

  Sym3 cov{};
  for (const DVec3& p : points) {
    const DVec3 d = p - c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) cov[i][j] += d[i] * d[j];
  }
  DVec3 n = smallestEigenvector(cov);
  if (glm::dot(n, v) < 0.0) n = -n;
  const double cos_tilt = std::cos(max_tilt);
  if (glm::dot(n, v) < cos_tilt - 1e-12) {
    // The rim of the cone: an orthonormal frame (v, a, b).
    const DVec3 a = glm::normalize(glm::cross(v, std::abs(v.z) < 0.9 ? DVec3(0, 0, 1) : DVec3(1, 0, 0)));
    const DVec3 b = glm::cross(v, a);
    const double sin_tilt = std::sin(max_tilt);
    auto rim = [&](double phi) { return cos_tilt * v + sin_tilt * (std::cos(phi) * a + std::sin(phi) * b); };
    auto cost = [&](double phi) {
      const DVec3 m = rim(phi);
      double s = 0.0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s += m[i] * cov[i][j] * m[j];
      return s;
    };
    constexpr int kScan = 360;
    int best = 0;
    for (int i = 1; i < kScan; ++i)
      if (cost(2 * kPi * i / kScan) < cost(2 * kPi * best / kScan)) best = i;
    double lo = 2 * kPi * (best - 1) / kScan, hi = 2 * kPi * (best + 1) / kScan;
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int it = 0; it < 60; ++it) {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (cost(x1) < cost(x2)) hi = x2; else lo = x1;
    }
    n = glm::normalize(rim(0.5 * (lo + hi)));
  }
  BestPlane out;
  out.plane.point = c;
  out.plane.normal = n;
  double sum = 0.0;
  for (const DVec3& p : points) {
    const double dist = std::abs(glm::dot(p - c, n));
    sum += dist * dist;
    out.max_distance = std::max(out.max_distance, dist);
  }
  out.rms_distance = std::sqrt(sum / double(points.size()));
  return out;
}

}  // namespace farfield::impostor
