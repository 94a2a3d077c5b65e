#include "farfield/runtime/crowd_shadows.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"

namespace farfield::runtime {

ShadowFit fitShadow(const Camera& camera, const Vec3& light_dir, std::span<const CasterSphere> spheres,
                    float distance_m, int map_size, float drop_m) {
  if (!(glm::length(light_dir) > 0.0f)) throw Error("crowd shadows", "the light has no direction");
  if (!(distance_m > 0.0f) || map_size < 16) throw Error("crowd shadows", "shadow distance and map size must be positive");
  const Vec3 f = glm::normalize(light_dir);
  const Vec3 hint = std::abs(f.z) < 0.99f ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
  const Vec3 right = glm::normalize(glm::cross(f, hint));
  const Vec3 up = glm::cross(right, f);
  auto toLight = [&](const Vec3& p) { return Vec3(glm::dot(p, right), glm::dot(p, up), glm::dot(p, f)); };

  // The frustum from the near plane to distance_m: its 8 corners bound the receivers.
  const Vec3 fwd = camera.forward();
  const Vec3 cam_right = glm::normalize(glm::cross(fwd, camera.up));
  const Vec3 cam_up = glm::cross(cam_right, fwd);
  const float ty = std::tan(camera.fov_y * 0.5f), tx = ty * camera.aspect();
  const float far_d = std::max(std::min(distance_m, camera.far_plane), camera.near_plane);
  Vec2 lo(1e30f), hi(-1e30f);
  for (float d : {camera.near_plane, far_d})
    for (float sx : {-1.0f, 1.0f})
      for (float sy : {-1.0f, 1.0f}) {
        const Vec3 l = toLight(camera.eye + fwd * d + cam_right * (sx * tx * d) + cam_up * (sy * ty * d));
        lo = glm::min(lo, Vec2(l));
        hi = glm::max(hi, Vec2(l));
      }

  ShadowFit fit;
  Vec2 clo(1e30f), chi(-1e30f);
  float zlo = 1e30f, zhi = -1e30f;
  for (size_t i = 0; i < spheres.size(); ++i) {
    const Vec3 l = toLight(spheres[i].centre);
    const float r = spheres[i].radius;
    if (l.x + r < lo.x || l.x - r > hi.x || l.y + r < lo.y || l.y - r > hi.y) continue;
    fit.casters.push_back(uint32_t(i));
    clo = glm::min(clo, Vec2(l) - r);
    chi = glm::max(chi, Vec2(l) + r);
    zlo = std::min(zlo, l.z - r);
    zhi = std::max(zhi, l.z + r);
  }
  if (fit.casters.empty()) return fit;
  lo = glm::max(lo, clo);
  hi = glm::min(hi, chi);
  // Square texels: the larger side sets the texel, the box is centred.
  const float side = std::max({hi.x - lo.x, hi.y - lo.y, 1e-3f});
  const Vec2 c = 0.5f * (lo + hi);
  lo = c - 0.5f * side;
  hi = c + 0.5f * side;
  zlo -= 0.01f;
  zhi += 0.01f;
  Mat4 m(0.0f);  // rows: x -> [-1, 1], y -> [-1, 1], z -> [0, 1]
  for (int k = 0; k < 3; ++k) {
    m[k][0] = right[k] * 2.0f / side;
    m[k][1] = up[k] * 2.0f / side;
    m[k][2] = f[k] / (zhi - zlo);
  }
  m[3][0] = -(lo.x + hi.x) / side;
  m[3][1] = -(lo.y + hi.y) / side;
  m[3][2] = -zlo / (zhi - zlo);
  m[3][3] = 1.0f;
  fit.projection.view_proj = m;
  fit.projection.depth_range_m = zhi - zlo;
  fit.projection.texel_m = side / float(map_size);

  // Screen bounds of the shadows: each caster's sphere at its centre and where the light carries it down to drop_m
  // below its lowest point (the sphere's bounds in between follow: the swept sphere is their convex hull).
  const Mat4 vp = camera.viewProjection();
  const float focal = float(camera.height) / (2.0f * ty);
  bool whole = f.z >= -1e-3f;
  for (uint32_t i : fit.casters) {
    if (whole) break;
    const CasterSphere& s = spheres[i];
    const float t = (2.0f * s.radius + drop_m) / -f.z;
    Vec2 clo(1e30f), chi(-1e30f);
    for (const Vec3& c : {s.centre, s.centre + f * t}) {
      const Vec4 clip = vp * Vec4(c, 1.0f);
      if (clip.w < camera.near_plane + s.radius) {
        whole = true;
        break;
      }
      const Vec2 p = (Vec2(clip) / clip.w * 0.5f + 0.5f) * Vec2(float(camera.width), float(camera.height));
      const float r = s.radius * focal / clip.w * 1.5f;  // off-axis spheres project a little wider: margin
      clo = glm::min(clo, p - r);
      chi = glm::max(chi, p + r);
    }
    if (whole) break;
    const glm::ivec4 rect(std::clamp(int(std::floor(clo.x)), 0, camera.width),
                          std::clamp(int(std::floor(clo.y)), 0, camera.height),
                          std::clamp(int(std::ceil(chi.x)) + 1, 0, camera.width),
                          std::clamp(int(std::ceil(chi.y)) + 1, 0, camera.height));
    if (rect.z > rect.x && rect.w > rect.y) fit.screen_rects.push_back(rect);
  }
  if (whole) fit.screen_rects.assign(1, glm::ivec4(0, 0, camera.width, camera.height));
  return fit;
}

}  // namespace farfield::runtime
