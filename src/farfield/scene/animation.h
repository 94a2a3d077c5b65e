// Skeletal animation: glTF animation channels (translation, rotation, scale of a node over time) sampled with
// linear or step interpolation, rotations by spherical linear interpolation (glTF 2.0, "Animations").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "farfield/core/math.h"

namespace farfield::scene {

using Quat = glm::quat;

// Local transform of a node: translation, rotation, scale (T * R * S).
struct NodePose {
  Vec3 translation{0.0f};
  Quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  Vec3 scale{1.0f};
  Mat4 matrix() const;
};

enum class AnimationPath { Translation, Rotation, Scale };
// CubicSpline keys are read as their values (the tangents dropped) and sampled linearly (counted on import).
enum class Interpolation { Linear, Step };

struct AnimationChannel {
  uint32_t node = 0;  // index into the skeleton's nodes
  AnimationPath path = AnimationPath::Translation;
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> times;   // seconds, strictly increasing, at least one
  std::vector<Vec4> values;   // one per time: xyz for translation and scale, quaternion (x, y, z, w) for rotation
};

struct Animation {
  std::string name;
  std::vector<AnimationChannel> channels;
  float start = 0.0f;     // first key time over all channels
  float duration = 0.0f;  // last key time minus start (0 for a single pose)
};

// The channel's value at time t (seconds, clamped to its keys): step takes the key at or before t, linear
// interpolates (rotations by slerp along the shorter arc, normalised).
Vec4 sampleChannel(const AnimationChannel& channel, float t);

// Sets the animated components of `poses` (indexed by node) at time t. The time wraps: t is taken modulo the
// duration, after the start (a walk cycle loops). Channels naming a node out of range are an FF_CHECK failure
// (the importer rejects them).
void applyAnimation(const Animation& animation, float t, std::vector<NodePose>& poses);

}  // namespace farfield::scene
