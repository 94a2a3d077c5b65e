#include "farfield/scene/skin.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "farfield/core/error.h"

namespace farfield::scene {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool finiteMatrix(const Mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

}  // namespace

int SkinnedModel::findAnimation(const std::string& wanted) const {
  if (animations.empty()) return -1;
  const std::string w = lower(wanted);
  for (size_t i = 0; i < animations.size(); ++i)
    if (!w.empty() && lower(animations[i].name).find(w) != std::string::npos) return int(i);
  return 0;
}

std::vector<Mat4> jointMatrices(const Skeleton& skeleton, const std::vector<NodePose>& poses) {
  std::vector<Mat4> world(skeleton.nodes.size());
  for (size_t i = 0; i < skeleton.nodes.size(); ++i) {
    const int32_t p = skeleton.nodes[i].parent;
    world[i] = p < 0 ? poses[i].matrix() : world[size_t(p)] * poses[i].matrix();
  }
  std::vector<Mat4> out(skeleton.joints.size());
  for (size_t j = 0; j < skeleton.joints.size(); ++j)
    out[j] = skeleton.root * world[skeleton.joints[j]] * skeleton.inverse_bind[j];
  return out;
}

std::vector<Mat4> jointMatrices(const SkinnedModel& model, const Animation* animation, float t) {
  std::vector<NodePose> poses(model.skeleton.nodes.size());
  for (size_t i = 0; i < poses.size(); ++i) poses[i] = model.skeleton.nodes[i].rest;
  if (animation) applyAnimation(*animation, t, poses);
  return jointMatrices(model.skeleton, poses);
}

Mesh skinMesh(const SkinnedModel& model, std::span<const Mat4> joint_matrices) {
  Mesh out;
  out.indices = model.mesh.indices;
  out.uvs = model.mesh.uvs;
  const size_t n = model.mesh.positions.size();
  out.positions.resize(n);
  const bool normals = model.mesh.normals.size() == n;
  if (normals) out.normals.resize(n);
  for (size_t v = 0; v < n; ++v) {
    Mat4 m(0.0f);
    for (int k = 0; k < 4; ++k) m += model.weights[v][k] * joint_matrices[model.joints[v][size_t(k)]];
    out.positions[v] = Vec3(m * Vec4(model.mesh.positions[v], 1.0f));
    if (normals) {
      const Vec3 nn = Mat3(m) * model.mesh.normals[v];
      const float len = glm::length(nn);
      out.normals[v] = len > 0.0f ? nn / len : Vec3(0.0f, 0.0f, 1.0f);
    }
  }
  out.computeBounds();
  return out;
}

Box3 animatedBounds(const SkinnedModel& model, const Animation* animation, int samples) {
  Box3 box;
  const int count = animation ? std::max(samples, 1) : 1;
  for (int i = 0; i < count; ++i) {
    const float t = animation ? animation->start + animation->duration * float(i) / float(count) : 0.0f;
    const std::vector<Mat4> joints = jointMatrices(model, animation, t);
    const Mesh posed = skinMesh(model, joints);
    for (const Vec3& p : posed.positions) box.expand(p);
  }
  return box;
}

void validateSkinnedModel(const SkinnedModel& model) {
  const std::string& src = model.name;
  model.mesh.validate(src);
  const size_t n = model.mesh.positions.size();
  if (model.joints.size() != n || model.weights.size() != n)
    throw Error(src, "skin: " + std::to_string(model.joints.size()) + " joint and " +
                         std::to_string(model.weights.size()) + " weight entries for " + std::to_string(n) +
                         " vertices");
  const Skeleton& sk = model.skeleton;
  if (sk.joints.empty()) throw Error(src, "skin: no joints");
  if (sk.inverse_bind.size() != sk.joints.size())
    throw Error(src, "skin: " + std::to_string(sk.inverse_bind.size()) + " inverse bind matrices for " +
                         std::to_string(sk.joints.size()) + " joints");
  for (size_t j = 0; j < sk.joints.size(); ++j) {
    if (sk.joints[j] >= sk.nodes.size())
      throw Error(src, "skin: joint " + std::to_string(j) + " names node " + std::to_string(sk.joints[j]) +
                           " of " + std::to_string(sk.nodes.size()));
    if (!finiteMatrix(sk.inverse_bind[j]))
      throw Error(src, "skin: inverse bind matrix " + std::to_string(j) + " is not finite");
  }
  for (size_t i = 0; i < sk.nodes.size(); ++i)
    if (sk.nodes[i].parent >= int32_t(i))
      throw Error(src, "skin: node " + std::to_string(i) + " comes before its parent " +
                           std::to_string(sk.nodes[i].parent));
  for (size_t v = 0; v < n; ++v) {
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const float w = model.weights[v][k];
      if (!std::isfinite(w) || w < 0.0f)
        throw Error(src, "skin: vertex " + std::to_string(v) + ": weight " + std::to_string(k) +
                             " is negative or not finite");
      if (model.joints[v][size_t(k)] >= sk.joints.size())
        throw Error(src, "skin: vertex " + std::to_string(v) + ": joint index " +
                             std::to_string(model.joints[v][size_t(k)]) + " out of range (skin has " +
                             std::to_string(sk.joints.size()) + " joints)");
      sum += w;
    }
    if (std::abs(sum - 1.0f) > 1e-3f)
      throw Error(src, "skin: vertex " + std::to_string(v) + ": weights sum to " + std::to_string(sum));
  }
  if (!model.regions.empty() && model.regions.size() != model.mesh.triangleCount())
    throw Error(src, "skin: " + std::to_string(model.regions.size()) + " colour regions for " +
                         std::to_string(model.mesh.triangleCount()) + " triangles");
  for (size_t t = 0; t < model.regions.size(); ++t)
    if (model.regions[t] >= kColorRegions)
      throw Error(src, "skin: triangle " + std::to_string(t) + ": colour region " + std::to_string(model.regions[t]) +
                           " out of range (" + std::to_string(kColorRegions) + " regions)");
  for (const Animation& a : model.animations)
    for (const AnimationChannel& c : a.channels)
      if (c.node >= sk.nodes.size() || c.times.empty() || c.times.size() != c.values.size())
        throw Error(src, "animation '" + a.name + "': channel of node " + std::to_string(c.node) +
                             " is out of range or has mismatched keys");
}

}  // namespace farfield::scene
