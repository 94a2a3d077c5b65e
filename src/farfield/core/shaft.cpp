#include "farfield/core/shaft.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"

namespace farfield {

Shaft Shaft::make(const Vec3& apex, const Vec3& axis, float apex_angle, float min_distance, const char* what) {
  if (!isFinite(apex)) throw Error(std::string(what) + ": the apex is not finite");
  const float length = glm::length(axis);
  if (!isFinite(axis) || !(length > 0.0f)) throw Error(std::string(what) + ": the axis is zero or not finite");
  if (!(apex_angle > 0.0f) || !(apex_angle <= static_cast<float>(kPi) + 1e-6f))
    throw Error(std::string(what) + ": apex angle " + std::to_string(apex_angle) + " rad is outside (0, pi]");
  if (!(min_distance >= 0.0f) || !std::isfinite(min_distance))
    throw Error(std::string(what) + ": minimum distance " + std::to_string(min_distance) + " is negative or not finite");
  return Shaft{apex, axis / length, apex_angle, min_distance};
}

std::optional<Shaft> Shaft::enclosing(const Vec3& apex, const Box3& box) {
  if (box.empty() || !isFinite(apex) || box.contains(apex)) return std::nullopt;
  const Vec3 to_centre = box.center() - apex;
  if (!(glm::length(to_centre) > 0.0f)) return std::nullopt;
  const Vec3 axis = glm::normalize(to_centre);
  float cos_half = 1.0f;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    const Vec3 d = corner - apex;
    cos_half = std::min(cos_half, glm::dot(d, axis) / glm::length(d));
  }
  // A little wider than the widest corner, so that containsBox's float test holds at that corner too.
  const float half = std::acos(std::clamp(cos_half, -1.0f, 1.0f)) + 1e-5f;
  if (!(half < 0.5f * static_cast<float>(kPi))) return std::nullopt;
  const float nearest = glm::length(glm::clamp(apex, box.lo, box.hi) - apex);
  return Shaft{apex, axis, 2.0f * half, nearest * (1.0f - 1e-6f)};
}

bool Shaft::contains(const Vec3& p) const {
  const Vec3 d = p - apex;
  const float dist = glm::length(d);
  if (dist < min_distance) return false;
  if (dist == 0.0f) return true;  // min_distance 0: the apex itself
  return glm::dot(d, axis) >= dist * std::cos(0.5f * apex_angle) - 1e-6f * dist;
}

bool Shaft::containsBox(const Box3& box) const {
  if (box.empty()) return false;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    const Vec3 d = corner - apex;
    const float dist = glm::length(d);
    if (dist > 0.0f && glm::dot(d, axis) < dist * std::cos(0.5f * apex_angle)) return false;
  }
  const Vec3 nearest = glm::clamp(apex, box.lo, box.hi);
  return glm::length(nearest - apex) >= min_distance;
}

bool Shaft::mayIntersectBox(const Box3& box) const {
  if (box.empty()) return false;
  // Inside the ball of min_distance: the farthest corner is closer than min_distance.
  float farthest = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    farthest = std::max(farthest, glm::length(corner - apex));
  }
  if (farthest < min_distance) return false;
  // Outside the cone: the box's bounding sphere does not reach the cone (angle from the axis to the sphere's centre
  // minus the sphere's angular radius exceeds the half angle).
  const Vec3 c = box.center();
  const float r = 0.5f * glm::length(box.extent());
  const Vec3 d = c - apex;
  const float dist = glm::length(d);
  if (dist <= r) return true;
  const float angle = std::acos(std::clamp(glm::dot(d, axis) / dist, -1.0f, 1.0f));
  const float spread = std::asin(std::clamp(r / dist, 0.0f, 1.0f));
  return angle - spread <= 0.5f * apex_angle;
}

Vec3 Shaft::sample(float u, float v, float w, float max_distance) const {
  // Direction uniform over the spherical cap of half angle a: cos(theta) uniform in [cos a, 1].
  const float cos_a = std::cos(0.5f * apex_angle);
  const float cos_t = 1.0f - v * (1.0f - cos_a);
  const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  const float phi = static_cast<float>(2.0 * kPi) * w;
  const Vec3 helper = std::abs(axis.z) < 0.9f ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
  const Vec3 e1 = glm::normalize(glm::cross(axis, helper));
  const Vec3 e2 = glm::cross(axis, e1);
  const Vec3 dir = cos_t * axis + sin_t * (std::cos(phi) * e1 + std::sin(phi) * e2);
  const float dist = min_distance + u * std::max(0.0f, max_distance - min_distance);
  return apex + dist * dir;
}

}  // namespace farfield
