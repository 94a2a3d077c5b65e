// Skinned, animated model: a mesh whose vertices follow up to four joints of a skeleton (linear blend skinning,
// glTF 2.0 "Skins"), the skeleton's node hierarchy, its animations and its base colour texture; CPU skinning of a
// pose (the reference the GPU skinning is tested against).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/image/image.h"
#include "farfield/scene/animation.h"
#include "farfield/scene/mesh.h"

namespace farfield::scene {

struct SkeletonNode {
  std::string name;
  int32_t parent = -1;  // index of the parent node, -1 for a root; parents come before their children
  NodePose rest;        // the node's own transform in the file
};

struct Skeleton {
  std::vector<SkeletonNode> nodes;   // parents before children
  std::vector<uint32_t> joints;      // joint j of the skin is node joints[j]
  std::vector<Mat4> inverse_bind;    // one per joint
  // Applied after the skinned world positions: the file's up axis to Farfield's Z up.
  Mat4 root{1.0f};
};

// Colour regions per model (Steed's lecture part 3: "16 independent regions"), each tinted per agent.
inline constexpr int kColorRegions = 16;

struct SkinnedModel {
  std::string name;  // the file, for messages
  Mesh mesh;         // bind-pose vertices (the mesh's space as the file gives it), normals, uvs
  std::vector<std::array<uint16_t, 4>> joints;  // per vertex: four joint indices (< skeleton.joints.size())
  std::vector<Vec4> weights;                    // per vertex: four weights, summing to 1
  Skeleton skeleton;
  std::vector<Animation> animations;
  std::shared_ptr<const image::ColorImage> texture;  // base colour texture; may be null
  Vec4 base_color{1.0f};
  // Per triangle: its colour region (< kColorRegions, scene/skin_regions.h); empty = every triangle in region 0.
  std::vector<uint8_t> regions;

  // Index of the animation named `name` (case-insensitive substring, e.g. "walk"), else 0; -1 without animations.
  int findAnimation(const std::string& name) const;
};

// Joint matrices of a pose: for each joint, root * world(joint node) * inverse_bind. Without an animation (null)
// the rest pose. Time in seconds, wrapped by the animation's duration.
std::vector<Mat4> jointMatrices(const SkinnedModel& model, const Animation* animation, float t);
// The same from explicit node poses (indexed like skeleton.nodes).
std::vector<Mat4> jointMatrices(const Skeleton& skeleton, const std::vector<NodePose>& poses);

// CPU linear blend skinning: the model's mesh in the pose (positions and normals moved, uvs and indices kept).
Mesh skinMesh(const SkinnedModel& model, std::span<const Mat4> joint_matrices);

// Bounds of the model (Z up, after root) over `samples` poses evenly spaced in the animation (rest pose when null).
Box3 animatedBounds(const SkinnedModel& model, const Animation* animation, int samples = 16);

// Throws farfield::Error naming model.name when the model cannot be skinned: per-vertex arrays of the wrong size,
// a joint index out of range, non-finite or negative weights, weights summing to 0, a skeleton whose joints or
// parents are out of range or not ordered parents first, non-finite inverse bind matrices, colour regions not one
// per triangle or out of range.
void validateSkinnedModel(const SkinnedModel& model);

}  // namespace farfield::scene
