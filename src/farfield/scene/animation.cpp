#include "farfield/scene/animation.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/check.h"

namespace farfield::scene {

Mat4 NodePose::matrix() const {
  return glm::translate(Mat4(1.0f), translation) * glm::mat4_cast(rotation) * glm::scale(Mat4(1.0f), scale);
}

namespace {

Quat toQuat(const Vec4& v) { return Quat(v.w, v.x, v.y, v.z); }
Vec4 fromQuat(const Quat& q) { return Vec4(q.x, q.y, q.z, q.w); }

// glm::slerp takes the shorter arc only in its 4-argument form on some versions: do it explicitly.
Quat slerpShort(Quat a, Quat b, float s) {
  if (glm::dot(a, b) < 0.0f) b = -b;
  return glm::normalize(glm::slerp(a, b, s));
}

}  // namespace

Vec4 sampleChannel(const AnimationChannel& channel, float t) {
  const std::vector<float>& times = channel.times;
  FF_CHECK(!times.empty() && times.size() == channel.values.size());
  if (t <= times.front()) return channel.values.front();
  if (t >= times.back()) return channel.values.back();
  // First key after t: keys k-1 <= t < k.
  const size_t k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const Vec4& a = channel.values[k - 1];
  if (channel.interpolation == Interpolation::Step) return a;
  const Vec4& b = channel.values[k];
  const float span = times[k] - times[k - 1];
  const float s = span > 0.0f ? (t - times[k - 1]) / span : 0.0f;
  if (channel.path == AnimationPath::Rotation) return fromQuat(slerpShort(toQuat(a), toQuat(b), s));
  return a + (b - a) * s;
}

void applyAnimation(const Animation& animation, float t, std::vector<NodePose>& poses) {
  float local = t - animation.start;
  if (animation.duration > 0.0f) {
    local = std::fmod(local, animation.duration);
    if (local < 0.0f) local += animation.duration;
  } else {
    local = 0.0f;
  }
  local += animation.start;
  for (const AnimationChannel& channel : animation.channels) {
    FF_CHECK(channel.node < poses.size());
    const Vec4 v = sampleChannel(channel, local);
    NodePose& pose = poses[channel.node];
    switch (channel.path) {
      case AnimationPath::Translation: pose.translation = Vec3(v); break;
      case AnimationPath::Rotation: pose.rotation = glm::normalize(toQuat(v)); break;
      case AnimationPath::Scale: pose.scale = Vec3(v); break;
    }
  }
}

}  // namespace farfield::scene
