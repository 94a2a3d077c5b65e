// Scene export to binary glTF. One buffer holds every mesh's vertex and index data and the PNG-encoded textures;
// each object becomes one root node whose matrix is its transform turned to glTF's Y up, with the Farfield-only data
// (name, footprint, parent) in the node's extras under "farfield", which importScene reads back. Meshes, materials
// and images are written on first use, so a subset of a scene's objects (a 3D Tiles leaf) carries only what it draws.
//
// The buffer is streamed: tinygltf serialises only the JSON (the model holds no buffer data); the buffer is a list
// of pieces that point into the scene's meshes (or own small data: PNGs, free meshes), written one by one after the
// JSON chunk. A scene's normals are made unit length at write time, one mesh at a time. So exporting a city holds
// its geometry once (the scene) plus the JSON, not the five copies a model buffer, tinygltf's binary copy, the
// serialisation stream and its string made (10,000 blocks at detail 1: 3.1 GB peak for 566 MB of geometry).
#include "farfield/scene/export_gltf.h"

#include <stb_image_write.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::scene {

namespace detail {
void checkTinygltfBinding();  // import.cpp
}  // namespace detail

Mat4 worldToGltf() { return Mat4(Vec4(1, 0, 0, 0), Vec4(0, 0, -1, 0), Vec4(0, 1, 0, 0), Vec4(0, 0, 0, 1)); }

namespace {

tinygltf::Value toValue(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::boolean:
      return tinygltf::Value(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned: {
      const int64_t v = j.get<int64_t>();
      if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) return tinygltf::Value(int(v));
      return tinygltf::Value(double(v));
    }
    case nlohmann::json::value_t::number_float:
      return tinygltf::Value(j.get<double>());
    case nlohmann::json::value_t::string:
      return tinygltf::Value(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      tinygltf::Value::Array a;
      for (const auto& e : j) a.push_back(toValue(e));
      return tinygltf::Value(std::move(a));
    }
    case nlohmann::json::value_t::object: {
      tinygltf::Value::Object o;
      for (const auto& [k, v] : j.items()) o[k] = toValue(v);
      return tinygltf::Value(std::move(o));
    }
    default:
      return tinygltf::Value();
  }
}

void appendBytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<unsigned char>*>(context);
  const auto* p = static_cast<const unsigned char*>(data);
  out->insert(out->end(), p, p + size);
}

}  // namespace

struct GltfBuilder::Impl {
  struct Primitive {
    int position = -1, normal = -1, uv = -1, indices = -1;
  };

  // One piece of the buffer at `offset`: bytes it owns, bytes borrowed from a scene mesh (alive until write()), or
  // the unit normals of a scene mesh, computed when written.
  struct Piece {
    size_t offset = 0, bytes = 0;
    std::vector<unsigned char> owned;
    const void* borrowed = nullptr;
    const Mesh* normals_of = nullptr;
  };

  std::string path;
  tinygltf::Model model;
  std::vector<Piece> pieces;
  size_t buffer_bytes = 0;
  std::map<std::pair<const Scene*, uint32_t>, Primitive> scene_meshes;
  // (scene, material, has uvs) -> glTF material: a texture needs TEXCOORD_0, so a mesh without uvs gets the
  // material without its texture.
  std::map<std::tuple<const Scene*, uint32_t, bool>, int> scene_materials;
  std::map<std::pair<const image::ColorImage*, bool>, int> textures;  // (image, clamp) -> texture
  std::map<const image::ColorImage*, int> images;
  int sampler_repeat = -1, sampler_clamp = -1;
  std::map<std::pair<const Scene*, std::vector<std::pair<uint32_t, uint32_t>>>, int> object_meshes;

  explicit Impl(std::string p) : path(std::move(p)) {
    model.asset.version = "2.0";
    model.asset.generator = "Farfield";
    model.scenes.emplace_back();
    model.defaultScene = 0;
  }

  // Places a piece in the single buffer at a 4-byte boundary and returns a buffer view over it.
  int addView(Piece piece, int target) {
    buffer_bytes = (buffer_bytes + 3) / 4 * 4;
    piece.offset = buffer_bytes;
    buffer_bytes += piece.bytes;
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = piece.offset;
    bv.byteLength = piece.bytes;
    bv.target = target;
    pieces.push_back(std::move(piece));
    model.bufferViews.push_back(bv);
    return int(model.bufferViews.size() - 1);
  }
  // A copy of `data`, or (borrow) a pointer to it, which must stay valid and unchanged until write().
  int addView(const void* data, size_t bytes, int target, bool borrow) {
    Piece piece;
    piece.bytes = bytes;
    if (borrow) {
      piece.borrowed = data;
    } else {
      const auto* p = static_cast<const unsigned char*>(data);
      piece.owned.assign(p, p + bytes);
    }
    return addView(std::move(piece), target);
  }

  // The normals glTF gets for `src`: its own made unit length (a vertex of degenerate triangles only, with no
  // direction, gets +z), computed from the triangles when it has none.
  static std::vector<Vec3> unitNormals(const Mesh& src) {
    std::vector<Vec3> n = src.normals;
    if (n.size() != src.positions.size()) {
      Mesh copy = src;
      copy.computeNormals();
      n = std::move(copy.normals);
    }
    for (Vec3& v : n) {
      const float len = glm::length(v);
      v = (std::isfinite(len) && len > 1e-12f) ? v / len : Vec3(0, 0, 1);
    }
    return n;
  }

  int addAccessor(int view, int component_type, int type, size_t count) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component_type;
    a.type = type;
    a.count = count;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  }

  // Vertex and index accessors of a mesh; normals only when `normals` (unlit materials need none). With `borrow`
  // the buffer points into `src` (a scene's mesh, alive until write()); otherwise it keeps a copy.
  Primitive writeMesh(const Mesh& src, bool normals, const std::string& what, bool borrow) {
    Primitive acc;
    if (src.positions.empty() || src.indices.empty()) return acc;
    src.validate(path + ": " + what);
    acc.position = addAccessor(addView(src.positions.data(), src.positions.size() * sizeof(Vec3),
                                       TINYGLTF_TARGET_ARRAY_BUFFER, borrow),
                               TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, src.positions.size());
    // glTF requires min and max on POSITION accessors.
    Box3 b;
    for (const Vec3& p : src.positions) b.expand(p);
    model.accessors[size_t(acc.position)].minValues = {b.lo.x, b.lo.y, b.lo.z};
    model.accessors[size_t(acc.position)].maxValues = {b.hi.x, b.hi.y, b.hi.z};
    if (normals) {
      // glTF requires unit normals.
      Piece piece;
      piece.bytes = src.positions.size() * sizeof(Vec3);
      if (borrow) {
        piece.normals_of = &src;
      } else {
        const std::vector<Vec3> n = unitNormals(src);
        const auto* p = reinterpret_cast<const unsigned char*>(n.data());
        piece.owned.assign(p, p + piece.bytes);
      }
      acc.normal = addAccessor(addView(std::move(piece), TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                               TINYGLTF_TYPE_VEC3, src.positions.size());
    }
    if (src.uvs.size() == src.positions.size())
      acc.uv = addAccessor(
          addView(src.uvs.data(), src.uvs.size() * sizeof(Vec2), TINYGLTF_TARGET_ARRAY_BUFFER, borrow),
          TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, src.uvs.size());
    acc.indices = addAccessor(addView(src.indices.data(), src.indices.size() * sizeof(uint32_t),
                                      TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, borrow),
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, src.indices.size());
    return acc;
  }

  // Writes the buffer's pieces in order, with the zero padding between them; errors name the file.
  void writeBuffer(std::ostream& out) const {
    static const char zeros[4] = {0, 0, 0, 0};
    size_t at = 0;
    for (const Piece& piece : pieces) {
      out.write(zeros, std::streamsize(piece.offset - at));
      if (piece.normals_of) {
        const std::vector<Vec3> n = unitNormals(*piece.normals_of);
        FF_CHECK(n.size() * sizeof(Vec3) == piece.bytes);
        out.write(reinterpret_cast<const char*>(n.data()), std::streamsize(piece.bytes));
      } else {
        const void* data = piece.borrowed ? piece.borrowed : piece.owned.data();
        out.write(static_cast<const char*>(data), std::streamsize(piece.bytes));
      }
      at = piece.offset + piece.bytes;
      if (!out) throw Error(path, "write failed");
    }
    out.write(zeros, std::streamsize((4 - at % 4) % 4));
  }

  int sampler(bool clamp) {
    int& index = clamp ? sampler_clamp : sampler_repeat;
    if (index >= 0) return index;
    tinygltf::Sampler s;
    s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    s.minFilter = clamp ? TINYGLTF_TEXTURE_FILTER_LINEAR : TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    s.wrapS = s.wrapT = clamp ? TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE : TINYGLTF_TEXTURE_WRAP_REPEAT;
    model.samplers.push_back(s);
    index = int(model.samplers.size() - 1);
    return index;
  }

  // glTF texture index for an image, PNG-encoded into the buffer once however many materials share it.
  int textureFor(const image::ColorImage& img, const std::string& name, bool clamp) {
    if (auto it = textures.find({&img, clamp}); it != textures.end()) return it->second;
    int source = -1;
    if (auto it = images.find(&img); it != images.end()) {
      source = it->second;
    } else {
      if (img.empty()) throw Error(path, "texture '" + name + "' is empty");
      std::vector<unsigned char> png;
      if (!stbi_write_png_to_func(&appendBytes, &png, img.width(), img.height(), 4, img.data(), img.width() * 4))
        throw Error(path, "cannot encode texture '" + name + "' as PNG");
      tinygltf::Image gi;
      gi.name = name;
      gi.mimeType = "image/png";
      gi.bufferView = addView(png.data(), png.size(), 0, false);
      model.images.push_back(gi);
      source = int(model.images.size() - 1);
      images[&img] = source;
    }
    tinygltf::Texture t;
    t.source = source;
    t.sampler = sampler(clamp);
    model.textures.push_back(t);
    const int index = int(model.textures.size() - 1);
    textures[{&img, clamp}] = index;
    return index;
  }

  int writeMaterial(const Material& m, bool textured, const GltfMaterialOptions& options) {
    tinygltf::Material gm;
    gm.name = m.name;
    gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a};
    // Farfield shades diffusely; a rough dielectric is the closest glTF material.
    gm.pbrMetallicRoughness.metallicFactor = 0.0;
    gm.pbrMetallicRoughness.roughnessFactor = 1.0;
    gm.doubleSided = m.double_sided;
    if (options.alpha_mask) {
      gm.alphaMode = "MASK";
      gm.alphaCutoff = options.alpha_cutoff;
    } else if (m.base_color.a < 1.0f) {
      gm.alphaMode = "BLEND";
    }
    if (m.texture && textured)
      gm.pbrMetallicRoughness.baseColorTexture.index =
          textureFor(*m.texture, m.texture_path.empty() ? m.name : m.texture_path, options.clamp);
    if (m.unlit) {
      gm.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
      if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_materials_unlit") ==
          model.extensionsUsed.end())
        model.extensionsUsed.push_back("KHR_materials_unlit");
    }
    model.materials.push_back(gm);
    return int(model.materials.size() - 1);
  }

  tinygltf::Primitive primitive(const Primitive& acc, int material) {
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.attributes["POSITION"] = acc.position;
    if (acc.normal >= 0) prim.attributes["NORMAL"] = acc.normal;
    if (acc.uv >= 0) prim.attributes["TEXCOORD_0"] = acc.uv;
    prim.indices = acc.indices;
    prim.material = material;
    return prim;
  }

  // One glTF mesh per distinct list of (mesh, material) parts; objects with the same parts share it.
  int objectMesh(const Scene& scene, const Object& o) {
    std::vector<std::pair<uint32_t, uint32_t>> key;
    for (const Part& p : o.parts) key.emplace_back(p.mesh, p.material);
    if (auto it = object_meshes.find({&scene, key}); it != object_meshes.end()) return it->second;
    tinygltf::Mesh gm;
    gm.name = o.name;
    for (const Part& p : o.parts) {
      if (p.mesh >= scene.meshes.size() || p.material >= scene.materials.size())
        throw Error(path, "object " + std::to_string(o.id) + ": part names a missing mesh or material");
      auto mesh_it = scene_meshes.find({&scene, p.mesh});
      if (mesh_it == scene_meshes.end())
        mesh_it = scene_meshes
                      .emplace(std::pair(&scene, p.mesh),
                               writeMesh(scene.meshes[p.mesh], true, "mesh " + std::to_string(p.mesh), true))
                      .first;
      const Primitive& acc = mesh_it->second;
      if (acc.position < 0) continue;  // no triangles
      const bool textured = acc.uv >= 0;
      auto mat_it = scene_materials.find({&scene, p.material, textured});
      if (mat_it == scene_materials.end())
        mat_it = scene_materials
                     .emplace(std::tuple(&scene, p.material, textured),
                              writeMaterial(scene.materials[p.material], textured, {}))
                     .first;
      gm.primitives.push_back(primitive(acc, mat_it->second));
    }
    int index = -1;
    if (!gm.primitives.empty()) {
      model.meshes.push_back(gm);
      index = int(model.meshes.size() - 1);
    }
    object_meshes[{&scene, key}] = index;
    return index;
  }

  int node(const std::string& name, int mesh, int parent, const Mat4& m, tinygltf::Value extras) {
    tinygltf::Node n;
    n.name = name;
    n.mesh = mesh;
    if (m != Mat4(1.0f)) {
      n.matrix.resize(16);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) n.matrix[size_t(c * 4 + r)] = m[c][r];
    }
    n.extras = std::move(extras);
    model.nodes.push_back(std::move(n));
    const int index = int(model.nodes.size() - 1);
    if (parent < 0) {
      model.scenes[0].nodes.push_back(index);
    } else {
      if (size_t(parent) >= model.nodes.size() - 1) throw Error(path, "node parent " + std::to_string(parent) + " does not exist");
      model.nodes[size_t(parent)].children.push_back(index);
    }
    return index;
  }

  void writeObject(const Scene& scene, const Object& o) {
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
    // The importer applies the y-up to z-up turn above the node, so worldToGltf() * transform gives back the
    // transform.
    node(o.name, objectMesh(scene, o), -1, worldToGltf() * o.transform, tinygltf::Value(std::move(extras)));
  }
};

GltfBuilder::GltfBuilder(std::string path) : impl_(std::make_unique<Impl>(std::move(path))) {}
GltfBuilder::~GltfBuilder() = default;

void GltfBuilder::addObjects(const Scene& scene) {
  for (const Object& o : scene.objects) impl_->writeObject(scene, o);
}

void GltfBuilder::addObjects(const Scene& scene, std::span<const uint32_t> ids) {
  for (uint32_t id : ids) {
    if (id == 0 || id > scene.objects.size())
      throw Error(impl_->path, "object id " + std::to_string(id) + " is not in the scene (1.." +
                                   std::to_string(scene.objects.size()) + ")");
    impl_->writeObject(scene, scene.objects[id - 1]);
  }
}

int GltfBuilder::addMesh(const Mesh& mesh, const Material& material, const GltfMaterialOptions& options,
                         const std::string& name) {
  return addMesh(std::vector<MeshPart>{{&mesh, material, options}}, name);
}

int GltfBuilder::addMesh(const std::vector<MeshPart>& parts, const std::string& name) {
  tinygltf::Mesh gm;
  gm.name = name;
  for (size_t i = 0; i < parts.size(); ++i) {
    const MeshPart& part = parts[i];
    const Impl::Primitive acc =
        impl_->writeMesh(*part.mesh, !part.material.unlit, name + " part " + std::to_string(i), false);
    if (acc.position < 0) continue;
    gm.primitives.push_back(impl_->primitive(acc, impl_->writeMaterial(part.material, acc.uv >= 0, part.options)));
  }
  if (gm.primitives.empty()) return -1;
  impl_->model.meshes.push_back(gm);
  return int(impl_->model.meshes.size() - 1);
}

int GltfBuilder::addNode(const std::string& name, int mesh, int parent, const Mat4& matrix,
                         const nlohmann::json& extras) {
  if (mesh >= int(impl_->model.meshes.size()))
    throw Error(impl_->path, "node '" + name + "': mesh " + std::to_string(mesh) + " does not exist");
  return impl_->node(name, mesh, parent, matrix, extras.is_null() ? tinygltf::Value() : toValue(extras));
}

size_t GltfBuilder::write() {
  detail::checkTinygltfBinding();
  const std::string& path = impl_->path;
  const size_t bin_bytes = (impl_->buffer_bytes + 3) / 4 * 4;
  if (bin_bytes > size_t(std::numeric_limits<uint32_t>::max()) - (size_t(64) << 20))
    throw Error(path, "scene data exceeds the 4 GiB limit of a .glb file");
  // The JSON alone (the model has no buffer), then the one buffer's length spliced into it: glTF forbids an empty
  // buffer, so a model without data has none.
  std::ostringstream glb;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&impl_->model, glb, false, true)) throw Error(path, "cannot serialise glTF");
  std::string json = glb.str();
  glb = std::ostringstream();
  FF_CHECK(json.size() >= 20 && json[0] == 'g' && json[1] == 'l' && json[2] == 'T' && json[3] == 'F');
  uint32_t json_chunk = 0;
  std::memcpy(&json_chunk, json.data() + 12, 4);
  json = json.substr(20, json_chunk);
  FF_CHECK(!json.empty() && json[0] == '{');
  if (bin_bytes > 0) json.insert(1, "\"buffers\":[{\"byteLength\":" + std::to_string(impl_->buffer_bytes) + "}],");
  while (json.size() % 4 != 0) json.push_back(' ');
  const size_t total = 12 + 8 + json.size() + (bin_bytes > 0 ? 8 + bin_bytes : 0);
  if (total > size_t(std::numeric_limits<uint32_t>::max()))
    throw Error(path, "scene data exceeds the 4 GiB limit of a .glb file");

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(path, "cannot open for writing");
  auto word = [&out](uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };  // glTF is little-endian
  out.write("glTF", 4);
  word(2);
  word(uint32_t(total));
  word(uint32_t(json.size()));
  word(0x4E4F534Au);  // "JSON"
  out.write(json.data(), std::streamsize(json.size()));
  if (bin_bytes > 0) {
    word(uint32_t(bin_bytes));
    word(0x004E4942u);  // "BIN"
    impl_->writeBuffer(out);
  }
  out.close();
  if (!out) throw Error(path, "write failed");
  return total;
}

void exportGlb(const Scene& scene, const std::string& path) {
  GltfBuilder builder(path);
  builder.addObjects(scene);
  builder.write();
}

}  // namespace farfield::scene
