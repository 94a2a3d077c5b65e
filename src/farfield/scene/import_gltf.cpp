// glTF (.glb, .gltf) through tinygltf, so that the per-node "farfield" extras written by exportGlb (object name,
// footprint, parent) come back.
#include <dlfcn.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/scene/gltf_accessor.h"
#include "farfield/scene/import_readers.h"

namespace farfield::scene {

namespace detail {

// libdraco (linked by assimp) exports its own build of tinygltf under the same names. If it comes before
// libtinygltf in the dynamic lookup order, tinygltf calls land in a class of another layout and crash; the
// link order in src/farfield/CMakeLists.txt prevents that, and this check turns a regression into a clear
// message instead of a segmentation fault.
void checkTinygltfBinding() {
  static const bool ok = [] {
    Dl_info info{};
    if (!dladdr(reinterpret_cast<void*>(&tinygltf::LoadImageData), &info) || !info.dli_fname) return true;
    return std::strstr(info.dli_fname, "draco") == nullptr;
  }();
  FF_CHECK_MSG(ok, "tinygltf symbols resolve to libdraco: link ff_tinygltf before assimp");
}

}  // namespace detail

namespace {

namespace fs = std::filesystem;

// tinygltf hands every image's bytes (embedded or read from a file next to the model) to this callback; decoding
// here keeps one decoder for all formats. An image that does not decode is left empty and its reason kept in the
// map behind `user` (image index -> why): GltfReader gives its materials the placeholder. (Returning false would
// make tinygltf refuse the whole model.)
bool loadGltfImage(tinygltf::Image* image, const int image_idx, std::string*, std::string*, int, int,
                   const unsigned char* bytes, int size, void* user) {
  // An image in a buffer view is decoded by GltfReader::texture from gltfImageBytes: tinygltf does not check the
  // view against its buffer before calling here.
  if (image->bufferView >= 0) return true;
  std::string why;
  TexturePtr img = decodeImage(bytes, size_t(std::max(size, 0)), &why);
  if (!img) {
    (*static_cast<std::map<int, std::string>*>(user))[image_idx] = why;
    image->image.clear();
    image->width = image->height = -1;
    return true;
  }
  image->width = img->width();
  image->height = img->height();
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(reinterpret_cast<const unsigned char*>(img->data()),
                      reinterpret_cast<const unsigned char*>(img->data()) + img->pixelCount() * 4);
  return true;
}

class GltfReader {
 public:
  GltfReader(const std::string& path, const tinygltf::Model& model, const ImportOptions& options,
             const std::map<int, std::string>& undecodable, ImportStats& stats)
      : path_(path), model_(model), options_(options), undecodable_(undecodable), stats_(stats) {}

  Scene read() {
    readMaterials();
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int s = (model_.defaultScene >= 0 && size_t(model_.defaultScene) < model_.scenes.size())
                        ? model_.defaultScene
                        : 0;
      roots = model_.scenes[size_t(s)].nodes;
    } else {
      // No scene: every node that is nobody's child is a root.
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const tinygltf::Node& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && size_t(c) < model_.nodes.size()) is_child[size_t(c)] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(int(i));
    }
    for (int r : roots) visit(r, rootTransform(options_));

    // Parents recorded in the extras refer to object ids of the exporting scene; they survive when the objects
    // come back in the same order, which exportGlb guarantees (one node per object, in id order).
    for (auto& [object_index, parent] : parents_)
      if (parent > 0 && size_t(parent) <= scene_.objects.size() && uint32_t(parent) != object_index + 1)
        scene_.objects[object_index].parent = uint32_t(parent);

    stats_.skipped_faces += skipped_primitives_;
    return std::move(scene_);
  }

 private:
  [[noreturn]] void fail(const std::string& message) const { throw Error(path_, message); }

  TexturePtr texture(int texture_index, std::string* texture_path) {
    if (texture_index < 0 || size_t(texture_index) >= model_.textures.size())
      fail("texture index " + std::to_string(texture_index) + " out of range");
    const int source = model_.textures[size_t(texture_index)].source;
    if (source < 0 || size_t(source) >= model_.images.size())
      fail("texture " + std::to_string(texture_index) + ": image index " + std::to_string(source) +
           " out of range");
    const tinygltf::Image& img = model_.images[size_t(source)];
    *texture_path = img.uri.rfind("data:", 0) == 0 ? std::string() : img.uri;
    auto it = images_.find(source);
    if (it != images_.end()) {
      if (TextureFiles::isPlaceholder(it->second)) ++stats_.placeholder_materials;
      return it->second;
    }
    std::string view_why;  // why an image in a buffer view gives no texture
    if (img.bufferView >= 0) {
      const std::span<const unsigned char> bytes = gltfImageBytes(model_, source, &view_why);
      if (!bytes.empty())
        if (TexturePtr decoded = decodeImage(bytes.data(), bytes.size(), &view_why)) return images_[source] = decoded;
      if (view_why.empty()) view_why = "no image data";
    }
    if (img.image.empty() || img.width <= 0 || img.height <= 0) {
      // tinygltf leaves an external image it could not find empty, with only a warning; loadGltfImage leaves an
      // undecodable one empty, and one in a buffer view to the lines above.
      texture_path->clear();
      const bool external = !img.uri.empty() && img.uri.rfind("data:", 0) != 0;
      const std::string label = external ? img.uri : !img.name.empty() ? img.name : "image " + std::to_string(source);
      auto why = undecodable_.find(source);
      const std::string reason =
          !view_why.empty()        ? view_why
          : why != undecodable_.end() ? why->second
          : external ? "no file " + (fs::path(path_).parent_path() / img.uri).string() + " (or not readable)"
                     : "no image data";
      stats_.missing_textures.push_back({label, reason});
      ++stats_.placeholder_materials;
      return images_[source] = checkerboardTexture();
    }
    if (img.component != 4 || img.bits != 8 ||
        img.image.size() != size_t(img.width) * size_t(img.height) * 4)
      fail("image " + std::to_string(source) + ": unexpected pixel layout");
    auto out = std::make_shared<image::ColorImage>(img.width, img.height);
    std::memcpy(out->data(), img.image.data(), img.image.size());
    images_[source] = out;
    return out;
  }

  void readMaterials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const tinygltf::Material& gm = model_.materials[i];
      Material m;
      m.name = gm.name.empty() ? "material_" + std::to_string(i) : gm.name;
      const std::vector<double>& f = gm.pbrMetallicRoughness.baseColorFactor;
      if (f.size() == 4) m.base_color = Vec4(float(f[0]), float(f[1]), float(f[2]), float(f[3]));
      if (!isFinite(Vec3(m.base_color)) || !std::isfinite(m.base_color.w))
        fail("material '" + m.name + "': non-finite base colour");
      if (gm.pbrMetallicRoughness.baseColorTexture.index >= 0)
        m.texture = texture(gm.pbrMetallicRoughness.baseColorTexture.index, &m.texture_path);
      m.double_sided = gm.doubleSided;
      m.unlit = gm.extensions.count("KHR_materials_unlit") > 0;
      scene_.addMaterial(std::move(m));
    }
  }

  uint32_t defaultMaterial() {
    if (default_material_ < 0) {
      Material m;
      m.name = "default";
      default_material_ = int64_t(scene_.addMaterial(std::move(m)));
    }
    return uint32_t(default_material_);
  }

  using View = GltfView;

  View view(int accessor_index, const std::string& what) const {
    return gltfAccessor(model_, accessor_index, what, path_);
  }

  static float component(const View& v, size_t i, int c) { return float(gltfComponent(v, i, c)); }

  static uint32_t indexAt(const View& v, size_t i) {
    const unsigned char* p = v.data + i * v.stride;
    switch (v.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s;
        std::memcpy(&s, p, 2);
        return s;
      }
      default: {
        uint32_t u;
        std::memcpy(&u, p, 4);
        return u;
      }
    }
  }

  // Returns false (and counts it) for primitives that are not triangles.
  bool readPrimitive(const tinygltf::Primitive& prim, const std::string& what, Mesh* mesh) const {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN)
      return false;
    auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) fail(what + ": no POSITION attribute");
    const View pos = view(pos_it->second, what + " POSITION");
    if (pos.components != 3 || pos.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail(what + ": POSITION must be VEC3 of floats");
    mesh->positions.resize(pos.count);
    for (size_t i = 0; i < pos.count; ++i)
      mesh->positions[i] = Vec3(component(pos, i, 0), component(pos, i, 1), component(pos, i, 2));

    if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      const View nv = view(it->second, what + " NORMAL");
      if (nv.components != 3 || nv.count != pos.count) fail(what + ": NORMAL must be VEC3, one per vertex");
      mesh->normals.resize(nv.count);
      for (size_t i = 0; i < nv.count; ++i)
        mesh->normals[i] = Vec3(component(nv, i, 0), component(nv, i, 1), component(nv, i, 2));
    }
    if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
      const View tv = view(it->second, what + " TEXCOORD_0");
      if (tv.components != 2 || tv.count != pos.count) fail(what + ": TEXCOORD_0 must be VEC2, one per vertex");
      mesh->uvs.resize(tv.count);
      for (size_t i = 0; i < tv.count; ++i) mesh->uvs[i] = Vec2(component(tv, i, 0), component(tv, i, 1));
    }

    std::vector<uint32_t> raw;
    if (prim.indices >= 0) {
      const View iv = view(prim.indices, what + " indices");
      if (iv.components != 1 || (iv.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                 iv.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                 iv.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(what + ": indices must be unsigned scalars");
      raw.resize(iv.count);
      for (size_t i = 0; i < iv.count; ++i) raw[i] = indexAt(iv, i);
    } else {
      raw.resize(pos.count);
      for (size_t i = 0; i < pos.count; ++i) raw[i] = uint32_t(i);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (raw.size() % 3 != 0)
        fail(what + ": " + std::to_string(raw.size()) + " triangle indices, not a multiple of 3");
      mesh->indices = std::move(raw);
    } else {
      for (size_t i = 0; i + 2 < raw.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
          mesh->indices.insert(mesh->indices.end(), {raw[0], raw[i + 1], raw[i + 2]});
        else if (i % 2 == 0)  // strips alternate their winding
          mesh->indices.insert(mesh->indices.end(), {raw[i], raw[i + 1], raw[i + 2]});
        else
          mesh->indices.insert(mesh->indices.end(), {raw[i + 1], raw[i], raw[i + 2]});
      }
    }
    mesh->validate(path_ + ": " + what);
    if (mesh->normals.empty()) mesh->computeNormals();
    return true;
  }

  // Scene mesh for a glTF (mesh, primitive) pair, converted once and shared by every node that uses it.
  int64_t sceneMesh(int mesh_index, int prim_index) {
    const auto key = std::make_pair(mesh_index, prim_index);
    if (auto it = meshes_.find(key); it != meshes_.end()) return it->second;
    const tinygltf::Mesh& gm = model_.meshes[size_t(mesh_index)];
    const std::string what = "mesh " + std::to_string(mesh_index) + (gm.name.empty() ? "" : " '" + gm.name + "'") +
                             " primitive " + std::to_string(prim_index);
    Mesh mesh;
    int64_t index = -1;
    if (readPrimitive(gm.primitives[size_t(prim_index)], what, &mesh))
      index = int64_t(scene_.addMesh(std::move(mesh)));
    else
      ++skipped_primitives_;
    meshes_[key] = index;
    return index;
  }

  static Mat4 localMatrix(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) {
      Mat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = float(n.matrix[size_t(c * 4 + r)]);
      return m;
    }
    Mat4 m(1.0f);
    if (n.translation.size() == 3)
      m = glm::translate(m, Vec3(float(n.translation[0]), float(n.translation[1]), float(n.translation[2])));
    if (n.rotation.size() == 4)
      m = m * glm::mat4_cast(glm::quat(float(n.rotation[3]), float(n.rotation[0]), float(n.rotation[1]),
                                       float(n.rotation[2])));
    if (n.scale.size() == 3) m = glm::scale(m, Vec3(float(n.scale[0]), float(n.scale[1]), float(n.scale[2])));
    return m;
  }

  void visit(int node_index, const Mat4& parent) {
    if (node_index < 0 || size_t(node_index) >= model_.nodes.size())
      fail("node index " + std::to_string(node_index) + " out of range");
    // glTF nodes form a forest: a node reached twice has two parents or lies on a cycle. Refusing it also keeps
    // a malicious file from making the traversal exponential.
    if (visited_.empty()) visited_.assign(model_.nodes.size(), false);
    if (visited_[size_t(node_index)])
      fail("node " + std::to_string(node_index) + " is reached twice (a node may have one parent and no cycles)");
    visited_[size_t(node_index)] = true;
    const tinygltf::Node& node = model_.nodes[size_t(node_index)];
    const Mat4 world = parent * localMatrix(node);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(world[c][r])) fail("node " + std::to_string(node_index) + ": non-finite transform");

    std::vector<Part> parts;
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size())
        fail("node " + std::to_string(node_index) + ": mesh " + std::to_string(node.mesh) + " out of range");
      const tinygltf::Mesh& gm = model_.meshes[size_t(node.mesh)];
      for (size_t p = 0; p < gm.primitives.size(); ++p) {
        const int64_t mesh = sceneMesh(node.mesh, int(p));
        if (mesh < 0) continue;
        const int mat = gm.primitives[p].material;
        const uint32_t material =
            (mat >= 0 && size_t(mat) < model_.materials.size()) ? uint32_t(mat) : defaultMaterial();
        parts.push_back({uint32_t(mesh), material});
      }
    }

    const tinygltf::Value* ff = nullptr;
    if (node.extras.IsObject() && node.extras.Has("farfield") && node.extras.Get("farfield").IsObject())
      ff = &node.extras.Get("farfield");

    if (!parts.empty() || ff) {
      Object base;
      base.name = !node.name.empty() ? node.name
                  : node.mesh >= 0     ? model_.meshes[size_t(node.mesh)].name
                                       : std::string();
      base.transform = world;
      int parent_id = 0;
      if (ff) readFarfieldExtras(*ff, node_index, &base, &parent_id);
      if (options_.one_object_per_node || parts.size() <= 1) {
        base.parts = parts;
        const uint32_t id = scene_.addObject(std::move(base));
        if (parent_id > 0) parents_.emplace_back(id - 1, parent_id);
      } else {
        for (size_t p = 0; p < parts.size(); ++p) {
          Object o = base;
          o.name = base.name + "/" + std::to_string(p);
          o.parts = {parts[p]};
          scene_.addObject(std::move(o));
        }
      }
    }
    for (int child : node.children) visit(child, world);
  }

  void readFarfieldExtras(const tinygltf::Value& ff, int node_index, Object* object, int* parent_id) const {
    const std::string where = "node " + std::to_string(node_index) + " extras.farfield";
    if (ff.Has("name") && ff.Get("name").IsString()) object->name = ff.Get("name").Get<std::string>();
    if (ff.Has("parent") && ff.Get("parent").IsNumber()) *parent_id = int(ff.Get("parent").GetNumberAsInt());
    if (!ff.Has("footprint")) return;
    const tinygltf::Value& fp = ff.Get("footprint");
    if (!fp.IsArray()) fail(where + ": footprint must be an array of [x, y] points");
    for (size_t k = 0; k < fp.ArrayLen(); ++k) {
      const tinygltf::Value& pt = fp.Get(int(k));
      if (!pt.IsArray() || pt.ArrayLen() != 2 || !pt.Get(0).IsNumber() || !pt.Get(1).IsNumber())
        fail(where + ": footprint point " + std::to_string(k) + " must be [x, y]");
      const Vec2 p(float(pt.Get(0).GetNumberAsDouble()), float(pt.Get(1).GetNumberAsDouble()));
      if (!isFinite(p)) fail(where + ": footprint point " + std::to_string(k) + " is not finite");
      object->footprint.push_back(p);
    }
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  const ImportOptions& options_;
  const std::map<int, std::string>& undecodable_;
  ImportStats& stats_;
  Scene scene_;
  std::map<std::pair<int, int>, int64_t> meshes_;
  std::map<int, TexturePtr> images_;
  std::vector<std::pair<uint32_t, int>> parents_;  // (object index, parent id from the extras)
  std::vector<bool> visited_;
  int64_t default_material_ = -1;
  size_t skipped_primitives_ = 0;
};

}  // namespace

Scene importGltf(const std::string& path, bool binary, const ImportOptions& options, ImportStats& stats) {
  detail::checkTinygltfBinding();
  tinygltf::TinyGLTF loader;
  std::map<int, std::string> undecodable;
  loader.SetImageLoader(&loadGltfImage, &undecodable);
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                         : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
  if (!ok)
    throw Error(path,
                "cannot read glTF (truncated or corrupt file?): " + (err.empty() ? std::string("no details") : err));
  if (!warn.empty()) FF_DEBUG(path << ": tinygltf: " << warn);
  Scene scene = GltfReader(path, model, options, undecodable, stats).read();
  checkEmpty(scene, path);
  return scene;
}

}  // namespace farfield::scene
