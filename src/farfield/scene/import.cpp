// Scene import. glTF (.glb, .gltf) is read with tinygltf so that the per-node "farfield" extras written by
// exportGlb (object name, footprint, parent) come back; every other format goes through assimp. Both paths
// flatten the node hierarchy into one Object per node with its world transform, decode textures with stb_image
// into RGBA8, and rotate Y-up files to Farfield's Z up. A texture that cannot be read is a counted warning with a
// checkerboard in its place (TextureFiles), never a failed import: real models often lose a texture or two.
#include "farfield/scene/import.h"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <stb_image.h>
#include <dlfcn.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/scene/gltf_accessor.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/off_check.h"

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
using TexturePtr = std::shared_ptr<const image::ColorImage>;

// Y-up file coordinates (x, y, z) become Z-up world coordinates (x, -z, y): a +90 degree turn about x, so
// handedness and winding are kept.
const Mat4 kYUpToZUp(Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, -1, 0, 0), Vec4(0, 0, 0, 1));

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

Mat4 rootTransform(const ImportOptions& options) { return options.up_axis == 'z' ? Mat4(1.0f) : kYUpToZUp; }

// Decodes PNG, JPEG, TGA, BMP, ... bytes into RGBA8; null with `why` set on failure.
TexturePtr decodeImage(const unsigned char* bytes, size_t size, std::string* why) {
  if (size == 0 || size > size_t(std::numeric_limits<int>::max())) {
    *why = "empty or oversized image data";
    return nullptr;
  }
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load_from_memory(bytes, int(size), &w, &h, &n, 4);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    *why = std::string("cannot decode image (") + (reason ? reason : "unknown reason") + ")";
    return nullptr;
  }
  auto img = std::make_shared<image::ColorImage>(w, h);
  std::memcpy(img->data(), pixels, size_t(w) * size_t(h) * 4);
  stbi_image_free(pixels);
  return img;
}

// Reads an image file into RGBA8; null with `why` set on failure.
TexturePtr readImageFile(const fs::path& file, std::string* why) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    *why = "no file " + file.string();
    return nullptr;
  }
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load(file.string().c_str(), &w, &h, &n, 4);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    *why = file.string() + ": cannot decode image (" + (reason ? reason : "unknown reason") + ")";
    return nullptr;
  }
  auto img = std::make_shared<image::ColorImage>(w, h);
  std::memcpy(img->data(), pixels, size_t(w) * size_t(h) * 4);
  stbi_image_free(pixels);
  return img;
}

void checkEmpty(const Scene& scene, const std::string& path) {
  if (scene.triangleCount() == 0) throw Error(path, "empty scene: no triangles");
}

// ---------------------------------------------------------------------------------------------------------------
// glTF through tinygltf

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
    throw Error(path, "cannot read glTF (truncated or corrupt file?): " + (err.empty() ? std::string("no details") : err));
  if (!warn.empty()) FF_DEBUG(path << ": tinygltf: " << warn);
  Scene scene = GltfReader(path, model, options, undecodable, stats).read();
  checkEmpty(scene, path);
  return scene;
}

// ---------------------------------------------------------------------------------------------------------------
// Everything else through assimp

class AssimpReader {
 public:
  AssimpReader(const std::string& path, const aiScene& ai, const ImportOptions& options, ImportStats& stats)
      : path_(path), ai_(ai), options_(options), dir_(fs::path(path).parent_path()), stats_(stats), files_(stats) {}

  Scene read() {
    for (unsigned i = 0; i < ai_.mNumMaterials; ++i) scene_.addMaterial(material(*ai_.mMaterials[i], i));
    mesh_map_.assign(ai_.mNumMeshes, -1);
    for (unsigned i = 0; i < ai_.mNumMeshes; ++i) {
      Mesh mesh;
      if (convertMesh(*ai_.mMeshes[i], i, &mesh)) mesh_map_[i] = int64_t(scene_.addMesh(std::move(mesh)));
    }
    if (ai_.mRootNode) visit(*ai_.mRootNode, rootTransform(options_));
    stats_.skipped_faces += skipped_faces_;
    return std::move(scene_);
  }

 private:
  [[noreturn]] void fail(const std::string& message) const { throw Error(path_, message); }

  static Mat4 toGlm(const aiMatrix4x4& a) {
    // aiMatrix4x4 is row-major (a1..a4 is the first row); glm is indexed [column][row].
    const float* rows = &a.a1;
    Mat4 m;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m[c][r] = rows[r * 4 + c];
    return m;
  }

  TexturePtr embeddedTexture(const aiTexture& tex, const std::string& label) {
    if (tex.mHeight == 0)  // compressed (PNG, JPEG, ...): mWidth is the byte count
      return files_.decode("embedded texture " + label, reinterpret_cast<const unsigned char*>(tex.pcData),
                           tex.mWidth);
    auto raw = std::make_shared<image::ColorImage>(int(tex.mWidth), int(tex.mHeight));
    for (size_t i = 0; i < raw->pixelCount(); ++i) {
      const aiTexel& t = tex.pcData[i];
      raw->pixels()[i] = image::Rgba8(t.r, t.g, t.b, t.a);
    }
    return raw;
  }

  TexturePtr fileTexture(const std::string& name, std::string* resolved_out) {
    std::string rel = name;
    std::replace(rel.begin(), rel.end(), '\\', '/');
    fs::path p = fs::path(rel).is_absolute() ? fs::path(rel) : dir_ / rel;
    // Models moved from another machine often keep absolute or foreign paths; the file next to the model is
    // the next best guess.
    std::error_code ec;
    if (!fs::exists(p, ec) && fs::exists(dir_ / fs::path(rel).filename(), ec)) p = dir_ / fs::path(rel).filename();
    TexturePtr img = files_.load(name, p);
    *resolved_out = TextureFiles::isPlaceholder(img) ? std::string() : p.string();
    return img;
  }

  Material material(const aiMaterial& am, unsigned index) {
    Material m;
    aiString name;
    m.name = (am.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0) ? std::string(name.C_Str())
                                                                             : "material_" + std::to_string(index);
    aiColor4D c;
    if (am.Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || am.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
      m.base_color = Vec4(c.r, c.g, c.b, c.a);
    float opacity = 1.0f;
    if (am.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && opacity >= 0.0f && opacity <= 1.0f)
      m.base_color.a = opacity;
    if (!isFinite(Vec3(m.base_color)) || !std::isfinite(m.base_color.a))
      fail("material '" + m.name + "': non-finite colour");
    int two_sided = 0;
    if (am.Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS) m.double_sided = two_sided != 0;
    int shading = 0;
    if (am.Get(AI_MATKEY_SHADING_MODEL, shading) == AI_SUCCESS) m.unlit = shading == aiShadingMode_NoShading;

    const aiTextureType type =
        am.GetTextureCount(aiTextureType_BASE_COLOR) > 0 ? aiTextureType_BASE_COLOR : aiTextureType_DIFFUSE;
    aiString tex_path;
    if (am.GetTextureCount(type) > 0 && am.GetTexture(type, 0, &tex_path) == AI_SUCCESS && tex_path.length > 0) {
      const std::string t = tex_path.C_Str();
      if (const aiTexture* emb = ai_.GetEmbeddedTexture(t.c_str())) {
        auto it = embedded_.find(t);
        m.texture = it != embedded_.end() ? it->second : (embedded_[t] = embeddedTexture(*emb, t));
        if (it != embedded_.end() && TextureFiles::isPlaceholder(m.texture)) ++stats_.placeholder_materials;
      } else if (!t.empty() && t[0] == '*') {
        // A reference to an embedded texture the file does not hold: a missing texture like any other.
        m.texture = files_.placeholder(t, "the file holds no such embedded texture");
      } else {
        m.texture = fileTexture(t, &m.texture_path);
      }
    }
    return m;
  }

  bool convertMesh(const aiMesh& am, unsigned index, Mesh* mesh) {
    const std::string what =
        "mesh " + std::to_string(index) + (am.mName.length > 0 ? " '" + std::string(am.mName.C_Str()) + "'" : "");
    mesh->positions.resize(am.mNumVertices);
    for (unsigned i = 0; i < am.mNumVertices; ++i)
      mesh->positions[i] = Vec3(am.mVertices[i].x, am.mVertices[i].y, am.mVertices[i].z);
    if (am.mNormals) {
      mesh->normals.resize(am.mNumVertices);
      for (unsigned i = 0; i < am.mNumVertices; ++i)
        mesh->normals[i] = Vec3(am.mNormals[i].x, am.mNormals[i].y, am.mNormals[i].z);
    }
    if (am.mTextureCoords[0]) {
      mesh->uvs.resize(am.mNumVertices);
      for (unsigned i = 0; i < am.mNumVertices; ++i)
        mesh->uvs[i] = Vec2(am.mTextureCoords[0][i].x, am.mTextureCoords[0][i].y);
    }
    for (unsigned f = 0; f < am.mNumFaces; ++f) {
      const aiFace& face = am.mFaces[f];
      if (face.mNumIndices != 3) {
        ++skipped_faces_;
        continue;
      }
      mesh->indices.insert(mesh->indices.end(), {face.mIndices[0], face.mIndices[1], face.mIndices[2]});
    }
    if (mesh->indices.empty()) return false;
    mesh->validate(path_ + ": " + what);
    if (mesh->normals.empty()) mesh->computeNormals();
    return true;
  }

  void visit(const aiNode& node, const Mat4& parent) {
    const Mat4 world = parent * toGlm(node.mTransformation);
    std::vector<Part> parts;
    for (unsigned k = 0; k < node.mNumMeshes; ++k) {
      const unsigned mi = node.mMeshes[k];
      if (mi >= mesh_map_.size() || mesh_map_[mi] < 0) continue;
      const unsigned mat = ai_.mMeshes[mi]->mMaterialIndex;
      if (mat >= scene_.materials.size()) fail("mesh " + std::to_string(mi) + ": material index out of range");
      parts.push_back({uint32_t(mesh_map_[mi]), mat});
    }
    if (!parts.empty()) {
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          if (!std::isfinite(world[c][r]))
            fail("node '" + std::string(node.mName.C_Str()) + "': non-finite transform");
      if (options_.one_object_per_node) {
        Object o;
        o.name = node.mName.C_Str();
        o.transform = world;
        o.parts = parts;
        scene_.addObject(std::move(o));
      } else {
        for (size_t k = 0; k < parts.size(); ++k) {
          Object o;
          o.name = std::string(node.mName.C_Str()) + "/" + ai_.mMeshes[node.mMeshes[k]]->mName.C_Str();
          o.transform = world;
          o.parts = {parts[k]};
          scene_.addObject(std::move(o));
        }
      }
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c)
      if (node.mChildren[c]) visit(*node.mChildren[c], world);
  }

  const std::string& path_;
  const aiScene& ai_;
  const ImportOptions& options_;
  fs::path dir_;
  ImportStats& stats_;
  TextureFiles files_;
  Scene scene_;
  std::vector<int64_t> mesh_map_;
  std::map<std::string, TexturePtr> embedded_;
  size_t skipped_faces_ = 0;
};

std::string acceptedFormats(const Assimp::Importer& importer) {
  std::string list;
  importer.GetExtensionList(list);  // "*.3ds;*.obj;..."
  std::string out = ".glb, .gltf";
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ';')) {
    if (item.rfind("*", 0) == 0) item.erase(0, 1);
    if (item.empty() || item == ".glb" || item == ".gltf") continue;
    out += ", " + item;
  }
  return out;
}

bool isAc3d(const std::string& ext) { return ext == ".ac" || ext == ".acc" || ext == ".ac3d"; }

// AC3D allows one `texture` line per object. TORCS tracks list up to four (base, tiled, skids, shad; the last ones
// unquoted), and assimp 5.2 keeps the last line and reads an unquoted name as "ERROR", so every multi-textured
// object would lose its base texture. Keeping each object's first texture line gives the file's AC3D meaning.
// Returns the text to read and counts the objects that listed more than one.
std::string firstTexturePerObject(const std::string& path, size_t* objects_with_extra) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open file");
  std::string out, line;
  bool seen = false, counted = false;
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(" \t");
    const std::string_view word = start == std::string::npos ? std::string_view() : std::string_view(line).substr(start);
    if (word.rfind("OBJECT", 0) == 0) {
      seen = counted = false;
    } else if (word.rfind("texture", 0) == 0 && (word.size() == 7 || word[7] == ' ' || word[7] == '\t')) {
      if (seen) {
        if (!counted) ++*objects_with_extra;
        counted = true;
        continue;
      }
      seen = true;
    }
    out += line;
    out += '\n';
  }
  if (in.bad()) throw Error(path, "read error");
  return out;
}

Scene importAssimp(const std::string& path, const ImportOptions& options, ImportStats& stats) {
  Assimp::Importer importer;
  // Points and lines carry no surface: the SortByPType step drops them. Faces that still are not triangles are
  // counted and reported by AssimpReader.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // Read without post-processing first: non-finite coordinates must be reported before normal generation or
  // vertex joining turn them into something harder to trace.
  const aiScene* raw = nullptr;
  if (const std::string ext = lowerExtension(path); isAc3d(ext)) {
    const std::string text = firstTexturePerObject(path, &stats.extra_ac3d_textures);
    raw = importer.ReadFileFromMemory(text.data(), text.size(), 0, "ac");
  } else {
    raw = importer.ReadFile(path, 0);
  }
  if (!raw) throw Error(path, std::string("cannot read: ") + importer.GetErrorString());
  for (unsigned m = 0; m < raw->mNumMeshes; ++m) {
    const aiMesh& am = *raw->mMeshes[m];
    for (unsigned i = 0; i < am.mNumVertices; ++i)
      if (!std::isfinite(am.mVertices[i].x) || !std::isfinite(am.mVertices[i].y) || !std::isfinite(am.mVertices[i].z))
        throw Error(path, "mesh " + std::to_string(m) +
                              (am.mName.length > 0 ? " '" + std::string(am.mName.C_Str()) + "'" : "") + ": vertex " +
                              std::to_string(i) + ": non-finite coordinate");
  }
  // Some loaders (OBJ with a two-vertex face among polygons) mis-report a mesh's primitive types, which makes
  // validation refuse a usable file and keeps SortByPType from dropping the lines. The scene is still the
  // importer's to change before post-processing, so the flags are recomputed from the faces.
  size_t surface_faces = 0;
  for (unsigned m = 0; m < raw->mNumMeshes; ++m) {
    aiMesh& am = *raw->mMeshes[m];
    unsigned types = 0;
    for (unsigned f = 0; f < am.mNumFaces; ++f) {
      const unsigned n = am.mFaces[f].mNumIndices;
      surface_faces += n >= 3;
      types |= n == 1 ? aiPrimitiveType_POINT : n == 2 ? aiPrimitiveType_LINE : n == 3 ? aiPrimitiveType_TRIANGLE
                                                                                     : aiPrimitiveType_POLYGON;
    }
    am.mPrimitiveTypes = types;
  }
  if (surface_faces == 0) throw Error(path, "empty scene: no triangles (only points, lines or nothing)");
  const aiScene* ai = importer.ApplyPostProcessing(
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_GenSmoothNormals | aiProcess_SortByPType |
      aiProcess_FlipUVs | aiProcess_ValidateDataStructure);
  if (!ai) throw Error(path, std::string("invalid or truncated data: ") + importer.GetErrorString());
  Scene scene = AssimpReader(path, *ai, options, stats).read();
  checkEmpty(scene, path);
  return scene;
}

}  // namespace

Scene importScene(const std::string& path, const ImportOptions& options, ImportStats* stats) {
  if (options.up_axis != 'y' && options.up_axis != 'z')
    throw Error(path, std::string("up axis must be 'y' or 'z', not '") + options.up_axis + "'");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path, "file not found");
  if (!fs::is_regular_file(path, ec)) throw Error(path, "not a regular file");
  const std::string ext = lowerExtension(path);
  ImportStats local;
  ImportStats& st = stats ? *stats : local;
  Scene scene;
  if (ext == ".glb" || ext == ".gltf") {
    scene = importGltf(path, ext == ".glb", options, st);
  } else {
    Assimp::Importer probe;
    if (ext.empty() || !probe.IsExtensionSupported(ext))
      throw Error(path, "unknown scene format '" + ext + "' (accepted: " + acceptedFormats(probe) + ")");
    if (ext == ".off") checkOffFile(path);  // assimp's OFF reader crashes on some damaged files
    scene = importAssimp(path, options, st);
  }
  if (!stats)
    for (const std::string& w : local.warnings()) FF_WARN(path << ": " << w);
  return scene;
}

Scene loadScene(const std::string& spec, const ImportOptions& options, ImportStats* stats) {
  constexpr const char* kBuiltin = "builtin:";
  if (spec.rfind(kBuiltin, 0) == 0) return builtinScene(spec.substr(std::strlen(kBuiltin)));
  return importScene(spec, options, stats);
}

// ---------------------------------------------------------------------------------------------------------------
// Counted warnings and the placeholder

std::vector<std::string> ImportStats::warnings(size_t max_names) const {
  std::vector<std::string> out;
  if (!missing_textures.empty()) {
    const size_t n = missing_textures.size();
    std::string line = std::to_string(n) + (n == 1 ? " texture" : " textures") +
                       " missing or unreadable (checkerboard placeholders on " + std::to_string(placeholder_materials) +
                       (placeholder_materials == 1 ? " material" : " materials") + "): ";
    for (size_t i = 0; i < n && i < max_names; ++i) line += (i ? ", " : "") + missing_textures[i].name;
    if (n > max_names) line += ", ... and " + std::to_string(n - max_names) + " more";
    out.push_back(line);
    // The first reason says why in the words of the file system or the decoder.
    out.push_back("  (" + missing_textures[0].name + ": " + missing_textures[0].reason + ")");
  }
  if (skipped_faces > 0)
    out.push_back(std::to_string(skipped_faces) + " face(s) that are not triangles skipped (points, lines)");
  if (extra_ac3d_textures > 0)
    out.push_back(std::to_string(extra_ac3d_textures) +
                  " AC3D objects list several textures (multi-texturing extension): the first of each is used");
  return out;
}

void ImportStats::merge(const ImportStats& other) {
  for (const MissingTexture& m : other.missing_textures)
    if (std::none_of(missing_textures.begin(), missing_textures.end(),
                     [&](const MissingTexture& k) { return k.name == m.name; }))
      missing_textures.push_back(m);
  placeholder_materials += other.placeholder_materials;
  skipped_faces += other.skipped_faces;
  extra_ac3d_textures += other.extra_ac3d_textures;
}

std::shared_ptr<const image::ColorImage> checkerboardTexture() {
  static const std::shared_ptr<const image::ColorImage> board = [] {
    constexpr int kSize = 64, kSquare = 8;
    auto img = std::make_shared<image::ColorImage>(kSize, kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        img->at(x, y) = ((x / kSquare + y / kSquare) % 2 == 0) ? image::Rgba8(255, 0, 255, 255)
                                                                : image::Rgba8(24, 24, 24, 255);
    return img;
  }();
  return board;
}

bool TextureFiles::isPlaceholder(const std::shared_ptr<const image::ColorImage>& texture) {
  return texture && texture == checkerboardTexture();
}

std::shared_ptr<const image::ColorImage> TextureFiles::placeholder(const std::string& name, const std::string& reason) {
  if (std::none_of(stats_.missing_textures.begin(), stats_.missing_textures.end(),
                   [&](const ImportStats::MissingTexture& m) { return m.name == name; }))
    stats_.missing_textures.push_back({name, reason});
  ++stats_.placeholder_materials;
  return checkerboardTexture();
}

std::shared_ptr<const image::ColorImage> TextureFiles::load(const std::string& name, const fs::path& file) {
  const std::string key = file.lexically_normal().string();
  if (auto it = files_.find(key); it != files_.end()) {
    if (isPlaceholder(it->second)) ++stats_.placeholder_materials;
    return it->second;
  }
  std::string why;
  TexturePtr img = readImageFile(file, &why);
  if (!img) img = placeholder(name, why);
  return files_[key] = img;
}

std::shared_ptr<const image::ColorImage> TextureFiles::decode(const std::string& name, const unsigned char* bytes,
                                                              size_t size) {
  std::string why;
  TexturePtr img = decodeImage(bytes, size, &why);
  return img ? img : placeholder(name, why);
}

}  // namespace farfield::scene
