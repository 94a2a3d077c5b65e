#include "farfield/core/camera.h"

#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield {

float Camera::fovX() const { return 2.0f * std::atan(std::tan(fov_y * 0.5f) * aspect()); }

Camera Camera::resized(int w, int h) const {
  Camera c = *this;
  c.fov_y = 2.0f * std::atan(std::tan(fov_y * 0.5f) * float(h) / float(height));
  c.width = w;
  c.height = h;
  return c;
}

Mat4 Camera::view() const { return glm::lookAt(eye, at, up); }

Mat4 Camera::projection() const {
  // depth = z_clip / w_clip with w_clip = distance d: depth(d) = -a + b / d, depth(near) = 1, depth(far) = 0.
  const float n = near_plane, f = far_plane;
  const float t = std::tan(fov_y * 0.5f);
  Mat4 p(0.0f);
  p[0][0] = 1.0f / (aspect() * t);
  p[1][1] = 1.0f / t;
  p[2][2] = n / (f - n);
  p[2][3] = -1.0f;
  p[3][2] = n * f / (f - n);
  return p;
}

float Camera::linearDepth(float window_depth) const {
  const float n = near_plane, f = far_plane;
  return n * f / (window_depth * (f - n) + n);
}

Vec3 Camera::unproject(float px, float py, float window_depth) const {
  const float d = linearDepth(window_depth);
  const float t = std::tan(fov_y * 0.5f);
  const float ndc_x = (px / float(width)) * 2.0f - 1.0f;
  const float ndc_y = 1.0f - (py / float(height)) * 2.0f;
  const Vec4 p_view(ndc_x * t * aspect() * d, ndc_y * t * d, -d, 1.0f);
  return Vec3(glm::inverse(view()) * p_view);
}

Vec3 Camera::project(const Vec3& world, float* w_out) const {
  const Vec4 clip = viewProjection() * Vec4(world, 1.0f);
  if (w_out) *w_out = clip.w;
  const float w = clip.w != 0.0f ? clip.w : 1e-20f;
  const Vec3 ndc = Vec3(clip) / w;
  return Vec3((ndc.x * 0.5f + 0.5f) * float(width), (0.5f - ndc.y * 0.5f) * float(height), ndc.z);
}

void Camera::validate(const char* what) const {
  auto fail = [&](const std::string& msg) { throw Error(what, msg); };
  if (!isFinite(eye) || !isFinite(at) || !isFinite(up)) fail("eye, look-at and up must be finite");
  if (glm::length(at - eye) <= 1e-6f) fail("eye and look-at point coincide");
  if (glm::length(up) <= 1e-6f) fail("up vector is zero");
  if (glm::length(glm::cross(glm::normalize(at - eye), glm::normalize(up))) < 1e-4f)
    fail("up vector is parallel to the view direction");
  if (!(fov_y > 0.0f && fov_y < float(kPi))) fail("field of view must be between 0 and 180 degrees");
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) fail("image size must be 1..16384 pixels");
  if (!(near_plane > 0.0f && far_plane > near_plane)) fail("need 0 < near < far");
}

Frustum Frustum::fromMatrix(const Mat4& m) {
  // Rows of the matrix (glm is column-major: m[col][row]).
  auto row = [&](int r) { return Vec4(m[0][r], m[1][r], m[2][r], m[3][r]); };
  const Vec4 r0 = row(0), r1 = row(1), r2 = row(2), r3 = row(3);
  Frustum f;
  f.planes = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2};  // depth range [0,1]: 0 <= z <= w
  for (auto& p : f.planes) {
    const float len = glm::length(Vec3(p));
    if (len > 0.0f) p /= len;
  }
  return f;
}

bool Frustum::intersects(const Box3& box) const {
  if (box.empty()) return false;
  for (const Vec4& p : planes) {
    // The box corner farthest along the plane normal.
    const Vec3 v(p.x >= 0 ? box.hi.x : box.lo.x, p.y >= 0 ? box.hi.y : box.lo.y, p.z >= 0 ? box.hi.z : box.lo.z);
    if (glm::dot(Vec3(p), v) + p.w < 0.0f) return false;
  }
  return true;
}

bool Frustum::contains(const Vec3& q) const {
  for (const Vec4& p : planes)
    if (glm::dot(Vec3(p), q) + p.w < 0.0f) return false;
  return true;
}

}  // namespace farfield
