// glTF 2.0 skins and animations ("Skins", "Animations" of the specification) read with tinygltf.
#include "farfield/scene/gltf_skin.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/scene/gltf_accessor.h"
#include "farfield/scene/import.h"
#include "farfield/scene/skin_regions.h"

namespace farfield::scene {

namespace detail {
void checkTinygltfBinding();  // import_gltf.cpp
}

namespace {

const Mat4 kYUpToZUp(Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, -1, 0, 0), Vec4(0, 0, 0, 1));

// Image bytes kept raw; decoded by TextureFiles afterwards (one decoder for every importer).
// Images in a buffer view are left alone here: tinygltf does not check the view against its buffer before calling
// (gltfImageBytes reads them, checked, in readTexture).
bool keepImageBytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                    const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0) image->image.assign(bytes, bytes + std::max(size, 0));
  image->width = image->height = 0;
  image->component = 0;
  return true;
}

class SkinReader {
 public:
  SkinReader(const std::string& path, const tinygltf::Model& model, SkinImportStats& stats)
      : path_(path), model_(model), stats_(stats) {}

  SkinnedModel read() {
    SkinnedModel out;
    out.name = path_;
    readNodes(out.skeleton);
    int mesh_node = -1;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (model_.nodes[i].mesh >= 0 && model_.nodes[i].skin >= 0) {
        mesh_node = int(i);
        break;
      }
    if (mesh_node < 0) fail("no mesh node with a skin");
    const tinygltf::Node& node = model_.nodes[size_t(mesh_node)];
    if (size_t(node.skin) >= model_.skins.size()) fail("node " + std::to_string(mesh_node) + ": skin out of range");
    if (size_t(node.mesh) >= model_.meshes.size()) fail("node " + std::to_string(mesh_node) + ": mesh out of range");
    readSkin(model_.skins[size_t(node.skin)], out.skeleton);
    const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
    int material = -1;
    std::vector<uint32_t> primitive_of_triangle;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      if (readPrimitive(mesh.primitives[p], "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p),
                        out) &&
          material < 0)
        material = mesh.primitives[p].material;
      primitive_of_triangle.resize(out.mesh.triangleCount(), uint32_t(p));
    }
    if (out.mesh.indices.empty()) fail("the skinned mesh has no triangles");
    readMaterial(material, out);
    out.regions = colorRegions(out, primitive_of_triangle);
    for (size_t a = 0; a < model_.animations.size(); ++a) readAnimation(model_.animations[a], a, out);
    validateSkinnedModel(out);
    out.mesh.computeBounds();
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw Error(path_, what); }

  using View = GltfView;

  View view(int index, const std::string& what) const { return gltfAccessor(model_, index, what, path_); }

  static double component(const View& v, size_t i, int c) { return gltfComponent(v, i, c); }

  void readNodes(Skeleton& skeleton) {
    // Parents before children: order the nodes breadth-first from the roots; `order_[gltf index]` = our index.
    const size_t n = model_.nodes.size();
    std::vector<int> parent(n, -1);
    for (size_t i = 0; i < n; ++i)
      for (int c : model_.nodes[i].children) {
        if (c < 0 || size_t(c) >= n) fail("node " + std::to_string(i) + ": child " + std::to_string(c) + " out of range");
        if (parent[size_t(c)] >= 0) fail("node " + std::to_string(c) + " has two parents");
        parent[size_t(c)] = int(i);
      }
    order_.assign(n, -1);
    std::vector<size_t> queue;
    for (size_t i = 0; i < n; ++i)
      if (parent[i] < 0) queue.push_back(i);
    for (size_t q = 0; q < queue.size(); ++q)
      for (int c : model_.nodes[queue[q]].children) queue.push_back(size_t(c));
    if (queue.size() != n) fail("the node hierarchy has a cycle");
    skeleton.nodes.resize(n);
    for (size_t k = 0; k < n; ++k) order_[queue[k]] = int(k);
    for (size_t k = 0; k < n; ++k) {
      const tinygltf::Node& g = model_.nodes[queue[k]];
      SkeletonNode& s = skeleton.nodes[k];
      s.name = g.name;
      s.parent = parent[queue[k]] < 0 ? -1 : order_[size_t(parent[queue[k]])];
      if (g.matrix.size() == 16) {
        // A node given by a matrix: decomposed only as a translation plus rotation-scale kept in the rest pose.
        Mat4 m;
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r) m[c][r] = float(g.matrix[size_t(c * 4 + r)]);
        s.rest.translation = Vec3(m[3]);
        Vec3 sc(glm::length(Vec3(m[0])), glm::length(Vec3(m[1])), glm::length(Vec3(m[2])));
        s.rest.scale = sc;
        Mat3 rot(Vec3(m[0]) / sc.x, Vec3(m[1]) / sc.y, Vec3(m[2]) / sc.z);
        s.rest.rotation = glm::normalize(glm::quat_cast(rot));
      }
      if (g.translation.size() == 3)
        s.rest.translation = Vec3(float(g.translation[0]), float(g.translation[1]), float(g.translation[2]));
      if (g.rotation.size() == 4)
        s.rest.rotation = glm::normalize(
            Quat(float(g.rotation[3]), float(g.rotation[0]), float(g.rotation[1]), float(g.rotation[2])));
      if (g.scale.size() == 3) s.rest.scale = Vec3(float(g.scale[0]), float(g.scale[1]), float(g.scale[2]));
    }
    skeleton.root = kYUpToZUp;
  }

  void readSkin(const tinygltf::Skin& skin, Skeleton& skeleton) {
    for (size_t j = 0; j < skin.joints.size(); ++j) {
      const int node = skin.joints[j];
      if (node < 0 || size_t(node) >= model_.nodes.size())
        fail("skin: joint " + std::to_string(j) + " names node " + std::to_string(node) + " out of range");
      skeleton.joints.push_back(uint32_t(order_[size_t(node)]));
    }
    if (skin.inverseBindMatrices < 0) {
      stats_.identity_inverse_bind = true;
      skeleton.inverse_bind.assign(skeleton.joints.size(), Mat4(1.0f));
      return;
    }
    const View v = view(skin.inverseBindMatrices, "skin inverse bind matrices");
    if (v.components != 16 || v.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail("skin inverse bind matrices: expected float MAT4");
    if (v.count < skeleton.joints.size())
      fail("skin: " + std::to_string(v.count) + " inverse bind matrices for " +
           std::to_string(skeleton.joints.size()) + " joints");
    for (size_t j = 0; j < skeleton.joints.size(); ++j) {
      Mat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = float(component(v, j, c * 4 + r));
      skeleton.inverse_bind.push_back(m);
    }
  }

  bool readPrimitive(const tinygltf::Primitive& prim, const std::string& what, SkinnedModel& out) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    auto attr = [&](const char* name) {
      auto it = prim.attributes.find(name);
      return it == prim.attributes.end() ? -1 : it->second;
    };
    if (mode != TINYGLTF_MODE_TRIANGLES || attr("POSITION") < 0 || attr("JOINTS_0") < 0 || attr("WEIGHTS_0") < 0) {
      ++stats_.skipped_primitives;
      return false;
    }
    const View pos = view(attr("POSITION"), what + " POSITION");
    const size_t base = out.mesh.positions.size(), n = pos.count;
    const View joints = view(attr("JOINTS_0"), what + " JOINTS_0");
    const View weights = view(attr("WEIGHTS_0"), what + " WEIGHTS_0");
    if (pos.components != 3 || joints.components != 4 || weights.components != 4 || joints.count != n ||
        weights.count != n)
      fail(what + ": POSITION, JOINTS_0 and WEIGHTS_0 must be VEC3, VEC4 and VEC4 of one count each");
    const int ni = attr("NORMAL"), ti = attr("TEXCOORD_0");
    View normals, uvs;
    if (ni >= 0) normals = view(ni, what + " NORMAL");
    if (ti >= 0) uvs = view(ti, what + " TEXCOORD_0");
    const bool has_n = ni >= 0 && normals.count == n && normals.components == 3;
    const bool has_t = ti >= 0 && uvs.count == n && uvs.components == 2;
    if ((has_n != !out.mesh.normals.empty() || has_t != !out.mesh.uvs.empty()) && base > 0)
      fail(what + ": primitives differ in their attributes");
    for (size_t i = 0; i < n; ++i) {
      out.mesh.positions.emplace_back(component(pos, i, 0), component(pos, i, 1), component(pos, i, 2));
      if (has_n) out.mesh.normals.emplace_back(component(normals, i, 0), component(normals, i, 1), component(normals, i, 2));
      if (has_t) out.mesh.uvs.emplace_back(component(uvs, i, 0), component(uvs, i, 1));
      std::array<uint16_t, 4> j{};
      Vec4 w;
      float sum = 0.0f;
      for (int k = 0; k < 4; ++k) {
        const double jj = component(joints, i, k);
        if (!(jj >= 0.0 && jj < double(out.skeleton.joints.size())))
          fail(what + ": vertex " + std::to_string(i) + ": joint index " + std::to_string(jj) +
               " out of range (skin has " + std::to_string(out.skeleton.joints.size()) + " joints)");
        j[size_t(k)] = uint16_t(jj);
        w[k] = float(component(weights, i, k));
        if (!std::isfinite(w[k]) || w[k] < 0.0f)
          fail(what + ": vertex " + std::to_string(i) + ": weight " + std::to_string(k) + " is negative or not finite");
        sum += w[k];
      }
      if (!(sum > 0.0f)) fail(what + ": vertex " + std::to_string(i) + ": weights sum to 0");
      if (std::abs(sum - 1.0f) > 1e-3f) {
        ++stats_.renormalised_vertices;
        w /= sum;
      } else {
        w /= sum;  // exact to float rounding
      }
      out.joints.push_back(j);
      out.weights.push_back(w);
    }
    if (prim.indices >= 0) {
      const View idx = view(prim.indices, what + " indices");
      if (idx.components != 1 || idx.count % 3 != 0) fail(what + ": indices not a multiple of 3 scalars");
      for (size_t i = 0; i < idx.count; ++i) {
        const double k = component(idx, i, 0);
        if (!(k >= 0.0 && k < double(n))) fail(what + ": index " + std::to_string(i) + " out of range");
        out.mesh.indices.push_back(uint32_t(base + size_t(k)));
      }
    } else {
      if (n % 3 != 0) fail(what + ": vertex count not a multiple of 3");
      for (size_t i = 0; i < n; ++i) out.mesh.indices.push_back(uint32_t(base + i));
    }
    return true;
  }

  void readMaterial(int material, SkinnedModel& out) {
    if (material < 0 || size_t(material) >= model_.materials.size()) return;
    const tinygltf::PbrMetallicRoughness& pbr = model_.materials[size_t(material)].pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      out.base_color = Vec4(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]),
                            float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3]));
    const int tex = pbr.baseColorTexture.index;
    if (tex < 0 || size_t(tex) >= model_.textures.size()) return;
    const int source = model_.textures[size_t(tex)].source;
    if (source < 0 || size_t(source) >= model_.images.size()) return;
    const tinygltf::Image& img = model_.images[size_t(source)];
    ImportStats import_stats;
    TextureFiles files(import_stats);
    const std::string name = img.uri.empty() ? "embedded image " + std::to_string(source) : img.uri;
    if (img.bufferView >= 0) {
      std::string why;
      const std::span<const unsigned char> bytes = gltfImageBytes(model_, source, &why);
      if (bytes.empty())
        FF_WARN(path_ << ": " << name << " left out: " << (why.empty() ? "no bytes" : why));
      else
        out.texture = files.decode(name, bytes.data(), bytes.size());
    } else if (!img.image.empty())
      out.texture = files.decode(name, img.image.data(), img.image.size());
    else if (!img.uri.empty())
      out.texture = files.load(name, std::filesystem::path(path_).parent_path() / img.uri);
    for (const std::string& w : import_stats.warnings()) FF_WARN(path_ << ": " << w);
  }

  void readAnimation(const tinygltf::Animation& ga, size_t index, SkinnedModel& out) {
    Animation anim;
    anim.name = ga.name.empty() ? "animation " + std::to_string(index) : ga.name;
    const std::string where = "animation '" + anim.name + "'";
    float lo = 1e30f, hi = -1e30f;
    for (size_t c = 0; c < ga.channels.size(); ++c) {
      const tinygltf::AnimationChannel& gc = ga.channels[c];
      const std::string what = where + " channel " + std::to_string(c);
      AnimationChannel ch;
      if (gc.target_path == "translation") ch.path = AnimationPath::Translation;
      else if (gc.target_path == "rotation") ch.path = AnimationPath::Rotation;
      else if (gc.target_path == "scale") ch.path = AnimationPath::Scale;
      else {
        ++stats_.skipped_channels;
        continue;
      }
      if (gc.target_node < 0 || size_t(gc.target_node) >= model_.nodes.size()) {
        ++stats_.skipped_channels;
        continue;
      }
      ch.node = uint32_t(order_[size_t(gc.target_node)]);
      if (gc.sampler < 0 || size_t(gc.sampler) >= ga.samplers.size()) fail(what + ": sampler out of range");
      const tinygltf::AnimationSampler& s = ga.samplers[size_t(gc.sampler)];
      bool cubic = false;
      if (s.interpolation == "STEP") ch.interpolation = Interpolation::Step;
      else if (s.interpolation == "CUBICSPLINE") cubic = true;
      const View in = view(s.input, what + " input");
      const View values = view(s.output, what + " output");
      const int want = ch.path == AnimationPath::Rotation ? 4 : 3;
      if (in.components != 1 || values.components != want) fail(what + ": wrong key or value type");
      const size_t per_key = cubic ? 3 : 1;
      if (in.count == 0 || values.count != in.count * per_key)
        fail(what + ": " + std::to_string(values.count) + " values for " + std::to_string(in.count) + " keys");
      if (cubic) ++stats_.cubic_channels;
      for (size_t k = 0; k < in.count; ++k) {
        const float t = float(component(in, k, 0));
        if (!std::isfinite(t) || (!ch.times.empty() && t <= ch.times.back()))
          fail(what + ": key times not finite and increasing at key " + std::to_string(k));
        ch.times.push_back(t);
        const size_t vi = k * per_key + (cubic ? 1 : 0);
        Vec4 v(0.0f, 0.0f, 0.0f, 1.0f);
        for (int e = 0; e < want; ++e) v[e] = float(component(values, vi, e));
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !std::isfinite(v.w))
          fail(what + ": value " + std::to_string(k) + " not finite");
        ch.values.push_back(v);
      }
      lo = std::min(lo, ch.times.front());
      hi = std::max(hi, ch.times.back());
      anim.channels.push_back(std::move(ch));
    }
    if (anim.channels.empty()) return;
    anim.start = lo;
    anim.duration = hi - lo;
    out.animations.push_back(std::move(anim));
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  SkinImportStats& stats_;
  std::vector<int> order_;  // glTF node index -> skeleton node index
};

}  // namespace

std::vector<std::string> SkinImportStats::warnings() const {
  std::vector<std::string> out;
  if (renormalised_vertices)
    out.push_back(std::to_string(renormalised_vertices) + " vertices: skin weights renormalised to sum to 1");
  if (identity_inverse_bind) out.push_back("skin without inverse bind matrices: identity assumed (glTF default)");
  if (cubic_channels) out.push_back(std::to_string(cubic_channels) + " cubic-spline channels sampled linearly");
  if (skipped_channels) out.push_back(std::to_string(skipped_channels) + " animation channels ignored (weights)");
  if (skipped_primitives)
    out.push_back(std::to_string(skipped_primitives) + " primitives skipped (not triangles or not skinned)");
  return out;
}

SkinnedModel importSkinnedModel(const std::string& path, SkinImportStats* stats) {
  detail::checkTinygltfBinding();
  if (!std::filesystem::is_regular_file(path)) throw Error(path, "no such file");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keepImageBytes, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool binary = path.size() >= 4 && path.substr(path.size() - 4) == ".glb";
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
  if (!ok) throw Error(path, "cannot read glTF (truncated or corrupt file?): " + (err.empty() ? "no details" : err));
  SkinImportStats local;
  SkinnedModel out = SkinReader(path, model, stats ? *stats : local).read();
  if (!stats)
    for (const std::string& w : local.warnings()) FF_WARN(path << ": " << w);
  return out;
}

}  // namespace farfield::scene
