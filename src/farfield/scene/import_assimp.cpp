// Every format but glTF through assimp (OBJ, PLY, AC3D, 3DS, ...): AC3D files' extra texture lines dropped, and
// non-finite coordinates and mis-reported primitive types caught before post-processing.
#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/scene/import_readers.h"

namespace farfield::scene {

namespace {

namespace fs = std::filesystem;

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
    const std::string_view word =
        start == std::string::npos ? std::string_view() : std::string_view(line).substr(start);
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

}  // namespace

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

}  // namespace farfield::scene
