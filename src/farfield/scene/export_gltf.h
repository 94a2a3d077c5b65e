// Scene export to binary glTF (.glb): meshes, materials with embedded PNG textures, one node per object
// (footprints go into the node's extras). Farfield's Z-up world is written as glTF's Y up.
//
// GltfBuilder is the writer under exportGlb, open to other exporters (store/export_impostors.h adds baked impostors
// to a scene; store/export_tiles.h writes each tile's content): it adds a scene's objects (all or some), free
// meshes with their own material, and group nodes with extras, and writes one .glb whose every buffer, image and
// accessor satisfies the glTF 2.0 specification (the tests run the Khronos validator on what it writes).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/math.h"
#include "farfield/scene/scene.h"

namespace farfield::scene {

// Throws farfield::Error naming the file when it cannot be written. A path ending in .gltf writes the JSON there and
// the buffer next to it (gltfBufferPath), with no 4 GiB limit; any other path writes one .glb.
void exportGlb(const Scene& scene, const std::string& path);
// Whether a path names a .gltf (JSON with a separate buffer) rather than a .glb: it ends in .gltf, any case.
bool isGltfPath(const std::string& path);
// The buffer file of a .gltf written by GltfBuilder: the same path with .bin for .gltf.
std::string gltfBufferPath(const std::string& gltf_path);

// The rotation from Farfield's world (x east, y north, z up) to glTF's frame (y up): world (x, y, z) is written
// as glTF (x, z, -y). Its inverse is the y-up to z-up turn that importers and 3D Tiles apply to glTF content.
Mat4 worldToGltf();

// How GltfBuilder::addMesh writes a material beyond what scene::Material says.
struct GltfMaterialOptions {
  // alphaMode MASK with this cutoff: texels with alpha below it are cut out (Farfield's impostor textures: alpha 0
  // on background, as the renderer's alpha test at 0.5). Otherwise OPAQUE, or BLEND when base_color.a < 1.
  bool alpha_mask = false;
  float alpha_cutoff = 0.5f;
  // Clamp-to-edge sampling without mipmaps (impostor images are not tiling textures); otherwise repeat with
  // mipmaps (the scene's textures).
  bool clamp = false;
};

class GltfBuilder {
 public:
  // `path` is the file write() will produce; errors name it.
  explicit GltfBuilder(std::string path);
  ~GltfBuilder();
  GltfBuilder(const GltfBuilder&) = delete;
  GltfBuilder& operator=(const GltfBuilder&) = delete;

  // Every object of `scene` as a root node in id order (what exportGlb writes), or only the listed ids (1-based, in
  // the order given). Each node's matrix is worldToGltf() * transform and its extras hold {"farfield": {"name",
  // "footprint", "parent"}}, which importScene reads back. Meshes, materials and textures are written once per
  // builder however many objects share them, and only when some object written uses them. The builder points into
  // the scene's meshes (the .glb is streamed from them by write()), so `scene` must stay alive and unchanged until
  // write(). Throws farfield::Error for a part naming a missing mesh or material, an id out of range, a bad mesh or
  // an empty texture.
  void addObjects(const Scene& scene);
  void addObjects(const Scene& scene, std::span<const uint32_t> ids);

  // A mesh (positions, optional normals (computed when missing) and uvs, triangle indices) with one material of its
  // own, returning its glTF mesh index for addNode, or -1 for a mesh without triangles. The mesh must pass
  // Mesh::validate; the builder keeps a copy of its data (the mesh may go away before write()). A material texture is written once per image whatever the number of meshes using it.
  int addMesh(const Mesh& mesh, const Material& material, const GltfMaterialOptions& options, const std::string& name);
  // The same with one primitive per part (each with its own material), in one glTF mesh; parts without triangles are
  // left out, -1 when none is left.
  struct MeshPart {
    const Mesh* mesh = nullptr;
    Material material;
    GltfMaterialOptions options;
  };
  int addMesh(const std::vector<MeshPart>& parts, const std::string& name);

  // A node (mesh -1: a group) under `parent` (-1: a root of the scene), with `matrix` (identity: none written) and
  // `extras` (a JSON object, or null for none). Returns its index, for children.
  int addNode(const std::string& name, int mesh, int parent, const Mat4& matrix, const nlohmann::json& extras);

  // Serialises the model as .glb to the path given at construction, replacing the file: the JSON chunk, then the
  // buffer streamed piece by piece (memory: the JSON and one mesh's normals). Throws farfield::Error
  // naming it when it cannot be written or the data exceed the 4 GiB limit of a .glb. A path ending in .gltf gets
  // the JSON, and the buffer goes to gltfBufferPath(path), streamed the same way, with no size limit. Returns the
  // bytes written.
  size_t write();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace farfield::scene
