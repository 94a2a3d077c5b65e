#include "farfield/gen/figure_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::gen {
namespace {

constexpr int kPaletteCells = 4;  // the palette texture: 4 x 4 cells
constexpr int kCellTexels = 4;    // of 4 x 4 texels each (mip level 2 still one colour a texel)
constexpr size_t kMaxMaterials = size_t(kPaletteCells * kPaletteCells);

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

FigureBuilder::FigureBuilder(std::string name) : name_(std::move(name)) {}

uint16_t FigureBuilder::addJoint(const std::string& name, int parent, Vec3 position) {
  if (parent >= int(nodes_.size()) || parent < -1)
    throw Error(name_, "joint '" + name + "': parent " + std::to_string(parent) + " is not an earlier joint");
  if (!finite(position)) throw Error(name_, "joint '" + name + "': position is not finite");
  if (nodes_.size() >= std::numeric_limits<uint16_t>::max()) throw Error(name_, "too many joints");
  scene::SkeletonNode node;
  node.name = name;
  node.parent = parent;
  node.rest.translation = parent < 0 ? position : position - positions_[size_t(parent)];
  nodes_.push_back(node);
  positions_.push_back(position);
  return uint16_t(nodes_.size() - 1);
}

uint32_t FigureBuilder::addMaterial(uint8_t region, image::Rgba8 colour) {
  if (region >= scene::kColorRegions)
    throw Error(name_, "material: colour region " + std::to_string(region) + " out of range (" +
                           std::to_string(scene::kColorRegions) + " regions)");
  if (materials_.size() >= kMaxMaterials)
    throw Error(name_, "material: at most " + std::to_string(kMaxMaterials) + " materials");
  materials_.push_back({region, colour});
  return uint32_t(materials_.size() - 1);
}

Vec3 FigureBuilder::jointPosition(uint16_t joint) const {
  if (joint >= positions_.size()) throw Error(name_, "joint " + std::to_string(joint) + " out of range");
  return positions_[joint];
}

std::vector<scene::NodePose> FigureBuilder::restPoses() const {
  std::vector<scene::NodePose> poses(nodes_.size());
  for (size_t i = 0; i < nodes_.size(); ++i) poses[i] = nodes_[i].rest;
  return poses;
}

Vec2 FigureBuilder::materialUv(uint32_t material) const {
  const int cx = int(material) % kPaletteCells, cy = int(material) / kPaletteCells;
  const float size = float(kPaletteCells * kCellTexels);
  return Vec2((float(cx * kCellTexels) + 0.5f * kCellTexels) / size,
              (float(cy * kCellTexels) + 0.5f * kCellTexels) / size);
}

void FigureBuilder::appendPart(scene::Mesh part, const std::vector<JointBlend>& skins, uint32_t material) {
  if (material >= materials_.size()) throw Error(name_, "part: material " + std::to_string(material) + " unknown");
  for (const JointBlend& s : skins)
    if (s.a >= nodes_.size() || s.b >= nodes_.size() || !(s.t >= 0.0f && s.t <= 1.0f))
      throw Error(name_, "part: joints " + std::to_string(s.a) + ", " + std::to_string(s.b) + " (of " +
                             std::to_string(nodes_.size()) + ") or blend " + std::to_string(s.t) + " out of range");
  part.computeNormals();
  part.uvs.assign(part.positions.size(), materialUv(material));
  mesh_.append(part);
  for (const JointBlend& s : skins) {
    if (s.a == s.b || s.t == 0.0f) {
      joints_.push_back({s.a, 0, 0, 0});
      weights_.emplace_back(1.0f, 0.0f, 0.0f, 0.0f);
    } else {
      joints_.push_back({s.a, s.b, 0, 0});
      weights_.emplace_back(1.0f - s.t, s.t, 0.0f, 0.0f);
    }
  }
  regions_.insert(regions_.end(), part.triangleCount(), materials_[material].region);
}

void FigureBuilder::addTube(std::span<const TubeRing> rings, int sides, uint32_t material, bool cap_start,
                            bool cap_end, Vec3 side) {
  if (rings.size() < 2 || sides < 3) throw Error(name_, "tube: needs 2 rings and 3 sides at least");
  const size_t n = rings.size(), s = size_t(sides);
  scene::Mesh part;
  std::vector<JointBlend> skins;
  // Each ring's frame (e1, e2, d) is right-handed, d along the tube there: vertex j at angle 2 pi j / sides goes
  // counter-clockwise about d, so (ring i, j), (i, j + 1), (i + 1, j) faces outwards.
  std::vector<Vec3> d(n), e1(n), e2(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 along = rings[std::min(i + 1, n - 1)].centre - rings[i > 0 ? i - 1 : 0].centre;
    if (!(glm::length(along) > 0.0f)) throw Error(name_, "tube: two rings at the same centre");
    d[i] = glm::normalize(along);
    const Vec3 off = side - glm::dot(side, d[i]) * d[i];
    if (!(glm::length(off) > 1e-4f)) throw Error(name_, "tube: its side vector runs along it");
    e1[i] = glm::normalize(off);
    e2[i] = glm::cross(d[i], e1[i]);
  }
  auto ringVertex = [&](size_t i, size_t j) {
    const float a = float(2.0 * kPi * double(j) / double(s));
    return rings[i].centre + rings[i].radius.x * std::cos(a) * e1[i] + rings[i].radius.y * std::sin(a) * e2[i];
  };
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < s; ++j) {
      part.positions.push_back(ringVertex(i, j));
      skins.push_back(rings[i].skin);
    }
  for (size_t i = 0; i + 1 < n; ++i)
    for (size_t j = 0; j < s; ++j) {
      const uint32_t a = uint32_t(i * s + j), b = uint32_t(i * s + (j + 1) % s);
      const uint32_t c = uint32_t((i + 1) * s + j), e = uint32_t((i + 1) * s + (j + 1) % s);
      part.indices.insert(part.indices.end(), {a, b, c, b, e, c});
    }
  // Caps: their own vertices (flat normals), a fan; the end cap faces +d, the start cap -d.
  auto cap = [&](size_t i, bool facing_d) {
    const uint32_t base = uint32_t(part.positions.size());
    for (size_t j = 0; j < s; ++j) {
      part.positions.push_back(ringVertex(i, j));
      skins.push_back(rings[i].skin);
    }
    for (uint32_t j = 1; j + 1 < uint32_t(s); ++j) {
      if (facing_d)
        part.indices.insert(part.indices.end(), {base, base + j, base + j + 1});
      else
        part.indices.insert(part.indices.end(), {base, base + j + 1, base + j});
    }
  };
  if (cap_start) cap(0, false);
  if (cap_end) cap(n - 1, true);
  appendPart(std::move(part), skins, material);
}

void FigureBuilder::addBox(Vec3 centre, Vec3 half, JointBlend skin, uint32_t material) {
  if (!(half.x > 0.0f && half.y > 0.0f && half.z > 0.0f) || !finite(centre))
    throw Error(name_, "box: half extents must be positive and the centre finite");
  scene::Mesh part;
  // Each face: its outward axis, and two axes u, v with u x v = the outward normal (counter-clockwise from outside).
  const Vec3 axes[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  for (int f = 0; f < 6; ++f) {
    const int k = f / 2;
    const float sign = (f % 2 == 0) ? 1.0f : -1.0f;
    const Vec3 normal = sign * axes[k];
    const Vec3 u = axes[(k + 1) % 3], v = sign * axes[(k + 2) % 3];
    const uint32_t base = uint32_t(part.positions.size());
    for (const Vec2 c : {Vec2(-1, -1), Vec2(1, -1), Vec2(1, 1), Vec2(-1, 1)})
      part.positions.push_back(centre + half * (normal + c.x * u + c.y * v));
    part.indices.insert(part.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  std::vector<JointBlend> skins(part.positions.size(), skin);
  appendPart(std::move(part), skins, material);
}

scene::Animation FigureBuilder::loopingAnimation(
    const std::string& name, float duration, int keys,
    const std::function<void(float phase, std::vector<scene::NodePose>&)>& pose, bool plant_root) const {
  if (keys < 2 || !(duration > 0.0f) || !std::isfinite(duration))
    throw Error(name_, "animation '" + name + "': needs 2 keys and a positive duration");
  if (nodes_.empty()) throw Error(name_, "animation '" + name + "': no joints");
  // The skinned parts so far, for planting the root: a model without animations.
  scene::SkinnedModel probe;
  if (plant_root) {
    probe.name = name_;
    probe.mesh = mesh_;
    probe.joints = joints_;
    probe.weights = weights_;
    probe.skeleton.nodes = nodes_;
    for (size_t j = 0; j < nodes_.size(); ++j) {
      probe.skeleton.joints.push_back(uint32_t(j));
      probe.skeleton.inverse_bind.push_back(glm::translate(Mat4(1.0f), -positions_[j]));
    }
  }
  std::vector<std::vector<scene::NodePose>> key_poses;
  for (int k = 0; k + 1 < keys; ++k) {
    std::vector<scene::NodePose> poses = restPoses();
    pose(float(k) / float(keys - 1), poses);
    if (plant_root && !probe.mesh.positions.empty()) {
      const scene::Mesh posed = scene::skinMesh(probe, scene::jointMatrices(probe.skeleton, poses));
      float lowest = std::numeric_limits<float>::max();
      for (const Vec3& p : posed.positions) lowest = std::min(lowest, p.z);
      poses[0].translation.z -= lowest;
    }
    key_poses.push_back(std::move(poses));
  }
  key_poses.push_back(key_poses.front());  // the cycle closes exactly
  scene::Animation animation;
  animation.name = name;
  animation.start = 0.0f;
  animation.duration = duration;
  for (uint32_t node = 0; node < nodes_.size(); ++node) {
    scene::AnimationChannel translation, rotation;
    translation.node = rotation.node = node;
    translation.path = scene::AnimationPath::Translation;
    rotation.path = scene::AnimationPath::Rotation;
    for (int k = 0; k < keys; ++k) {
      const float t = duration * float(k) / float(keys - 1);
      const scene::NodePose& p = key_poses[size_t(k)][node];
      translation.times.push_back(t);
      translation.values.emplace_back(p.translation, 0.0f);
      rotation.times.push_back(t);
      const scene::Quat q = glm::normalize(p.rotation);
      rotation.values.emplace_back(q.x, q.y, q.z, q.w);
    }
    animation.channels.push_back(std::move(translation));
    animation.channels.push_back(std::move(rotation));
  }
  return animation;
}

scene::SkinnedModel FigureBuilder::build(std::vector<scene::Animation> animations) const {
  scene::SkinnedModel model;
  model.name = name_;
  model.mesh = mesh_;
  model.mesh.computeBounds();
  model.joints = joints_;
  model.weights = weights_;
  model.skeleton.nodes = nodes_;
  for (size_t j = 0; j < nodes_.size(); ++j) {
    model.skeleton.joints.push_back(uint32_t(j));
    model.skeleton.inverse_bind.push_back(glm::translate(Mat4(1.0f), -positions_[j]));
  }
  model.animations = std::move(animations);
  const int size = kPaletteCells * kCellTexels;
  auto texture = std::make_shared<image::ColorImage>(size, size, image::Rgba8(255, 255, 255, 255));
  for (size_t m = 0; m < materials_.size(); ++m) {
    const int cx = int(m) % kPaletteCells, cy = int(m) / kPaletteCells;
    for (int y = 0; y < kCellTexels; ++y)
      for (int x = 0; x < kCellTexels; ++x)
        texture->at(cx * kCellTexels + x, cy * kCellTexels + y) = materials_[m].colour;
  }
  model.texture = std::move(texture);
  model.regions = regions_;
  scene::validateSkinnedModel(model);
  return model;
}

}  // namespace farfield::gen
