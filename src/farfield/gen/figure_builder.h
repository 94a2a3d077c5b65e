// Builds a low-poly skinned, animated figure (scene::SkinnedModel, the form importSkinnedModel gives glTF models) out
// of simple parts: a skeleton of joints placed in the bind pose (figure space: metres, Z up, front +x, feet on z = 0),
// tubes (rings of an elliptical cross-section along a polyline) and boxes, each vertex following one joint or
// blending two, each part in one material (a colour region and a colour of the figure's small palette texture), and
// looping animations keyed from a pose function. The crowd's built-in figures (walker_figure.h,
// quadruped_figure.h) are made with it.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/image/image.h"
#include "farfield/scene/skin.h"

namespace farfield::gen {

// A vertex's joints: `a` with weight 1 - t, `b` with weight t (t = 0 or b == a: `a` alone).
struct JointBlend {
  uint16_t a = 0;
  uint16_t b = 0;
  float t = 0.0f;
};

// One ring of a tube: its centre, its half extents (x along the tube's side vector, y along axis x side) and the
// joints its vertices follow.
struct TubeRing {
  Vec3 centre{0.0f};
  Vec2 radius{0.1f};
  JointBlend skin;
};

class FigureBuilder {
 public:
  explicit FigureBuilder(std::string name);

  // A joint at `position` (bind pose, figure space) under `parent` (-1: a root; parents are added before their
  // children). Its node's rest pose is the translation from its parent, without rotation, so that the bind pose is
  // the rest pose. Node and joint indices are the same. Throws farfield::Error naming the figure for a parent out
  // of range or a non-finite position.
  uint16_t addJoint(const std::string& name, int parent, Vec3 position);
  // A material: its colour region (< scene::kColorRegions) and its colour in the palette texture (at most 16
  // materials). Returns its index. Throws farfield::Error for a region out of range or too many materials.
  uint32_t addMaterial(uint8_t region, image::Rgba8 colour);

  // A tube through `rings` (at least 2), `sides` (>= 3) vertices around each, the cross-section's first axis along
  // `side` made perpendicular to the tube; closed at its first and last ring when asked. Faces point outwards
  // (counter-clockwise seen from outside); normals are smooth around the tube, flat on the caps.
  void addTube(std::span<const TubeRing> rings, int sides, uint32_t material, bool cap_start = true,
               bool cap_end = true, Vec3 side = Vec3(0.0f, 1.0f, 0.0f));
  // An axis-aligned box (centre, half extents), flat-shaded, every vertex following `skin`.
  void addBox(Vec3 centre, Vec3 half, JointBlend skin, uint32_t material);

  size_t jointCount() const { return nodes_.size(); }
  Vec3 jointPosition(uint16_t joint) const;
  // The rest pose of every node (indexed like the skeleton's nodes).
  std::vector<scene::NodePose> restPoses() const;

  // A looping animation: `keys` (>= 2) key times evenly over [0, duration], each node's translation and rotation set
  // by pose(phase in [0, 1), poses) from the rest poses, the last key a copy of the first so that the cycle closes
  // exactly. With plant_root, the root node (node 0) is raised or lowered at each key so that the figure's lowest
  // vertex touches z = 0 (the parts added so far, skinned). Throws farfield::Error for keys < 2 or duration <= 0.
  scene::Animation loopingAnimation(const std::string& name, float duration, int keys,
                                    const std::function<void(float phase, std::vector<scene::NodePose>&)>& pose,
                                    bool plant_root) const;

  // The figure: mesh (positions, normals, the palette uvs), per-vertex joints and weights, skeleton (inverse bind
  // matrices the joints' bind translations inverted, no root turn), the palette texture (4 x 4 cells of 4 x 4
  // texels, one per material), per-triangle colour regions and the given animations. Validated
  // (scene::validateSkinnedModel).
  scene::SkinnedModel build(std::vector<scene::Animation> animations) const;

 private:
  struct Material {
    uint8_t region = 0;
    image::Rgba8 colour{255};
  };
  void appendPart(scene::Mesh part, const std::vector<JointBlend>& skins, uint32_t material);
  Vec2 materialUv(uint32_t material) const;

  std::string name_;
  std::vector<scene::SkeletonNode> nodes_;
  std::vector<Vec3> positions_;  // per joint, bind pose
  std::vector<Material> materials_;
  scene::Mesh mesh_;
  std::vector<std::array<uint16_t, 4>> joints_;
  std::vector<Vec4> weights_;
  std::vector<uint8_t> regions_;
};

}  // namespace farfield::gen
