// Scene export to binary glTF. One buffer holds every mesh's vertex and index data and the PNG-encoded textures;
// each object becomes one root node whose matrix is its transform turned to glTF's Y up, with the Farfield-only data
// (name, footprint, parent) in the node's extras under "farfield", which importScene reads back. Meshes, materials
// and images are written on first use, so a subset of a scene's objects (a 3D Tiles leaf) carries only what it draws.
//
// The file is streamed: the builder keeps compact records of the glTF objects (no tinygltf model, no JSON tree),
// writes the JSON text from them, then the buffer as a list of pieces that point into the scene's meshes (or own
// small data: PNGs, free meshes), one by one; a scene's normals are made unit length at write time, one mesh at a
// time. Exporting a city holds its geometry once (the scene) plus the JSON text, not the five copies a model buffer,
// tinygltf's binary copy, its serialisation stream and string made, nor tinygltf's model and JSON tree (100,000
// blocks at detail 0: 4.3 GB peak with them for a 1.4 GB scene).
#include "farfield/scene/export_gltf.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::scene {

Mat4 worldToGltf() { return Mat4(Vec4(1, 0, 0, 0), Vec4(0, 0, -1, 0), Vec4(0, 1, 0, 0), Vec4(0, 0, 0, 1)); }

namespace {

// glTF constants (the specification's enums).
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kLinear = 9729, kLinearMipmapLinear = 9987, kRepeat = 10497, kClampToEdge = 33071;

void appendBytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<unsigned char>*>(context);
  const auto* p = static_cast<const unsigned char*>(data);
  out->insert(out->end(), p, p + size);
}

// JSON text of a value; invalid UTF-8 in names (real data) is replaced, not an exception.
std::string dump(const nlohmann::json& j) { return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

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
  struct View {
    size_t offset = 0, bytes = 0;
    int target = 0;
  };
  struct Accessor {
    int view = -1, component = 0;
    const char* type = "SCALAR";
    size_t count = 0;
    std::optional<Box3> bounds;  // min and max (POSITION)
  };
  struct MeshPrimitive {
    Primitive acc;
    int material = -1;
  };
  struct GltfMesh {
    std::string name;
    std::vector<MeshPrimitive> primitives;
  };
  struct Node {
    std::string name;
    int mesh = -1;
    std::optional<Mat4> matrix;
    std::string extras;  // JSON text, empty for none
    std::vector<int> children;
  };

  std::string path;
  std::vector<Piece> pieces;
  size_t buffer_bytes = 0;
  std::vector<View> views;
  std::vector<Accessor> accessors;
  std::vector<GltfMesh> meshes;
  std::vector<Node> nodes;
  std::vector<int> roots;
  std::vector<std::string> materials, images;  // JSON text of each
  std::vector<std::pair<int, int>> textures;   // (image, sampler)
  std::vector<std::string> samplers;
  bool unlit_used = false;

  std::map<std::pair<const Scene*, uint32_t>, Primitive> scene_meshes;
  // (scene, material, has uvs) -> glTF material: a texture needs TEXCOORD_0, so a mesh without uvs gets the
  // material without its texture.
  std::map<std::tuple<const Scene*, uint32_t, bool>, int> scene_materials;
  std::map<std::pair<const image::ColorImage*, bool>, int> texture_index;  // (image, clamp) -> texture
  std::map<const image::ColorImage*, int> image_index;
  int sampler_repeat = -1, sampler_clamp = -1;
  std::map<std::pair<const Scene*, std::vector<std::pair<uint32_t, uint32_t>>>, int> object_meshes;

  explicit Impl(std::string p) : path(std::move(p)) {}

  // Places a piece in the single buffer at a 4-byte boundary and returns a buffer view over it.
  int addView(Piece piece, int target) {
    buffer_bytes = (buffer_bytes + 3) / 4 * 4;
    piece.offset = buffer_bytes;
    buffer_bytes += piece.bytes;
    views.push_back({piece.offset, piece.bytes, target});
    pieces.push_back(std::move(piece));
    return int(views.size() - 1);
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

  int addAccessor(int view, int component, const char* type, size_t count) {
    accessors.push_back({view, component, type, count, std::nullopt});
    return int(accessors.size() - 1);
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

  // Vertex and index accessors of a mesh; normals only when `normals` (unlit materials need none). With `borrow`
  // the buffer points into `src` (a scene's mesh, alive until write()); otherwise it keeps a copy.
  Primitive writeMesh(const Mesh& src, bool normals, const std::string& what, bool borrow) {
    Primitive acc;
    if (src.positions.empty() || src.indices.empty()) return acc;
    src.validate(path + ": " + what);
    acc.position = addAccessor(
        addView(src.positions.data(), src.positions.size() * sizeof(Vec3), kArrayBuffer, borrow), kFloat, "VEC3",
        src.positions.size());
    // glTF requires min and max on POSITION accessors.
    Box3 b;
    for (const Vec3& p : src.positions) b.expand(p);
    accessors[size_t(acc.position)].bounds = b;
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
      acc.normal = addAccessor(addView(std::move(piece), kArrayBuffer), kFloat, "VEC3", src.positions.size());
    }
    if (src.uvs.size() == src.positions.size())
      acc.uv = addAccessor(addView(src.uvs.data(), src.uvs.size() * sizeof(Vec2), kArrayBuffer, borrow), kFloat,
                           "VEC2", src.uvs.size());
    acc.indices = addAccessor(
        addView(src.indices.data(), src.indices.size() * sizeof(uint32_t), kElementArrayBuffer, borrow),
        kUnsignedInt, "SCALAR", src.indices.size());
    return acc;
  }

  int sampler(bool clamp) {
    int& index = clamp ? sampler_clamp : sampler_repeat;
    if (index >= 0) return index;
    samplers.push_back(dump({{"magFilter", kLinear},
                             {"minFilter", clamp ? kLinear : kLinearMipmapLinear},
                             {"wrapS", clamp ? kClampToEdge : kRepeat},
                             {"wrapT", clamp ? kClampToEdge : kRepeat}}));
    index = int(samplers.size() - 1);
    return index;
  }

  // glTF texture index for an image, PNG-encoded into the buffer once however many materials share it.
  int textureFor(const image::ColorImage& img, const std::string& name, bool clamp) {
    if (auto it = texture_index.find({&img, clamp}); it != texture_index.end()) return it->second;
    int source = -1;
    if (auto it = image_index.find(&img); it != image_index.end()) {
      source = it->second;
    } else {
      if (img.empty()) throw Error(path, "texture '" + name + "' is empty");
      std::vector<unsigned char> png;
      if (!stbi_write_png_to_func(&appendBytes, &png, img.width(), img.height(), 4, img.data(), img.width() * 4))
        throw Error(path, "cannot encode texture '" + name + "' as PNG");
      Piece piece;
      piece.bytes = png.size();
      piece.owned = std::move(png);
      const int view = addView(std::move(piece), 0);
      images.push_back(dump({{"name", name}, {"mimeType", "image/png"}, {"bufferView", view}}));
      source = int(images.size() - 1);
      image_index[&img] = source;
    }
    textures.emplace_back(source, sampler(clamp));
    const int index = int(textures.size() - 1);
    texture_index[{&img, clamp}] = index;
    return index;
  }

  int writeMaterial(const Material& m, bool textured, const GltfMaterialOptions& options) {
    // Farfield shades diffusely; a rough dielectric is the closest glTF material.
    nlohmann::json pbr = {{"baseColorFactor", {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a}},
                          {"metallicFactor", 0.0},
                          {"roughnessFactor", 1.0}};
    if (m.texture && textured)
      pbr["baseColorTexture"] = {
          {"index", textureFor(*m.texture, m.texture_path.empty() ? m.name : m.texture_path, options.clamp)}};
    nlohmann::json gm = {{"name", m.name}, {"pbrMetallicRoughness", std::move(pbr)}};
    if (m.double_sided) gm["doubleSided"] = true;
    if (options.alpha_mask) {
      gm["alphaMode"] = "MASK";
      gm["alphaCutoff"] = options.alpha_cutoff;
    } else if (m.base_color.a < 1.0f) {
      gm["alphaMode"] = "BLEND";
    }
    if (m.unlit) {
      gm["extensions"] = {{"KHR_materials_unlit", nlohmann::json::object()}};
      unlit_used = true;
    }
    materials.push_back(dump(gm));
    return int(materials.size() - 1);
  }

  // One glTF mesh per distinct list of (mesh, material) parts; objects with the same parts share it.
  int objectMesh(const Scene& scene, const Object& o) {
    std::vector<std::pair<uint32_t, uint32_t>> key;
    for (const Part& p : o.parts) key.emplace_back(p.mesh, p.material);
    if (auto it = object_meshes.find({&scene, key}); it != object_meshes.end()) return it->second;
    GltfMesh gm;
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
      gm.primitives.push_back({acc, mat_it->second});
    }
    int index = -1;
    if (!gm.primitives.empty()) {
      meshes.push_back(std::move(gm));
      index = int(meshes.size() - 1);
    }
    object_meshes[{&scene, key}] = index;
    return index;
  }

  int node(const std::string& name, int mesh, int parent, const Mat4& m, std::string extras) {
    Node n;
    n.name = name;
    n.mesh = mesh;
    if (m != Mat4(1.0f)) n.matrix = m;
    n.extras = std::move(extras);
    nodes.push_back(std::move(n));
    const int index = int(nodes.size() - 1);
    if (parent < 0) {
      roots.push_back(index);
    } else {
      if (size_t(parent) >= nodes.size() - 1) throw Error(path, "node parent " + std::to_string(parent) + " does not exist");
      nodes[size_t(parent)].children.push_back(index);
    }
    return index;
  }

  void writeObject(const Scene& scene, const Object& o) {
    nlohmann::json ff = {{"name", o.name}};
    if (o.parent != 0) ff["parent"] = int(o.parent);
    if (!o.footprint.empty()) {
      nlohmann::json pts = nlohmann::json::array();
      for (const Vec2& p : o.footprint) pts.push_back({double(p.x), double(p.y)});
      ff["footprint"] = std::move(pts);
    }
    // The importer applies the y-up to z-up turn above the node, so worldToGltf() * transform gives back the
    // transform.
    node(o.name, objectMesh(scene, o), -1, worldToGltf() * o.transform, dump({{"farfield", std::move(ff)}}));
  }

  // The glTF JSON of everything added, with one buffer of buffer_bytes (none when there are no data), in the .glb's
  // BIN chunk or, with a uri, in that file.
  std::string json(const std::string& buffer_uri = {}) const {
    std::string out = R"({"asset":{"generator":"Farfield","version":"2.0"})";
    if (unlit_used) out += R"(,"extensionsUsed":["KHR_materials_unlit"])";
    auto list = [&out](const char* name, size_t count, const auto& element) {
      if (count == 0) return;
      out += ",\"";
      out += name;
      out += "\":[";
      for (size_t i = 0; i < count; ++i) {
        if (i > 0) out += ',';
        element(i);
      }
      out += ']';
    };
    auto number = [&out](size_t v) { out += std::to_string(v); };
    if (buffer_bytes > 0) {
      out += R"(,"buffers":[{)";
      if (!buffer_uri.empty()) out += R"("uri":)" + dump(nlohmann::json(buffer_uri)) + ",";
      out += R"("byteLength":)" + std::to_string(buffer_bytes) + "}]";
    }
    list("bufferViews", views.size(), [&](size_t i) {
      const View& v = views[i];
      out += R"({"buffer":0,"byteOffset":)";
      number(v.offset);
      out += R"(,"byteLength":)";
      number(v.bytes);
      if (v.target != 0) out += ",\"target\":" + std::to_string(v.target);
      out += '}';
    });
    list("accessors", accessors.size(), [&](size_t i) {
      const Accessor& a = accessors[i];
      out += "{\"bufferView\":" + std::to_string(a.view) + ",\"componentType\":" + std::to_string(a.component) +
             ",\"count\":" + std::to_string(a.count) + ",\"type\":\"" + a.type + "\"";
      if (a.bounds) {
        const Box3& b = *a.bounds;
        out += ",\"min\":" + dump({b.lo.x, b.lo.y, b.lo.z}) + ",\"max\":" + dump({b.hi.x, b.hi.y, b.hi.z});
      }
      out += '}';
    });
    list("images", images.size(), [&](size_t i) { out += images[i]; });
    list("samplers", samplers.size(), [&](size_t i) { out += samplers[i]; });
    list("textures", textures.size(), [&](size_t i) {
      out += "{\"source\":" + std::to_string(textures[i].first) + ",\"sampler\":" + std::to_string(textures[i].second) +
             "}";
    });
    list("materials", materials.size(), [&](size_t i) { out += materials[i]; });
    list("meshes", meshes.size(), [&](size_t i) {
      out += "{\"name\":" + dump(meshes[i].name) + ",\"primitives\":[";
      for (size_t k = 0; k < meshes[i].primitives.size(); ++k) {
        const MeshPrimitive& p = meshes[i].primitives[k];
        if (k > 0) out += ',';
        out += "{\"attributes\":{\"POSITION\":" + std::to_string(p.acc.position);
        if (p.acc.normal >= 0) out += ",\"NORMAL\":" + std::to_string(p.acc.normal);
        if (p.acc.uv >= 0) out += ",\"TEXCOORD_0\":" + std::to_string(p.acc.uv);
        out += "},\"indices\":" + std::to_string(p.acc.indices) + ",\"material\":" + std::to_string(p.material) +
               ",\"mode\":4}";
      }
      out += "]}";
    });
    list("nodes", nodes.size(), [&](size_t i) {
      const Node& n = nodes[i];
      out += "{\"name\":" + dump(n.name);
      if (n.mesh >= 0) out += ",\"mesh\":" + std::to_string(n.mesh);
      if (n.matrix) {
        nlohmann::json m = nlohmann::json::array();
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r) m.push_back(double((*n.matrix)[c][r]));
        out += ",\"matrix\":" + dump(m);
      }
      if (!n.children.empty()) out += ",\"children\":" + dump(n.children);
      if (!n.extras.empty()) out += ",\"extras\":" + n.extras;
      out += '}';
    });
    // glTF forbids an empty list: a scene without nodes has none.
    out += R"(,"scene":0,"scenes":[{)" + (roots.empty() ? std::string() : "\"nodes\":" + dump(roots)) + "}]}";
    return out;
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
  Impl::GltfMesh gm;
  gm.name = name;
  for (size_t i = 0; i < parts.size(); ++i) {
    const MeshPart& part = parts[i];
    const Impl::Primitive acc =
        impl_->writeMesh(*part.mesh, !part.material.unlit, name + " part " + std::to_string(i), false);
    if (acc.position < 0) continue;
    gm.primitives.push_back({acc, impl_->writeMaterial(part.material, acc.uv >= 0, part.options)});
  }
  if (gm.primitives.empty()) return -1;
  impl_->meshes.push_back(std::move(gm));
  return int(impl_->meshes.size() - 1);
}

int GltfBuilder::addNode(const std::string& name, int mesh, int parent, const Mat4& matrix,
                         const nlohmann::json& extras) {
  if (mesh >= int(impl_->meshes.size()))
    throw Error(impl_->path, "node '" + name + "': mesh " + std::to_string(mesh) + " does not exist");
  return impl_->node(name, mesh, parent, matrix, extras.is_null() ? std::string() : dump(extras));
}

bool isGltfPath(const std::string& path) {
  const std::string ext = ".gltf";
  if (path.size() <= ext.size()) return false;
  std::string tail = path.substr(path.size() - ext.size());
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return tail == ext;
}

std::string gltfBufferPath(const std::string& gltf_path) {
  return (isGltfPath(gltf_path) ? gltf_path.substr(0, gltf_path.size() - 5) : gltf_path) + ".bin";
}

size_t GltfBuilder::write() {
  const std::string& path = impl_->path;
  if (isGltfPath(path)) {
    // JSON and a separate buffer file: no 32-bit sizes, so scenes over the .glb's 4 GiB can be written.
    const std::string bin_path = gltfBufferPath(path);
    const std::string json = impl_->json(impl_->buffer_bytes > 0 ? std::filesystem::path(bin_path).filename().string() : "");
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path, "cannot open for writing");
    out.write(json.data(), std::streamsize(json.size()));
    out.close();
    if (!out) throw Error(path, "write failed");
    if (impl_->buffer_bytes == 0) return json.size();
    std::ofstream bin(bin_path, std::ios::binary | std::ios::trunc);
    if (!bin) throw Error(bin_path, "cannot open for writing");
    impl_->writeBuffer(bin);
    bin.close();
    if (!bin) throw Error(bin_path, "write failed");
    return json.size() + impl_->buffer_bytes;
  }
  const size_t bin_bytes = (impl_->buffer_bytes + 3) / 4 * 4;
  std::string json = impl_->json();
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
