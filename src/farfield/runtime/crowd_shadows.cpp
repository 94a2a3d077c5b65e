#include "farfield/runtime/crowd_shadows.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"

namespace farfield::runtime {

namespace {

// Light space: x, y across the light, z along it.
struct LightBasis {
  Vec3 right, up, f;
  explicit LightBasis(const Vec3& light_dir) {
    f = glm::normalize(light_dir);
    const Vec3 hint = std::abs(f.z) < 0.99f ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
    right = glm::normalize(glm::cross(f, hint));
    up = glm::cross(right, f);
  }
  Vec3 toLight(const Vec3& p) const { return Vec3(glm::dot(p, right), glm::dot(p, up), glm::dot(p, f)); }
};

void checkShadowArguments(const Vec3& light_dir, float distance_m, int map_size) {
  if (!(glm::length(light_dir) > 0.0f)) throw Error("crowd shadows", "the light has no direction");
  if (!(distance_m > 0.0f) || map_size < 16) throw Error("crowd shadows", "shadow distance and map size must be positive");
}

// The receivers' bounds in light space: the frustum from the near plane to distance_m (its 8 corners).
void receiverBounds(const Camera& camera, const LightBasis& b, float distance_m, Vec2& lo, Vec2& hi, float& zlo,
                    float& zhi) {
  const Vec3 fwd = camera.forward();
  const Vec3 cam_right = glm::normalize(glm::cross(fwd, camera.up));
  const Vec3 cam_up = glm::cross(cam_right, fwd);
  const float ty = std::tan(camera.fov_y * 0.5f), tx = ty * camera.aspect();
  const float far_d = std::max(std::min(distance_m, camera.far_plane), camera.near_plane);
  lo = Vec2(1e30f), hi = Vec2(-1e30f);
  zlo = 1e30f, zhi = -1e30f;
  for (float d : {camera.near_plane, far_d})
    for (float sx : {-1.0f, 1.0f})
      for (float sy : {-1.0f, 1.0f}) {
        const Vec3 l = b.toLight(camera.eye + fwd * d + cam_right * (sx * tx * d) + cam_up * (sy * ty * d));
        lo = glm::min(lo, Vec2(l));
        hi = glm::max(hi, Vec2(l));
        zlo = std::min(zlo, l.z);
        zhi = std::max(zhi, l.z);
      }
}

// The orthographic projection of the light-space box [lo, hi] x [zlo, zhi] with square texels (the box centred on
// the larger side).
gpu::ShadowProjection orthographic(const LightBasis& b, Vec2 lo, Vec2 hi, float zlo, float zhi, int map_size) {
  const float side = std::max({hi.x - lo.x, hi.y - lo.y, 1e-3f});
  const Vec2 c = 0.5f * (lo + hi);
  lo = c - 0.5f * side;
  hi = c + 0.5f * side;
  zlo -= 0.01f;
  zhi += 0.01f;
  Mat4 m(0.0f);  // rows: x -> [-1, 1], y -> [-1, 1], z -> [0, 1]
  for (int k = 0; k < 3; ++k) {
    m[k][0] = b.right[k] * 2.0f / side;
    m[k][1] = b.up[k] * 2.0f / side;
    m[k][2] = b.f[k] / (zhi - zlo);
  }
  m[3][0] = -(lo.x + hi.x) / side;
  m[3][1] = -(lo.y + hi.y) / side;
  m[3][2] = -zlo / (zhi - zlo);
  m[3][3] = 1.0f;
  gpu::ShadowProjection out;
  out.view_proj = m;
  out.depth_range_m = zhi - zlo;
  out.texel_m = side / float(map_size);
  return out;
}

}  // namespace

ShadowFit fitShadowReceivers(const Camera& camera, const Vec3& light_dir, float distance_m, int map_size,
                             float reach_m) {
  checkShadowArguments(light_dir, distance_m, map_size);
  const LightBasis b(light_dir);
  Vec2 lo, hi;
  float zlo = 0.0f, zhi = 0.0f;
  receiverBounds(camera, b, distance_m, lo, hi, zlo, zhi);
  ShadowFit fit;
  fit.projection = orthographic(b, lo - reach_m, hi + reach_m, zlo - reach_m, zhi + reach_m, map_size);
  fit.screen_rects.assign(1, glm::ivec4(0, 0, camera.width, camera.height));
  return fit;
}

ShadowFit fitShadow(const Camera& camera, const Vec3& light_dir, std::span<const CasterSphere> spheres,
                    float distance_m, int map_size, float drop_m) {
  checkShadowArguments(light_dir, distance_m, map_size);
  const LightBasis b(light_dir);
  const Vec3 f = b.f;
  auto toLight = [&](const Vec3& p) { return b.toLight(p); };
  Vec2 lo, hi;
  float receivers_zlo = 0.0f, receivers_zhi = 0.0f;
  receiverBounds(camera, b, distance_m, lo, hi, receivers_zlo, receivers_zhi);
  const float ty = std::tan(camera.fov_y * 0.5f);
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
  fit.projection = orthographic(b, lo, hi, zlo, zhi, map_size);

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
