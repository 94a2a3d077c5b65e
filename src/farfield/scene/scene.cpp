// Scene: ownership of meshes, materials and objects; world bounds and statistics.
#include "farfield/scene/scene.h"

#include <string>
#include <unordered_set>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::scene {

namespace {

// Bounds of a mesh, from its cached bounds when they are current enough to be trusted (non-empty), else from
// its positions: meshes edited after addMesh may not have called computeBounds().
Box3 meshBounds(const Mesh& mesh) {
  if (!mesh.bounds.empty() || mesh.positions.empty()) return mesh.bounds;
  Box3 b;
  for (const Vec3& p : mesh.positions) b.expand(p);
  return b;
}

Box3 objectWorldBounds(const Scene& scene, const Object& object) {
  // Parts of one object share its transform, so the union in object space is transformed once.
  Box3 local;
  for (const Part& part : object.parts)
    if (part.mesh < scene.meshes.size()) local.expand(meshBounds(scene.meshes[part.mesh]));
  return transformBox(local, object.transform);
}

}  // namespace

uint32_t Scene::addMesh(Mesh mesh) {
  mesh.computeBounds();
  meshes.push_back(std::move(mesh));
  return uint32_t(meshes.size() - 1);
}

uint32_t Scene::addMaterial(Material material) {
  materials.push_back(std::move(material));
  return uint32_t(materials.size() - 1);
}

uint32_t Scene::addObject(Object object) {
  object.id = uint32_t(objects.size() + 1);
  object.world_bounds = objectWorldBounds(*this, object);
  objects.push_back(std::move(object));
  return objects.back().id;
}

const Object& Scene::object(uint32_t id) const {
  FF_CHECK_MSG(id >= 1 && id <= objects.size(), "object id out of range");
  return objects[id - 1];
}

void Scene::updateBounds() {
  for (Mesh& mesh : meshes) mesh.computeBounds();
  for (Object& object : objects) object.world_bounds = objectWorldBounds(*this, object);
}

Box3 Scene::bounds() const {
  Box3 b;
  for (const Object& object : objects) b.expand(object.world_bounds);
  return b;
}

uint64_t Scene::triangleCount() const {
  uint64_t n = 0;
  for (const Object& object : objects)
    for (const Part& part : object.parts)
      if (part.mesh < meshes.size()) n += meshes[part.mesh].triangleCount();
  return n;
}

SceneStats Scene::stats() const {
  SceneStats s;
  s.objects = objects.size();
  s.meshes = meshes.size();
  s.materials = materials.size();
  for (const Object& object : objects)
    for (const Part& part : object.parts)
      if (part.mesh < meshes.size()) {
        s.triangles += meshes[part.mesh].triangleCount();
        s.vertices += meshes[part.mesh].vertexCount();
      }
  for (const Mesh& mesh : meshes) s.geometry_bytes += mesh.byteSize();
  // Materials may share one texture image; it is counted once.
  std::unordered_set<const image::ColorImage*> seen;
  for (const Material& material : materials)
    if (material.texture && seen.insert(material.texture.get()).second) {
      ++s.textures;
      s.texture_bytes += material.texture->pixelCount() * sizeof(image::Rgba8);
    }
  s.bounds = bounds();
  return s;
}

void Scene::validate(const std::string& source) const {
  for (size_t i = 0; i < meshes.size(); ++i) meshes[i].validate(source + ": mesh " + std::to_string(i));
  for (size_t i = 0; i < objects.size(); ++i) {
    const Object& o = objects[i];
    const std::string where = "object " + std::to_string(i + 1) + (o.name.empty() ? "" : " '" + o.name + "'");
    if (o.id != i + 1)
      throw Error(source, where + ": id " + std::to_string(o.id) + " out of order (expected " +
                              std::to_string(i + 1) + ")");
    for (size_t p = 0; p < o.parts.size(); ++p) {
      if (o.parts[p].mesh >= meshes.size())
        throw Error(source, where + ": part " + std::to_string(p) + " names mesh " +
                                std::to_string(o.parts[p].mesh) + " of " + std::to_string(meshes.size()));
      if (o.parts[p].material >= materials.size())
        throw Error(source, where + ": part " + std::to_string(p) + " names material " +
                                std::to_string(o.parts[p].material) + " of " + std::to_string(materials.size()));
    }
    if (o.parent > objects.size() || o.parent == o.id)
      throw Error(source, where + ": parent id " + std::to_string(o.parent) + " is not another object");
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(o.transform[c][r])) throw Error(source, where + ": non-finite transform");
    for (size_t k = 0; k < o.footprint.size(); ++k)
      if (!isFinite(o.footprint[k]))
        throw Error(source, where + ": footprint point " + std::to_string(k) + " is not finite");
  }
}

}  // namespace farfield::scene
