// View-direction intervals and enclosing frusta (Jeschke et al. 2005, section 3.2; Aliaga and Lastra 1999).
//
// Why this construction: the union of the enclosed view frusta is bounded by cones, not planes, so the plane
// normals are chosen for tightness and each plane's offset is then computed conservatively. Every enclosed view
// frustum, for any roll, lies in the cone of half-angle rho (the lens's half-diagonal) around its view direction and
// between distances near and far / cos(rho) from its eye. So for a unit normal n the smallest value of n . p over all
// enclosed frusta is at least
//   min over eyes in the box of n . eye   (a box corner)
// + (m >= 0 ? near * m : (far / cos rho) * m),  m = cos(min(pi, theta + rho)),  theta = max angle from n to the VDI
// where theta is found exactly on the VDI's spherical quadrilateral (great-circle edges; the interior only matters
// when -n lies in it). The side normals are tilted out from the VDI edges so that the rho-caps around both corners
// of an edge just touch the plane (m = 0 when nothing else sticks out), which keeps the far points from widening
// the offset; the near and far planes face along the VDI's centre direction.
#include "farfield/core/enclosing_frustum.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield {

namespace {

int majorAxis(int face) { return face / 2; }
float faceSign(int face) { return (face % 2 == 0) ? 1.0f : -1.0f; }

// Smallest n . c over the great-circle arc from unit a to unit b (shorter than pi).
double arcMin(const DVec3& n, const DVec3& a, const DVec3& b) {
  const double fa = glm::dot(n, a), fb = glm::dot(n, b);
  const DVec3 w_raw = b - glm::dot(a, b) * a;
  const double w_len = glm::length(w_raw);
  if (w_len < 1e-12) return std::min(fa, fb);
  const DVec3 w = w_raw / w_len;
  const double arc = std::atan2(w_len, glm::dot(a, b));
  const double fw = glm::dot(n, w);
  // f(t) = fa cos t + fw sin t is smallest at t = atan2(fw, fa) + pi.
  double t_min = std::atan2(fw, fa) + kPi;
  if (t_min >= 2.0 * kPi) t_min -= 2.0 * kPi;
  if (t_min <= arc) return -std::sqrt(fa * fa + fw * fw);
  return std::min(fa, fb);
}

}  // namespace

Vdi Vdi::fullFace(int face) { return Vdi{face, -1.0f, 1.0f, -1.0f, 1.0f}; }

int Vdi::faceOf(const Vec3& dir) {
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(dir[i]) > std::abs(dir[axis])) axis = i;
  return 2 * axis + (dir[axis] < 0.0f ? 1 : 0);
}

Vec2 Vdi::faceCoords(int face, const Vec3& dir) {
  const int a = majorAxis(face);
  const float m = faceSign(face) * dir[a];
  return Vec2(dir[(a + 1) % 3] / m, dir[(a + 2) % 3] / m);
}

Vec3 Vdi::direction(float u, float v) const {
  const int a = majorAxis(face);
  Vec3 d(0.0f);
  d[a] = faceSign(face);
  d[(a + 1) % 3] = u;
  d[(a + 2) % 3] = v;
  return glm::normalize(d);
}

std::array<Vec3, 4> Vdi::corners() const {
  return {direction(u0, v0), direction(u1, v0), direction(u1, v1), direction(u0, v1)};
}

bool Vdi::contains(const Vec3& dir) const {
  const int a = majorAxis(face);
  const float m = faceSign(face) * dir[a];
  if (!(m > 0.0f)) return false;
  const float u = dir[(a + 1) % 3] / m, v = dir[(a + 2) % 3] / m;
  const float eps = 1e-6f;
  return u >= u0 - eps && u <= u1 + eps && v >= v0 - eps && v <= v1 + eps;
}

std::array<Vdi, 4> Vdi::split() const {
  const float um = 0.5f * (u0 + u1), vm = 0.5f * (v0 + v1);
  return {Vdi{face, u0, um, v0, vm}, Vdi{face, um, u1, v0, vm}, Vdi{face, u0, um, vm, v1}, Vdi{face, um, u1, vm, v1}};
}

float Vdi::angularRadius() const {
  const Vec3 c = centerDirection();
  float r = 0.0f;
  for (const Vec3& k : corners()) r = std::max(r, std::acos(std::clamp(glm::dot(c, k), -1.0f, 1.0f)));
  return r;
}

Lens Lens::fromCamera(const Camera& camera) {
  return Lens{camera.fov_y, camera.aspect(), camera.near_plane, camera.far_plane};
}

float Lens::halfDiagonal() const {
  const double ty = std::tan(0.5 * double(fov_y));
  const double tx = ty * double(aspect);
  return float(std::atan(std::sqrt(tx * tx + ty * ty)));
}

void Lens::validate(const char* what) const {
  if (!(fov_y > 0.0f && fov_y < float(kPi))) throw Error(what, "field of view must be between 0 and 180 degrees");
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) throw Error(what, "aspect must be > 0");
  if (!(near_plane > 0.0f && far_plane > near_plane) || !std::isfinite(far_plane))
    throw Error(what, "need 0 < near < far (finite)");
  if (!(halfDiagonal() < 0.5f * float(kPi) - 1e-4f)) throw Error(what, "field of view too wide");
}

Frustum enclosingFrustum(const Box3& region, const Vdi& vdi, const Lens& lens) {
  if (region.empty() || !isFinite(region.lo) || !isFinite(region.hi))
    throw Error("enclosing frustum", "the view region is empty or not finite");
  if (vdi.face < 0 || vdi.face > 5) throw Error("enclosing frustum", "VDI face " + std::to_string(vdi.face) + " not in 0..5");
  if (!(vdi.u0 >= -1.0f && vdi.u0 < vdi.u1 && vdi.u1 <= 1.0f && vdi.v0 >= -1.0f && vdi.v0 < vdi.v1 && vdi.v1 <= 1.0f))
    throw Error("enclosing frustum", "VDI rectangle must lie in [-1,1]^2 with u0 < u1 and v0 < v1");
  lens.validate("enclosing frustum lens");

  const double rho = lens.halfDiagonal();
  const double reach = double(lens.far_plane) / std::cos(rho);
  const std::array<Vec3, 4> cf = vdi.corners();
  std::array<DVec3, 4> c;
  for (int k = 0; k < 4; ++k) c[size_t(k)] = DVec3(cf[size_t(k)]);
  const DVec3 center(vdi.centerDirection());

  // Plane with inward unit normal n, offset from the exact bound described in the file comment.
  auto plane = [&](DVec3 n) {
    n = glm::normalize(n);
    double c_min = 1.0;
    if (vdi.contains(Vec3(-n))) {
      c_min = -1.0;
    } else {
      for (int k = 0; k < 4; ++k) c_min = std::min(c_min, arcMin(n, c[size_t(k)], c[size_t((k + 1) % 4)]));
    }
    const double theta = std::acos(std::clamp(c_min, -1.0, 1.0)) + rho;
    const double m = theta >= kPi ? -1.0 : std::cos(theta);
    const double q_min = m >= 0.0 ? double(lens.near_plane) * m : reach * m;
    double box_min = 0.0, box_abs = 0.0;
    for (int i = 0; i < 3; ++i) {
      box_min += n[i] * double(n[i] >= 0.0 ? region.lo[i] : region.hi[i]);
      box_abs += std::abs(n[i]) * std::max(std::abs(double(region.lo[i])), std::abs(double(region.hi[i])));
    }
    // A margin for float rounding of the caller's points and of the stored plane.
    const double h = box_min + q_min - 1e-6 * (reach + box_abs) - 1e-6;
    return Vec4(Vec3(n), float(-h));
  };

  // Side plane through the edge from corner a to corner b, tilted outwards by the lens cone.
  auto side = [&](int a, int b) {
    DVec3 n = glm::normalize(glm::cross(c[size_t(a)], c[size_t(b)]));
    if (glm::dot(n, center) < 0.0) n = -n;
    const DVec3 e = glm::normalize(c[size_t(a)] + c[size_t(b)]);
    // n' = alpha n + beta e with n' . corner = sin(rho) at both corners (n . corner = 0, e . corner = cos(half arc)).
    const double beta = std::min(1.0, std::sin(rho) / std::max(1e-9, glm::dot(e, c[size_t(a)])));
    const double alpha = std::sqrt(std::max(0.0, 1.0 - beta * beta));
    return plane(alpha * n + beta * e);
  };

  Frustum f;
  // Corners: 0 (u0,v0), 1 (u1,v0), 2 (u1,v1), 3 (u0,v1).
  f.planes[0] = side(3, 0);  // u0
  f.planes[1] = side(1, 2);  // u1
  f.planes[2] = side(0, 1);  // v0
  f.planes[3] = side(2, 3);  // v1
  f.planes[4] = plane(-center);
  f.planes[5] = plane(center);
  return f;
}

bool containsBox(const Frustum& frustum, const Box3& box) {
  if (box.empty()) return false;
  for (const Vec4& p : frustum.planes) {
    const Vec3 v(p.x >= 0 ? box.lo.x : box.hi.x, p.y >= 0 ? box.lo.y : box.hi.y, p.z >= 0 ? box.lo.z : box.hi.z);
    if (glm::dot(Vec3(p), v) + p.w < 0.0f) return false;
  }
  return true;
}

}  // namespace farfield
