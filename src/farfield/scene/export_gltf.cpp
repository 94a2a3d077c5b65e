// Scene export to binary glTF through tinygltf. One buffer holds every mesh's vertex and index data and the
// PNG-encoded textures; each object becomes one root node whose matrix is its transform turned to glTF's Y up,
// with the Farfield-only data (name, footprint, parent) in the node's extras under "farfield", which
// importScene reads back.
#include "farfield/scene/export_gltf.h"

#include <stb_image_write.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::scene {

namespace detail {
void checkTinygltfBinding();  // import.cpp
}  // namespace detail

namespace {

// Inverse of the importer's Y-up to Z-up turn: world (x, y, z) is written as glTF (x, z, -y).
const Mat4 kZUpToYUp(Vec4(1, 0, 0, 0), Vec4(0, 0, -1, 0), Vec4(0, 1, 0, 0), Vec4(0, 0, 0, 1));

class GlbWriter {
 public:
  GlbWriter(const Scene& scene, const std::string& path) : scene_(scene), path_(path) {
    model_.asset.version = "2.0";
    model_.asset.generator = "Farfield";
    model_.buffers.emplace_back();
  }

  tinygltf::Model build() {
    for (size_t i = 0; i < scene_.meshes.size(); ++i) writeMesh(i);
    for (const Material& m : scene_.materials) writeMaterial(m);
    tinygltf::Scene root;
    for (const Object& o : scene_.objects) root.nodes.push_back(writeNode(o));
    model_.scenes.push_back(root);
    model_.defaultScene = 0;
    if (model_.buffers[0].data.size() > size_t(std::numeric_limits<uint32_t>::max()) - 1024)
      throw Error(path_, "scene data exceeds the 4 GiB limit of a .glb file");
    return std::move(model_);
  }

 private:
  struct MeshAccessors {
    int position = -1, normal = -1, uv = -1, indices = -1;
  };

  // Appends bytes to the single buffer at a 4-byte boundary and returns a buffer view over them.
  int addView(const void* data, size_t bytes, int target) {
    std::vector<unsigned char>& buf = model_.buffers[0].data;
    while (buf.size() % 4 != 0) buf.push_back(0);
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = buf.size();
    bv.byteLength = bytes;
    bv.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    model_.bufferViews.push_back(bv);
    return int(model_.bufferViews.size() - 1);
  }

  int addAccessor(int view, int component_type, int type, size_t count) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component_type;
    a.type = type;
    a.count = count;
    model_.accessors.push_back(a);
    return int(model_.accessors.size() - 1);
  }

  void writeMesh(size_t index) {
    const Mesh& src = scene_.meshes[index];
    MeshAccessors acc;
    if (src.positions.empty() || src.indices.empty()) {
      accessors_.push_back(acc);
      return;
    }
    src.validate(path_ + ": mesh " + std::to_string(index));
    acc.position = addAccessor(addView(src.positions.data(), src.positions.size() * sizeof(Vec3),
                                       TINYGLTF_TARGET_ARRAY_BUFFER),
                               TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, src.positions.size());
    // glTF requires min and max on POSITION accessors.
    Box3 b;
    for (const Vec3& p : src.positions) b.expand(p);
    model_.accessors[size_t(acc.position)].minValues = {b.lo.x, b.lo.y, b.lo.z};
    model_.accessors[size_t(acc.position)].maxValues = {b.hi.x, b.hi.y, b.hi.z};
    std::vector<Vec3> computed;
    const std::vector<Vec3>* normals = &src.normals;
    if (src.normals.size() != src.positions.size()) {
      Mesh copy = src;
      copy.computeNormals();
      computed = std::move(copy.normals);
      normals = &computed;
    }
    acc.normal = addAccessor(addView(normals->data(), normals->size() * sizeof(Vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, normals->size());
    if (src.uvs.size() == src.positions.size())
      acc.uv = addAccessor(addView(src.uvs.data(), src.uvs.size() * sizeof(Vec2), TINYGLTF_TARGET_ARRAY_BUFFER),
                           TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, src.uvs.size());
    acc.indices = addAccessor(addView(src.indices.data(), src.indices.size() * sizeof(uint32_t),
                                      TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, src.indices.size());
    accessors_.push_back(acc);
  }

  static void appendBytes(void* context, void* data, int size) {
    auto* out = static_cast<std::vector<unsigned char>*>(context);
    const auto* p = static_cast<const unsigned char*>(data);
    out->insert(out->end(), p, p + size);
  }

  // glTF texture index for an image, PNG-encoded into the buffer once however many materials share it.
  int textureFor(const image::ColorImage& img, const std::string& name) {
    if (auto it = textures_.find(&img); it != textures_.end()) return it->second;
    if (img.empty()) throw Error(path_, "texture '" + name + "' is empty");
    std::vector<unsigned char> png;
    if (!stbi_write_png_to_func(&GlbWriter::appendBytes, &png, img.width(), img.height(), 4, img.data(),
                                img.width() * 4))
      throw Error(path_, "cannot encode texture '" + name + "' as PNG");
    tinygltf::Image gi;
    gi.name = name;
    gi.mimeType = "image/png";
    gi.bufferView = addView(png.data(), png.size(), 0);
    model_.images.push_back(gi);
    if (model_.samplers.empty()) {
      tinygltf::Sampler s;
      s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
      s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
      s.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;
      s.wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT;
      model_.samplers.push_back(s);
    }
    tinygltf::Texture t;
    t.source = int(model_.images.size() - 1);
    t.sampler = 0;
    model_.textures.push_back(t);
    const int index = int(model_.textures.size() - 1);
    textures_[&img] = index;
    return index;
  }

  void writeMaterial(const Material& m) {
    tinygltf::Material gm;
    gm.name = m.name;
    gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a};
    // Farfield shades diffusely; a rough dielectric is the closest glTF material.
    gm.pbrMetallicRoughness.metallicFactor = 0.0;
    gm.pbrMetallicRoughness.roughnessFactor = 1.0;
    gm.doubleSided = m.double_sided;
    if (m.base_color.a < 1.0f) gm.alphaMode = "BLEND";
    if (m.texture)
      gm.pbrMetallicRoughness.baseColorTexture.index =
          textureFor(*m.texture, m.texture_path.empty() ? m.name : m.texture_path);
    if (m.unlit) {
      gm.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
      if (std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), "KHR_materials_unlit") ==
          model_.extensionsUsed.end())
        model_.extensionsUsed.push_back("KHR_materials_unlit");
    }
    model_.materials.push_back(gm);
  }

  // One glTF mesh per distinct list of (mesh, material) parts; objects with the same parts share it.
  int gltfMesh(const Object& o) {
    std::vector<std::pair<uint32_t, uint32_t>> key;
    for (const Part& p : o.parts) key.emplace_back(p.mesh, p.material);
    if (auto it = meshes_.find(key); it != meshes_.end()) return it->second;
    tinygltf::Mesh gm;
    gm.name = o.name;
    for (const Part& p : o.parts) {
      if (p.mesh >= accessors_.size() || p.material >= scene_.materials.size())
        throw Error(path_, "object " + std::to_string(o.id) + ": part names a missing mesh or material");
      const MeshAccessors& acc = accessors_[p.mesh];
      if (acc.position < 0) continue;  // no triangles
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      prim.attributes["POSITION"] = acc.position;
      prim.attributes["NORMAL"] = acc.normal;
      if (acc.uv >= 0) prim.attributes["TEXCOORD_0"] = acc.uv;
      prim.indices = acc.indices;
      prim.material = int(p.material);
      gm.primitives.push_back(prim);
    }
    int index = -1;
    if (!gm.primitives.empty()) {
      model_.meshes.push_back(gm);
      index = int(model_.meshes.size() - 1);
    }
    meshes_[key] = index;
    return index;
  }

  int writeNode(const Object& o) {
    tinygltf::Node node;
    node.name = o.name;
    node.mesh = gltfMesh(o);
    // The importer applies kYUpToZUp above the node, so writing kZUpToYUp * transform gives back the transform.
    const Mat4 m = kZUpToYUp * o.transform;
    const bool identity = m == Mat4(1.0f);
    if (!identity) {
      node.matrix.resize(16);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) node.matrix[size_t(c * 4 + r)] = m[c][r];
    }
    tinygltf::Value::Object ff;
    ff["name"] = tinygltf::Value(o.name);
    if (o.parent != 0) ff["parent"] = tinygltf::Value(int(o.parent));
    if (!o.footprint.empty()) {
      tinygltf::Value::Array pts;
      for (const Vec2& p : o.footprint)
        pts.push_back(tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(double(p.x)), tinygltf::Value(double(p.y))}));
      ff["footprint"] = tinygltf::Value(std::move(pts));
    }
    tinygltf::Value::Object extras;
    extras["farfield"] = tinygltf::Value(std::move(ff));
    node.extras = tinygltf::Value(std::move(extras));
    model_.nodes.push_back(node);
    return int(model_.nodes.size() - 1);
  }

  const Scene& scene_;
  const std::string& path_;
  tinygltf::Model model_;
  std::vector<MeshAccessors> accessors_;
  std::map<const image::ColorImage*, int> textures_;
  std::map<std::vector<std::pair<uint32_t, uint32_t>>, int> meshes_;
};

}  // namespace

void exportGlb(const Scene& scene, const std::string& path) {
  detail::checkTinygltfBinding();
  const tinygltf::Model model = GlbWriter(scene, path).build();
  // Serialised to memory first so that a file that cannot be written is reported with the stream's state
  // (tinygltf's file writer does not check it).
  std::ostringstream data;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, data, false, true)) throw Error(path, "cannot serialise glTF");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path, "cannot open for writing");
  const std::string bytes = data.str();
  out.write(bytes.data(), std::streamsize(bytes.size()));
  out.close();
  if (!out) throw Error(path, "write failed");
}

}  // namespace farfield::scene
